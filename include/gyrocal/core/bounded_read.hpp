#pragma once
// Reading a whole input file with a bound on its size (the limits of core/limits.hpp), whatever the file is:
// a regular file, a FIFO, a character device such as /dev/zero or /dev/urandom, standard input. At most
// `max_bytes` + 1 bytes are ever read, so an endless or huge input ends quickly and in bounded memory; its
// size is not asked of the file system, which a FIFO or a device does not know.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

namespace gyrocal {

/// What read_bounded read.
struct BoundedRead {
  /// The bytes read: the whole file unless one of the flags below is set.
  std::string text;
  /// The file holds more than max_bytes bytes: text holds its first max_bytes + 1 (or a little more, never
  /// more than one read of 64 KiB beyond max_bytes).
  bool too_large = false;
  /// `stop` returned true: text is the file's beginning up to that point (the rest was not read).
  bool stopped = false;
};

/// Reads the file at `path` whole, but no more than `max_bytes` + 1 bytes of it (see BoundedRead). `what`
/// names the kind of file in messages ("configuration file", "result file"). `stop`, if given, is called
/// after each read with all the bytes read so far; returning true ends reading there (e.g. once the first
/// bytes show that the file is not of the kind expected, so that the rest is never read).
/// Throws gyrocal::Error "Cannot read <what> <path>: <reason>." if the file does not exist, is a directory,
/// or cannot be opened or read (the system's reason).
BoundedRead read_bounded(const std::filesystem::path& path, std::size_t max_bytes, std::string_view what,
                         const std::function<bool(std::string_view)>& stop = {});

}  // namespace gyrocal
