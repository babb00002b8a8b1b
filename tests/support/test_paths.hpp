#pragma once
// Where the tests find the command line and their data (tests/CMakeLists.txt). Every test program is compiled
// with GYROCAL_CLI and GYROCAL_TEST_DATA_DIR defined as calls of these two functions and this header included
// first (-include), so that no absolute path of a checkout appears in a test's compile command: a clone in
// another folder (CI's lone clone) reuses the compiler cache's objects of every test (docs/performance.md,
// "CI"). Only tests/support/test_paths.cpp, a few lines, is compiled with the paths themselves.
namespace gyrocal_test {

/// The path of the gyrocal binary the tests run.
const char* cli_path();
/// The folder tests/data of this checkout.
const char* data_dir();

}  // namespace gyrocal_test
