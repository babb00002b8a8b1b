#pragma once
// Force-included into the fuzz build's toml++ (header-only there, ../CMakeLists.txt): toml++'s own debug
// assertions stay off, as in the Release build that gyrocal ships. toml++ 3.3.0 asserts wrongly on a table
// header such as "[=" that its parser then refuses cleanly (docs/fuzzing.md).
#define TOML_ASSERT(expr) static_assert(true)
