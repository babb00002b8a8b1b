#pragma once
// An output file that appears whole or not at all (INTERFACE.md: "no partial output file is left
// behind"). Bytes go to a temporary file in the target's directory; commit() renames it onto the
// target, which is atomic on POSIX file systems. Without commit(), the temporary is removed.
#include <filesystem>
#include <memory>
#include <ostream>
#include <string_view>

namespace gyrocal {

class AtomicOutputFile {
 public:
  /// Creates a uniquely named temporary file beside `target`. Throws gyrocal::Error if `target`
  /// exists and `overwrite` is false ("… exists; use --force to overwrite"), or if the temporary
  /// cannot be created. The path "-" is an ordinary file name here.
  AtomicOutputFile(std::filesystem::path target, bool overwrite);
  /// Removes the temporary file unless commit() succeeded.
  ~AtomicOutputFile();
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;

  /// Appends bytes (buffered, 1 MiB). Throws gyrocal::Error naming the file on a write error.
  void write(std::string_view bytes);
  /// The same file as a std::ostream (shares write()'s buffer). A write error throws gyrocal::Error
  /// from the stream operation (badbit is in exceptions()).
  std::ostream& stream();

  /// Flushes, optionally fsyncs (`sync_to_disk`: file and directory, for durability across a power
  /// loss), and renames the temporary onto the target. Throws gyrocal::Error naming the file on any
  /// failure, in which case the temporary is removed and the target is untouched. Call once.
  void commit(bool sync_to_disk = false);

  /// The final path given to the constructor.
  const std::filesystem::path& target() const { return target_; }

 private:
  class Buffer;
  std::filesystem::path target_;
  bool overwrite_;
  std::filesystem::path temporary_;
  int fd_ = -1;
  std::unique_ptr<Buffer> buffer_;
  std::unique_ptr<std::ostream> stream_;
  bool committed_ = false;
};

/// Writes `content` to `path` through an AtomicOutputFile and commits it. Same errors as above.
void write_file_atomically(const std::filesystem::path& path, std::string_view content, bool overwrite);

}  // namespace gyrocal
