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
#include <functional>
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
  /// The constructor's checks of `target` without creating or opening anything, so that a command refuses
  /// an output before its work rather than after (docs/interface.md, "Files"): throws the same
  /// gyrocal::Error as the constructor would for a path that is not a file name, a dangling link, something
  /// that is neither a regular file nor a character device nor a FIFO, an existing regular file without
  /// `overwrite`, and a folder where the temporary cannot be created (missing, not a folder, not writable).
  /// The constructor checks again (the file system may change meanwhile).
  static void check(const std::filesystem::path& target, bool overwrite);
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
  /// What the checks found: where a rename goes, how messages name it, whether it is written through.
  struct Inspection {
    std::filesystem::path destination;
    std::string described;
    bool direct = false;
  };
  static Inspection inspect(const std::filesystem::path& target, bool overwrite);
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

/// The one way text reaches standard output (file descriptor 1): whatever stdio holds is flushed first,
/// then `text` is written whole with write(2), so that a failure is seen at once. Throws gyrocal::Error
/// "Cannot write standard output: <reason>." on any failure (a full disk, /dev/full, a closed descriptor).
/// When standard output is a regular file that nothing else wrote to meanwhile, a failure first cuts the
/// file back to its length before gyrocal's first byte (`>> cfg.toml` keeps no half-written section).
/// AtomicOutputFile's standard output (`--json -`) writes through the same function.
void write_standard_output(std::string_view text);

/// Flushes stdout and std::cout and throws the same gyrocal::Error as write_standard_output if either
/// failed at any time (the final check of a command: text written by other means, e.g. a library).
void check_standard_output();

/// A folder of outputs that appears complete or not at all (`gyrocal demo --out DIR`). Files are written
/// into a staging folder (path() names them); commit() moves them into place:
/// - DIR does not exist: the staging folder is created beside it and renamed to DIR (atomic);
/// - DIR is an existing folder: the staging folder is created inside it, and commit() renames each file
///   onto DIR/<name> with SIGINT, SIGTERM and SIGHUP blocked (so an interruption leaves all of the set or
///   none of it); other files in DIR are left alone, and an existing DIR/<name> must be a regular file
///   that the caller's check (path()'s `may_replace`) accepts.
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

  /// Decides whether an existing regular file DIR/<name> may be replaced (it throws gyrocal::Error naming
  /// the file if not); called with the file's path.
  using ReplaceCheck = std::function<void(const std::filesystem::path& existing)>;

  /// Where to write the file `name` now (inside the staging folder). Each name once. When DIR exists,
  /// DIR/<name> is checked at once (so that a command refuses before its work) and again by commit():
  /// anything but a regular file is refused, and an existing regular file is passed to `may_replace` (none:
  /// always replaced).
  std::filesystem::path path(const std::string& name, ReplaceCheck may_replace = {});
  /// Where the file `name` will be after commit().
  std::filesystem::path final_path(const std::string& name) const { return target_ / name; }
  /// Moves the files into place. Throws gyrocal::Error naming the path on failure (before any file moved
  /// when a DIR/<name> is not a regular file or its `may_replace` refuses it).
  void commit();

 private:
  std::filesystem::path target_;
  std::string what_;
  bool target_existed_ = false;
  std::filesystem::path staging_;
  int registration_ = -1;
  struct Staged {
    std::string name;
    int registration = -1;
    ReplaceCheck may_replace;
  };
  /// Throws unless DIR/<file.name> is absent or a regular file that file.may_replace accepts.
  void check_destination(const Staged& file) const;
  std::vector<Staged> files_;
  bool committed_ = false;
};

}  // namespace gyrocal
