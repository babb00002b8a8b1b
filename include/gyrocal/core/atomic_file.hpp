#pragma once
// Output files that appear whole or not at all (docs/contract.md: "no partial output file is left behind";
// docs/interface.md, "Files").
//
// A regular file (new or replaced): bytes go to a temporary file in the target's folder; commit() renames it
// onto the target, which is atomic on POSIX file systems. Without commit(), the temporary is removed.
// A character device (/dev/null, a terminal) or a FIFO: bytes are written straight to it (no temporary, no
// rename: the device stays what it is); what was written before an error has been delivered.
// A symbolic link is followed to what it names: a regular file is replaced through a temporary beside it
// (the link stays a link), a device or FIFO is written to. A dangling link is refused.
// Anything else (a folder, a socket, a block device) is refused with a sentence that names it: gyrocal
// never replaces anything that is not a regular file.
//
// Temporaries are also removed when the process is ended by SIGINT, SIGTERM or SIGHUP: the first
// temporary installs a handler (unless the signal is ignored) that removes every registered path with
// async-signal-safe calls and then re-raises the signal with its default action, so that the exit status
// still says "killed by signal".
#include <cstdint>
#include <filesystem>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace gyrocal {

class AtomicOutputFile {
 public:
  /// Tag of the constructor that writes to standard output.
  struct StandardOutput {};

  /// Opens `target` as described above. Throws gyrocal::Error if `target` is an existing regular file (or
  /// a link to one) and `overwrite` is false ("… exists; use --force to overwrite"), if it is neither a
  /// regular file nor a character device nor a FIFO, or if the temporary cannot be created. A device or
  /// FIFO is written to whatever `overwrite` says (nothing is replaced). The path "-" is an ordinary file
  /// name here; standard output has its own constructor.
  AtomicOutputFile(std::filesystem::path target, bool overwrite);
  /// Writes to standard output (file descriptor 1, which stays open), after flushing stdout and std::cout.
  explicit AtomicOutputFile(StandardOutput);
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
  /// loss; not for devices and FIFOs), and renames the temporary onto the target. Throws gyrocal::Error
  /// naming the file on any failure, in which case the temporary is removed and the target is untouched.
  /// Call once.
  void commit(bool sync_to_disk = false);

  /// The final path given to the constructor ("-" for standard output).
  const std::filesystem::path& target() const { return target_; }
  /// The path that commit() renames onto: target() with symbolic links resolved.
  const std::filesystem::path& destination() const { return destination_; }
  /// Bytes handed to write() and stream() so far.
  std::uint64_t bytes() const;
  /// True when bytes go straight to the target (standard output, a character device, a FIFO): nothing is
  /// renamed, and the target is not a regular file whose size means anything.
  bool writes_through() const { return direct_; }

 private:
  class Buffer;
  std::filesystem::path target_;
  std::filesystem::path destination_;  ///< target_ with symbolic links resolved: what is renamed onto
  std::string name_;                   ///< how messages name the target
  bool overwrite_ = false;
  bool direct_ = false;  ///< bytes go straight to the target
  bool owns_fd_ = true;  ///< false for standard output
  std::filesystem::path temporary_;
  int registration_ = -1;  ///< slot of temporary_ in the interruption registry
  int fd_ = -1;
  std::unique_ptr<Buffer> buffer_;
  std::unique_ptr<std::ostream> stream_;
  bool committed_ = false;
};

/// Writes `content` to `path` through an AtomicOutputFile and commits it. Same errors as above.
void write_file_atomically(const std::filesystem::path& path, std::string_view content, bool overwrite);

/// A folder of outputs that appears complete or not at all (`gyrocal demo --out DIR`). Files are written
/// into a staging folder (path() names them); commit() moves them into place:
/// - DIR does not exist: the staging folder is created beside it and renamed to DIR (atomic);
/// - DIR is an existing folder: the staging folder is created inside it, and commit() renames each file
///   onto DIR/<name> with SIGINT, SIGTERM and SIGHUP blocked (so an interruption leaves all of the set or
///   none of it); other files in DIR are left alone, and an existing DIR/<name> must be a regular file.
/// Without commit() (an error, or SIGINT/SIGTERM/SIGHUP), the staging folder and its files are removed.
class AtomicOutputFolder {
 public:
  /// Throws gyrocal::Error with a sentence naming the path for "-" (standard output cannot hold a folder),
  /// a path that exists and is not a folder, a parent folder that does not exist, or a staging folder
  /// that cannot be created (a read-only folder, ...). `what` names the outputs in messages ("the demo").
  AtomicOutputFolder(std::filesystem::path target, std::string what);
  ~AtomicOutputFolder();
  AtomicOutputFolder(const AtomicOutputFolder&) = delete;
  AtomicOutputFolder& operator=(const AtomicOutputFolder&) = delete;

  /// Where to write the file `name` now (inside the staging folder). Each name once.
  std::filesystem::path path(const std::string& name);
  /// Where the file `name` will be after commit().
  std::filesystem::path final_path(const std::string& name) const { return target_ / name; }
  /// Moves the files into place. Throws gyrocal::Error naming the path on failure (before any file moved
  /// when a DIR/<name> is not a regular file).
  void commit();

 private:
  std::filesystem::path target_;
  std::string what_;
  bool target_existed_ = false;
  std::filesystem::path staging_;
  int registration_ = -1;
  std::vector<std::pair<std::string, int>> files_;  ///< name, registration slot
  bool committed_ = false;
};

}  // namespace gyrocal
