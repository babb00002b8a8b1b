#include "toml_prescan.hpp"

#include <cstddef>
#include <vector>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"

namespace gyrocal {
namespace {

/// A character of a bare key (TOML 1.0: A-Z a-z 0-9 _ -); numbers and booleans are made of them too.
bool is_bare(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
}

}  // namespace

void prescan_configuration(std::string_view text, const std::string& file) {
  constexpr std::string_view kBom = "\xEF\xBB\xBF", kTripleQuote = R"(""")", kTripleApostrophe = "'''";
  if (text.starts_with(kBom)) text.remove_prefix(kBom.size());
  const auto beyond_ascii = [](char c) { return static_cast<unsigned char>(c) >= 0x80; };
  enum class State { kCode, kComment, kBasic, kLiteral, kMultiBasic, kMultiLiteral };
  State state = State::kCode;
  std::size_t line = 1, line_start = 0;
  // The run of key parts being read (a key, a header's name, or a value such as 1.5): its dots, the line it
  // began on (a key does not span lines).
  bool in_run = false;
  std::size_t dots = 0, run_line = 0;
  // The nesting of tables and arrays: the parts of the current table header, and per open inline table or
  // array the levels it adds (the parts of its key, at least 1). The stack is bounded by the limit.
  std::size_t table_parts = 0, open_levels = 0, key_parts = 0;
  std::vector<std::size_t> open;
  bool in_header = false, header_is_array = false;
  const auto fail = [&](std::size_t at, const std::string& what) {
    throw Error(file + ", line " + std::to_string(at) + ": " + what + ".");
  };
  const auto check_depth = [&](std::size_t at) {
    const std::size_t depth = table_parts + open_levels + (in_run ? dots + 1 : 0);
    if (depth > limits::kConfigurationDepth)
      fail(at,
           "tables, inline tables and arrays nested more than " +
               std::to_string(limits::kConfigurationDepth) +
               " levels deep (each dotted part of a key or header, inline table and array is one), the limit "
               "of a configuration (gyrocal's deepest value is 6 levels down)");
  };
  const auto end_run = [&] {
    in_run = false;
    dots = 0;
  };
  const auto part = [&] {  // a bare part or a one-line string: begins a run unless one is open
    if (in_run) return;
    in_run = true;
    dots = 0;
    run_line = line;
    check_depth(line);
  };
  const auto open_level = [&](std::size_t levels) {
    open.push_back(levels);
    open_levels += levels;
    key_parts = 0;
    end_run();
    check_depth(line);
  };
  const auto close_level = [&] {
    if (open.empty()) return;  // a stray bracket: TOML's error
    open_levels -= open.back();
    open.pop_back();
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    const std::string_view rest = text.substr(i);
    if (beyond_ascii(c) && state != State::kComment) {
      throw Error(file + ", line " + std::to_string(line) + ", column " + std::to_string(i - line_start + 1) +
                  ": a character beyond ASCII outside a comment; the keys and values of a configuration are "
                  "ASCII.");
    }
    if (c == '\n') {
      ++line;
      line_start = i + 1;
      if (state != State::kMultiBasic && state != State::kMultiLiteral) {
        state = State::kCode;
        end_run();
        in_header = false;
        key_parts = 0;  // a value begins on its key's line
      }
      continue;
    }
    switch (state) {
      case State::kCode:
        if (c == '#') {
          state = State::kComment;
          end_run();
        } else if (rest.starts_with(kTripleQuote) || rest.starts_with(kTripleApostrophe)) {
          // A multi-line string is never a key part: it ends the run.
          state = c == '"' ? State::kMultiBasic : State::kMultiLiteral;
          end_run();
          i += 2;
        } else if (c == '"' || c == '\'') {
          part();
          state = c == '"' ? State::kBasic : State::kLiteral;
        } else if (is_bare(c)) {
          part();
        } else if (c == '.') {
          if (!in_run) part();  // a leading dot: not TOML, counted all the same
          ++dots;
          if (dots + 1 > limits::kConfigurationKeyParts)
            fail(run_line,
                 "a key or table header of more than " + std::to_string(limits::kConfigurationKeyParts) +
                     " dotted parts, the limit of a configuration's keys (gyrocal's longest has 4)");
          check_depth(run_line);
        } else if (c == '[' && open.empty() && !in_header && !in_run && key_parts == 0) {
          // A table header (an array's '[' follows a key's '='): it names the table from the root.
          in_header = true;
          header_is_array = rest.starts_with("[[");
          if (header_is_array) ++i;
          table_parts = 0;
        } else if (c == ']' && in_header) {
          table_parts = (in_run ? dots + 1 : 0) + (header_is_array ? 1 : 0);
          in_header = false;
          end_run();
          if (header_is_array && rest.starts_with("]]")) ++i;
        } else if (c == '=') {
          key_parts = in_run ? dots + 1 : 0;
          end_run();
        } else if (c == '{' || c == '[') {
          open_level(key_parts > 0 ? key_parts : 1);
        } else if (c == '}' || c == ']') {
          close_level();
          end_run();
        } else if (c == ',') {
          key_parts = 0;
          end_run();
        } else if (c != ' ' && c != '\t' && c != '\r') {
          end_run();  // any other character ends a key
        }
        break;
      case State::kBasic:
      case State::kMultiBasic:
        if (c == '\\') {
          // Skip the escaped character, unless it is a line end (counted above) or beyond ASCII (refused
          // next).
          if (i + 1 < text.size() && text[i + 1] != '\n' && !beyond_ascii(text[i + 1])) ++i;
        } else if (state == State::kBasic && c == '"') {
          state = State::kCode;
        } else if (state == State::kMultiBasic && rest.starts_with(kTripleQuote)) {
          state = State::kCode;
          i += 2;
        }
        break;
      case State::kLiteral:
        if (c == '\'') state = State::kCode;
        break;
      case State::kMultiLiteral:
        if (rest.starts_with(kTripleApostrophe)) {
          state = State::kCode;
          i += 2;
        }
        break;
      case State::kComment:
        break;
    }
  }
}

}  // namespace gyrocal
