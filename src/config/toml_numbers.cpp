// Numbers as a configuration writes them: the shortest text that reads back to the same double.
#include <bit>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>

#include "config_keys.hpp"
#include "gyrocal/config/config_io.hpp"

namespace gyrocal {
namespace config_detail {

// ---------------------------------------------------------------------------------------------------------
// Numbers as text.

/// Shortest decimal form that reads back to the same double.
std::string shortest(double v) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
  return std::string(buffer, result.ptr);
}

/// A TOML float, bit exact: the shortest form, with ".0" added where it would otherwise read as an integer.
std::string toml_number(double v) {
  std::string text = shortest(v);
  if (text.find_first_of(".en") == std::string::npos) text += ".0";  // "nan" and "inf" hold an 'n'
  return text;
}

bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

/// The value in the file's unit that the reader turns back into si exactly (as value * to_si); among the
/// candidates, the one with the shortest text: 127.96 deg is read as 127.96 * kDegToRad, and dividing that
/// by kDegToRad gives 127.96000000000001, a neighbour that reads back to the same radians.
double in_file_unit(double si, double to_si) {
  const double guess = si / to_si;
  if (to_si == 1.0 || !std::isfinite(guess)) return guess;
  double best = guess;
  std::size_t best_length = SIZE_MAX;
  double below = guess;
  double above = guess;
  for (int step = 0; step < 4; ++step) {
    for (double candidate : {below, above}) {
      const std::size_t length = shortest(candidate).size();
      if (same_bits(candidate * to_si, si) && length < best_length) {
        best = candidate;
        best_length = length;
      }
    }
    below = std::nextafter(below, -kInf);
    above = std::nextafter(above, kInf);
  }
  return best;
}

/// The values of a list of numbers as the file would write them: "[a, b]".
std::string list_text(const std::vector<double>& values) {
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + shortest(values[i]);
  return text + "]";
}

/// The value of a [reduce] key as the file writes it.
std::string reduce_value(const ReduceKey& k, const ReduceOptions& o) {
  if (k.number != nullptr) return toml_number(o.*k.number);
  if (k.integer != nullptr) return std::to_string(o.*k.integer);
  return o.*k.flag ? "true" : "false";
}

}  // namespace config_detail

std::string toml_float(double v) {
  return config_detail::toml_number(v);
}

}  // namespace gyrocal
