#pragma once
// A configuration's text checked before toml++ sees it: one linear scan without recursion (issue 29, D1).
#include <string>
#include <string_view>

namespace gyrocal {

/// Checks a configuration's text before toml++ parses it, in one pass that follows strings (basic, literal,
/// multi-line) and comments as TOML writes them. Throws Error "<file>, line <n>: ..." on:
/// - a character beyond ASCII anywhere but in a comment (a UTF-8 byte order mark at the start aside): the
/// keys
///   and values of a configuration are ASCII, and toml++ 3.3.0 (Debian 12) reaches __builtin_unreachable in
///   its whitespace test for many such characters (upstream marzer/tomlplusplus issue 295, found by fuzzing,
///   docs/fuzzing.md); a string holding one is refused too (the only strings, [record]'s, are ASCII);
/// - a key or table header of more than limits::kConfigurationKeyParts dotted parts (`a.b.c` has 3), and
///   values nested more than limits::kConfigurationDepth levels deep (each dotted part of the table header
///   and of the keys above a value, each inline table and array is one): toml++ nests one table per part and
///   walks and frees the tables by recursion, so ~50,000 parts overflowed the stack.
/// A dot inside a quoted key or a comment does not count. The scan counts the dots of any run of key parts,
/// values included; a valid value has at most one dot (a float, a time), so nothing valid is refused but an
/// overlong or overdeep key. Where the scan and TOML could disagree (a closing delimiter with extra quotes),
/// the scan sees a string where TOML sees none, which refuses more, never less.
void prescan_configuration(std::string_view text, const std::string& file);

}  // namespace gyrocal
