// The two paths of tests/support/test_paths.hpp, compiled in from the build's definitions.
#include "support/test_paths.hpp"

namespace gyrocal_test {

const char* cli_path() {
  return GYROCAL_CLI_PATH;
}
const char* data_dir() {
  return GYROCAL_TEST_DATA_PATH;
}

}  // namespace gyrocal_test
