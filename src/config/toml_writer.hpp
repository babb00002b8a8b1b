#pragma once
// The writer of `init`'s commented configuration, private to src/config: lines "key = value  # comment".
#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <sstream>
#include <string>
#include <string_view>

namespace gyrocal::config_detail {

/// A TOML basic string: quotes, backslashes and control characters escaped.
inline std::string toml_string(std::string_view text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\t') {
      out += "\\t";
    } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      char code[8];
      std::snprintf(code, sizeof code, "\\u%04X", static_cast<unsigned>(static_cast<unsigned char>(c)));
      out += code;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

/// Lines "key = value  # comment", the comments aligned.
class TomlWriter {
 public:
  void comment(std::string_view text) { out_ << "# " << text << "\n"; }
  /// A table header after a blank line, its note (lines separated by \n) as comment lines above it.
  void section(std::string_view name, std::string_view note) {
    out_ << "\n";
    for (std::size_t begin = 0; begin < note.size();) {
      const std::size_t end = std::min(note.find('\n', begin), note.size());
      comment(note.substr(begin, end - begin));
      begin = end + 1;
    }
    out_ << "[" << name << "]\n";
  }
  /// An array-of-tables header ("[[name]]", one element) after a blank line, its note above it.
  void array_section(std::string_view name, std::string_view note) {
    section("[" + std::string(name) + "]", note);
  }
  /// A table header and its key lines (as another writer wrote them), all commented out.
  void section_commented(std::string_view name, std::string_view note, std::string_view keys) {
    out_ << "\n";
    const std::string lines = std::string(note) + "\n[" + std::string(name) + "]\n" + std::string(keys);
    for (std::size_t begin = 0; begin < lines.size();) {
      const std::size_t end = std::min(lines.find('\n', begin), lines.size());
      if (end > begin) comment(std::string_view(lines).substr(begin, end - begin));
      begin = end + 1;
    }
  }
  /// "key = value  # note"; a note of several lines (separated by \n) continues on comment lines aligned
  /// with its first.
  void key(std::string_view key, const std::string& value, std::string_view note,
           bool commented_out = false) {
    constexpr std::size_t kCommentColumn = 44;
    std::string line = (commented_out ? "# " : "") + std::string(key) + " = " + value;
    line.resize(std::max(line.size() + 2, kCommentColumn), ' ');
    const std::size_t first_end = std::min(note.find('\n'), note.size());
    out_ << line << "# " << note.substr(0, first_end) << "\n";
    for (std::size_t begin = first_end + 1; begin < note.size();) {
      const std::size_t end = std::min(note.find('\n', begin), note.size());
      out_ << std::string(kCommentColumn, ' ') << "# " << note.substr(begin, end - begin) << "\n";
      begin = end + 1;
    }
  }
  std::string text() const { return out_.str(); }

 private:
  std::ostringstream out_;
};

}  // namespace gyrocal::config_detail
