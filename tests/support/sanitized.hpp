#pragma once
// For tests: whether this run is the sanitizer build's (scripts/test --sanitize sets GYROCAL_SANITIZED).
// There every step is ~10x slower; a statistical study may take fewer trials with a band as wide in units of
// its own statistic's spread (docs/performance.md, "CI").
#include <cstdlib>

namespace gyrocal::testing {

/// True in the sanitizer build's run of the tests.
inline bool sanitized() {
  return std::getenv("GYROCAL_SANITIZED") != nullptr;
}

}  // namespace gyrocal::testing
