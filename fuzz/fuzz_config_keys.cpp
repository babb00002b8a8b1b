// libFuzzer target: deep and long keys in a configuration (issue 29, D1). The fuzzer's bytes are not the text
// but a recipe for it: each statement is a dotted key, a table header, an array of tables, nested arrays or
// nested inline tables, of a depth or length taken from two bytes (up to 131,070: far beyond the limits of
// core/limits.hpp, kConfigurationKeyParts and kConfigurationDepth, and beyond the depth at which toml++'s
// recursion overflowed the stack), its parts bare or quoted (with dots inside the quotes), with white space
// around the dots. The text goes to parse_scenario, which must return or throw gyrocal::Error: a crash, a
// stack overflow or another exception escaping is a finding (fuzz_config mutates TOML text itself, which
// rarely grows a key of thousands of parts).
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <string>
#include <string_view>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/core/error.hpp"

namespace {

/// The fuzzer's bytes, read one at a time (0 once they are used up).
class Recipe {
 public:
  Recipe(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool more() const { return next_ < size_; }
  std::uint8_t byte() { return next_ < size_ ? data_[next_++] : 0; }
  /// A count in [0, 131070]: two bytes, doubled.
  std::size_t count() {
    const std::size_t low = byte();
    return 2 * (low | (static_cast<std::size_t>(byte()) << 8));
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t next_ = 0;
};

/// One part of a key: a bare name (some of them gyrocal's keys), or a quoted one holding dots.
std::string key_part(std::uint8_t choice) {
  static constexpr std::string_view kBare[] = {"a",    "site",   "test",          "centrifuge", "errors",
                                               "gyro", "record", "main_wobble_y", "harmonic",   "x-1_"};
  switch (choice % 4) {
    case 0:
      return "\"a.b\"";
    case 1:
      return "'c.d.e'";
    default:
      return std::string(kBare[(choice / 4) % std::size(kBare)]);
  }
}

/// `parts` parts joined by dots, white space around the dots when `spaced`.
std::string dotted(std::size_t parts, std::uint8_t style) {
  const bool spaced = (style & 0x80) != 0, quoted = (style & 0x40) != 0;
  std::string out;
  for (std::size_t i = 0; i < parts; ++i) {
    if (i) out += spaced ? " . " : ".";
    out += quoted ? key_part(static_cast<std::uint8_t>(style + i))
                  : key_part(static_cast<std::uint8_t>(style & 0x3C));
  }
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Recipe recipe(data, size);
  std::string text;
  // A few statements; the text stays below the 16 MiB of a configuration file.
  for (int statement = 0; statement < 8 && recipe.more() && text.size() < (std::size_t{4} << 20);
       ++statement) {
    const std::uint8_t shape = recipe.byte();
    const std::uint8_t style = recipe.byte();
    const std::size_t n = recipe.count();
    const std::size_t parts = n == 0 ? 1 : n;
    switch (shape % 7) {
      case 0:  // a dotted key
        text += dotted(parts, style) + " = 1\n";
        break;
      case 1:  // a table header
        text += "[" + dotted(parts, style) + "]\n";
        break;
      case 2:  // an array of tables
        text += "[[" + dotted(parts, style) + "]]\n";
        break;
      case 3:  // a known section, then a long key
        text += "site." + dotted(parts, style) + " = 1.5\n";
        break;
      case 4:  // nested arrays
        text += "a = " + std::string(n, '[') + "1" + std::string(n, ']') + "\n";
        break;
      case 5: {  // nested inline tables, their keys dotted (one part when deep, to keep the text small)
        const std::string key = dotted(n < 2048 ? 1 + static_cast<std::size_t>(style % 40) : 1, style);
        std::string value;
        for (std::size_t i = 0; i < n; ++i) value += "{" + key + " = ";
        text += "b = " + value + "1" + std::string(n, '}') + "\n";
        break;
      }
      case 6: {  // a long header, then a long key holding nested inline tables
        const std::size_t depth = 1 + static_cast<std::size_t>(style % 64);
        text += "[" + dotted(1 + n % 40, style) + "]\n" + dotted(1 + (n / 40) % 40, style) + " = ";
        for (std::size_t i = 0; i < depth; ++i) text += "{" + dotted(1 + i % 40, style) + " = [";
        text += "1";
        for (std::size_t i = 0; i < depth; ++i) text += "]}";
        text += "\n";
        break;
      }
    }
  }
  try {
    (void)gyrocal::parse_scenario(text, "keys.toml");
  } catch (const gyrocal::Error&) {
    // a clean refusal
  }
  return 0;
}
