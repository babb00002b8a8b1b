#pragma once
// The one exception type of gyrocal: its message is a complete sentence for the user, naming the
// file, line or key at fault. The command line prints it and exits non-zero.
#include <stdexcept>
#include <string>

namespace gyrocal {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace gyrocal
