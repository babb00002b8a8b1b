#pragma once
// SHA-256 (FIPS 180-4) through OpenSSL's libcrypto: what identifies a run's record and configuration in the
// calibration history (docs/history.md).
#include <filesystem>
#include <string>
#include <string_view>

namespace gyrocal::history {

/// The SHA-256 of `bytes`, as 64 lower-case hexadecimal digits.
std::string sha256_hex(std::string_view bytes);

/// The SHA-256 of the file at `path`, read in chunks of 1 MiB (any size, in bounded memory), as 64 lower-case
/// hexadecimal digits. Throws gyrocal::Error "Cannot read <what> <path>: <reason>." if it cannot be opened or
/// read, or is a directory, and refuses a file that is not a regular file (a pipe, a device).
std::string sha256_file(const std::filesystem::path& path, std::string_view what);

/// True when `text` is 64 lower-case hexadecimal digits (a SHA-256 as sha256_hex writes it).
bool is_sha256_hex(std::string_view text);

}  // namespace gyrocal::history
