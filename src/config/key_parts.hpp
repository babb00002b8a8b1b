#pragma once
// The dotted parts of a configuration's keys, counted before toml++ sees the text (issue 29, D1).
#include <string>
#include <string_view>

namespace gyrocal {

/// Refuses a key or table header of more than limits::kConfigurationKeyParts dotted parts (`a.b.c` has 3),
/// and values nested more than limits::kConfigurationDepth levels deep (each dotted part of the table
/// header and of the keys above a value, each inline table and array is one): toml++ nests one table per
/// part and walks and frees the tables by recursion, so ~50,000 parts overflowed the stack. Throws Error
/// "<file>, line <n>: ..." naming the limit. The scan itself is linear and free of recursion; strings
/// (basic, literal, multi-line) and comments are skipped, so a dot inside a quoted key or a comment does not
/// count. It counts the dots of any run of key parts, values included; a valid value has at most one dot
/// (a float, a time), so nothing valid is refused but an overlong or overdeep key.
void refuse_long_dotted_keys(std::string_view text, const std::string& file);

}  // namespace gyrocal
