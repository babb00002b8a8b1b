#include "gyrocal/core/atomic_file.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <mutex>
#include <random>
#include <streambuf>
#include <string>
#include <system_error>
#include <vector>

#include "gyrocal/core/error.hpp"

namespace gyrocal {
namespace {

constexpr std::size_t kBufferBytes = std::size_t{1} << 20;
constexpr std::size_t kDirectBytes = std::size_t{64} << 10;

std::string errno_text(int error) {
  return std::error_code(error, std::generic_category()).message();
}

std::string quoted(const std::filesystem::path& path) {
  return "'" + path.string() + "'";
}

/// `what` is a verb phrase, `name` the target as messages show it ("'out.json'", "standard output").
[[noreturn]] void throw_io_error(const std::string& what, const std::string& name, int error) {
  throw Error("Cannot " + what + " " + name + ": " + errno_text(error) + ".");
}

[[noreturn]] void throw_exists(const std::filesystem::path& path) {
  throw Error("Output file '" + path.string() + "' already exists; use --force to overwrite it.");
}

bool path_exists(const std::filesystem::path& path) {
  std::error_code ignored;
  // symlink_status: a dangling link is an existing entry that a rename would replace.
  return std::filesystem::exists(std::filesystem::symlink_status(path, ignored));
}

/// A name that no other writer (thread, process) picks: pid, a process-wide counter and randomness.
std::filesystem::path temporary_name(const std::filesystem::path& folder, const std::string& stem) {
  static std::atomic<unsigned long> counter{0};
  static thread_local std::mt19937_64 random{std::random_device{}()};
  const std::string name = "." + stem + ".tmp-" + std::to_string(::getpid()) + "-" +
                           std::to_string(counter++) + "-" + std::to_string(random() % 1000000);
  return folder / name;
}

/// What a file type is, for a refusal ("a folder").
std::string type_text(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISBLK(mode)) return "a block device";
  return "neither a regular file, a character device nor a FIFO";
}

constexpr std::string_view kWhatIsWritten =
    "gyrocal writes to a regular file, a character device (such as /dev/null), a FIFO or standard "
    "output ('-'), and never replaces anything else";

// ---- Paths to remove when the process is interrupted ----------------------------------------------------
//
// A fixed table, so that the signal handler needs no allocation or lock: a slot is free, being filled, or
// live. The handler unlinks live files, then removes live folders (latest first), then re-raises.

constexpr int kSlots = 64;
constexpr std::size_t kPathBytes = 4096;
enum SlotState : int { kFree = 0, kFilling = 1, kLive = 2 };

struct Slot {
  std::atomic<int> state{kFree};
  bool directory = false;
  char path[kPathBytes] = {};
};

Slot g_slots[kSlots];

constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE};  // SIGPIPE: `gyrocal demo | head -c1`

extern "C" void remove_registered_paths(int signal_number) {
  for (Slot& slot : g_slots)
    if (slot.state.load(std::memory_order_acquire) == kLive && !slot.directory) ::unlink(slot.path);
  for (int i = kSlots - 1; i >= 0; --i)
    if (g_slots[i].state.load(std::memory_order_acquire) == kLive && g_slots[i].directory)
      ::rmdir(g_slots[i].path);
  // The signal is blocked while its handler runs: raised again with the default action, it ends the
  // process as soon as the handler returns, and the exit status says which signal it was.
  ::signal(signal_number, SIG_DFL);
  ::raise(signal_number);
}

void install_signal_handlers() {
  static const bool installed = [] {
    for (const int signal_number : kSignals) {
      struct sigaction old {};
      if (::sigaction(signal_number, nullptr, &old) != 0) continue;
      // An ignored signal (nohup, a background job) stays ignored; someone else's handler stays too.
      if ((old.sa_flags & SA_SIGINFO) != 0 || old.sa_handler != SIG_DFL) continue;
      struct sigaction action {};
      action.sa_handler = remove_registered_paths;
      sigemptyset(&action.sa_mask);
      for (const int other : kSignals) sigaddset(&action.sa_mask, other);
      ::sigaction(signal_number, &action, nullptr);
    }
    return true;
  }();
  (void)installed;
}

/// Registers `path` for removal on interruption; returns its slot, or -1 if it could not be registered
/// (the table is full or the path too long: the path is then removed only on an ordinary error).
int register_for_removal(const std::filesystem::path& path, bool directory) {
  install_signal_handlers();
  std::error_code ec;
  std::string text = std::filesystem::absolute(path, ec).string();
  if (ec) text = path.string();
  if (text.size() >= kPathBytes) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = kFree;
    if (!g_slots[i].state.compare_exchange_strong(expected, kFilling)) continue;
    std::memcpy(g_slots[i].path, text.c_str(), text.size() + 1);
    g_slots[i].directory = directory;
    g_slots[i].state.store(kLive, std::memory_order_release);
    return i;
  }
  return -1;
}

void unregister(int& slot) {
  if (slot >= 0) g_slots[slot].state.store(kFree, std::memory_order_release);
  slot = -1;
}

/// Blocks SIGINT, SIGTERM, SIGHUP and SIGPIPE on the calling thread for its lifetime; a signal that arrives
/// meanwhile is delivered afterwards.
class SignalsBlocked {
 public:
  SignalsBlocked() {
    sigset_t set;
    sigemptyset(&set);
    for (const int signal_number : kSignals) sigaddset(&set, signal_number);
    ::pthread_sigmask(SIG_BLOCK, &set, &old_);
  }
  ~SignalsBlocked() { ::pthread_sigmask(SIG_SETMASK, &old_, nullptr); }
  SignalsBlocked(const SignalsBlocked&) = delete;
  SignalsBlocked& operator=(const SignalsBlocked&) = delete;

 private:
  sigset_t old_;
};

// ---- Standard output -------------------------------------------------------------------------------------
//
// Every byte gyrocal writes to standard output goes through write_to_standard_output, which sees each
// failure at once. When standard output is a regular file, where gyrocal's bytes began is remembered, so that
// a failure can take them back (`>> cfg.toml` on a full disk keeps cfg.toml as it was).

struct StandardOutputState {
  bool started = false;       ///< the first byte was written (start and regular are known)
  bool regular = false;       ///< standard output is a regular file whose offset is known
  off_t start = 0;            ///< the file's length before gyrocal's first byte
  std::uint64_t written = 0;  ///< bytes gyrocal wrote to it since
};

std::mutex g_standard_output_mutex;
StandardOutputState g_standard_output;

const std::string kStandardOutputName = "standard output";

/// Cuts standard output back to where gyrocal's first byte went, when it is a regular file that ends where
/// gyrocal's last byte went (nothing else wrote to it, and gyrocal wrote at its end).
void take_back_standard_output() {
  StandardOutputState& state = g_standard_output;
  if (!state.regular || state.written == 0) return;
  struct stat status {};
  if (::fstat(STDOUT_FILENO, &status) != 0 || !S_ISREG(status.st_mode)) return;
  if (static_cast<std::uint64_t>(status.st_size) != static_cast<std::uint64_t>(state.start) + state.written)
    return;
  if (::ftruncate(STDOUT_FILENO, state.start) != 0) return;
  const int flags = ::fcntl(STDOUT_FILENO, F_GETFL);
  if (flags >= 0 && (flags & O_APPEND) == 0) ::lseek(STDOUT_FILENO, state.start, SEEK_SET);
  state.written = 0;
}

/// Writes `count` bytes to file descriptor 1 (the caller holds g_standard_output_mutex). Throws
/// gyrocal::Error naming standard output, after take_back_standard_output, on any failure.
void write_to_standard_output(const char* bytes, std::size_t count) {
  StandardOutputState& state = g_standard_output;
  if (!state.started) {
    state.started = true;
    struct stat status {};
    if (::fstat(STDOUT_FILENO, &status) == 0 && S_ISREG(status.st_mode)) {
      const int flags = ::fcntl(STDOUT_FILENO, F_GETFL);
      const off_t start =
          flags >= 0 && (flags & O_APPEND) != 0 ? status.st_size : ::lseek(STDOUT_FILENO, 0, SEEK_CUR);
      if (start >= 0) {
        state.regular = true;
        state.start = start;
      }
    }
  }
  while (count > 0) {
    const ssize_t written = ::write(STDOUT_FILENO, bytes, count);
    if (written < 0) {
      if (errno == EINTR) continue;
      const int error = errno;
      take_back_standard_output();
      throw_io_error("write", kStandardOutputName, error);
    }
    bytes += written;
    count -= static_cast<std::size_t>(written);
    state.written += static_cast<std::uint64_t>(written);
  }
}

/// Flushes std::cout and stdout (what the program printed by other means comes first) and throws if they
/// failed, now or before (the caller holds g_standard_output_mutex).
void flush_standard_streams() {
  std::cout.flush();
  if (std::fflush(stdout) != 0) {
    const int error = errno;
    take_back_standard_output();
    throw_io_error("write", kStandardOutputName, error);
  }
  if (std::ferror(stdout) || !std::cout) {
    take_back_standard_output();
    throw Error("Cannot write " + kStandardOutputName + ": an earlier write failed.");
  }
}

}  // namespace

void write_standard_output(std::string_view text) {
  const std::lock_guard<std::mutex> lock(g_standard_output_mutex);
  flush_standard_streams();
  write_to_standard_output(text.data(), text.size());
}

void check_standard_output() {
  const std::lock_guard<std::mutex> lock(g_standard_output_mutex);
  flush_standard_streams();
}

/// The write buffer, as a streambuf so that stream() and write() share it. Errors throw
/// gyrocal::Error; std::ostream rethrows them because badbit is in its exceptions().
class AtomicOutputFile::Buffer : public std::streambuf {
 public:
  /// `standard_output`: fd is standard output, written through write_to_standard_output.
  Buffer(int fd, const std::string& name, bool standard_output = false)
      : fd_(fd), name_(name), standard_output_(standard_output), data_(kBufferBytes) {
    setp(data_.data(), data_.data() + data_.size());
  }

  /// Writes the buffered bytes to the file.
  void flush_buffer() {
    write_all(pbase(), static_cast<std::size_t>(pptr() - pbase()));
    setp(data_.data(), data_.data() + data_.size());
  }

  bool failed() const { return failed_; }
  std::uint64_t bytes() const { return flushed_ + static_cast<std::uint64_t>(pptr() - pbase()); }

 protected:
  int_type overflow(int_type c) override {
    flush_buffer();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }

  std::streamsize xsputn(const char* s, std::streamsize n) override {
    const auto count = static_cast<std::size_t>(n);
    if (count >= kDirectBytes) {
      // Large blocks (e.g. a RecordWriter's buffer) skip the copy.
      flush_buffer();
      write_all(s, count);
    } else {
      if (count > static_cast<std::size_t>(epptr() - pptr())) flush_buffer();
      std::copy(s, s + count, pptr());
      pbump(static_cast<int>(count));
    }
    return n;
  }

  int sync() override {
    flush_buffer();
    return 0;
  }

 private:
  void write_all(const char* bytes, std::size_t count) {
    if (failed_) throw Error("Cannot write " + name_ + ": an earlier write failed.");
    if (standard_output_) {
      // Standard output: the one writer, which takes back a regular file's bytes on failure.
      const std::lock_guard<std::mutex> lock(g_standard_output_mutex);
      try {
        write_to_standard_output(bytes, count);
      } catch (...) {
        failed_ = true;
        throw;
      }
      flushed_ += count;
      return;
    }
    while (count > 0) {
      const ssize_t written = ::write(fd_, bytes, count);
      if (written < 0) {
        if (errno == EINTR) continue;
        failed_ = true;
        throw_io_error("write", name_, errno);
      }
      bytes += written;
      count -= static_cast<std::size_t>(written);
      flushed_ += static_cast<std::uint64_t>(written);
    }
  }

  int fd_;
  const std::string& name_;
  bool standard_output_;
  std::vector<char> data_;
  std::uint64_t flushed_ = 0;
  bool failed_ = false;
};

AtomicOutputFile::Inspection AtomicOutputFile::inspect(const std::filesystem::path& target, bool overwrite) {
  const std::string name = quoted(target);
  if (target.filename().empty()) throw Error("Output path " + name + " is not a file name.");
  Inspection found{target, name, false};
  struct stat status {};
  const bool exists = ::lstat(target.c_str(), &status) == 0;
  if (!exists && errno != ENOENT) throw_io_error("write", name, errno);
  if (exists && S_ISLNK(status.st_mode)) {
    // A link is followed to what it names: the link stays, its target is written (docs/interface.md).
    std::error_code ec;
    const std::filesystem::path link = std::filesystem::read_symlink(target, ec);
    const std::filesystem::path resolved = std::filesystem::canonical(target, ec);
    if (ec || ::stat(resolved.c_str(), &status) != 0) {
      throw Error("Output path " + name + " is a symbolic link to " + quoted(link) +
                  ", which does not exist; gyrocal follows a link only to an existing file.");
    }
    found.destination = resolved;
    found.described = name + " (a symbolic link to " + quoted(resolved) + ")";
  }
  if (exists) {
    // Written straight through: a device or FIFO is never replaced by a file.
    if (S_ISCHR(status.st_mode) || S_ISFIFO(status.st_mode)) {
      found.direct = true;
      return found;
    }
    if (!S_ISREG(status.st_mode)) {
      throw Error("Output path " + found.described + " is " + type_text(status.st_mode) + "; " +
                  std::string(kWhatIsWritten) + ".");
    }
    if (!overwrite) throw_exists(target);
  }
  return found;
}

void AtomicOutputFile::check(const std::filesystem::path& target, bool overwrite) {
  const Inspection found = inspect(target, overwrite);
  if (found.direct) return;  // a device or FIFO is not opened here: opening a FIFO waits for its reader
  // The temporary goes beside the destination: its folder must exist and take a new file.
  const std::filesystem::path folder =
      found.destination.has_parent_path() ? found.destination.parent_path() : std::filesystem::path(".");
  struct stat status {};
  int error = 0;
  if (::stat(folder.c_str(), &status) != 0)
    error = errno;
  else if (!S_ISDIR(status.st_mode))
    error = ENOTDIR;
  else if (::access(folder.c_str(), W_OK | X_OK) != 0)
    error = errno;
  if (error != 0) throw_io_error("create a file beside", quoted(target), error);
}

AtomicOutputFile::AtomicOutputFile(std::filesystem::path target, bool overwrite)
    : target_(std::move(target)), destination_(target_), name_(quoted(target_)), overwrite_(overwrite) {
  const Inspection found = inspect(target_, overwrite_);
  destination_ = found.destination;
  if (found.direct) {
    fd_ = ::open(destination_.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
    if (fd_ < 0) throw_io_error("write", found.described, errno);
    struct stat opened {};
    if (::fstat(fd_, &opened) != 0 || !(S_ISCHR(opened.st_mode) || S_ISFIFO(opened.st_mode))) {
      ::close(fd_);
      fd_ = -1;
      throw Error("Output path " + found.described +
                  " changed while it was being opened; nothing was written.");
    }
    direct_ = true;
    buffer_ = std::make_unique<Buffer>(fd_, name_);
    stream_ = std::make_unique<std::ostream>(buffer_.get());
    stream_->exceptions(std::ios::badbit);
    return;
  }
  for (int attempt = 0; fd_ < 0; ++attempt) {
    temporary_ = temporary_name(destination_.parent_path(), destination_.filename().string());
    // Registered before it exists, so that no interruption can come between its creation and its
    // registration (removing a path that does not exist yet is harmless).
    registration_ = register_for_removal(temporary_, /*directory=*/false);
    // 0666 so that the process umask gives the file the permissions of any newly created file.
    fd_ = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd_ < 0) {
      const int error = errno;
      unregister(registration_);
      if (error != EEXIST || attempt == 100) {
        temporary_.clear();
        throw_io_error("create a file beside", name_, error);
      }
    }
  }
  buffer_ = std::make_unique<Buffer>(fd_, name_);
  stream_ = std::make_unique<std::ostream>(buffer_.get());
  stream_->exceptions(std::ios::badbit);
}

AtomicOutputFile::AtomicOutputFile(StandardOutput)
    : target_("-"), destination_("-"), name_(kStandardOutputName), direct_(true), owns_fd_(false) {
  // Whatever the program printed before comes first; a failure there is a failure of this output.
  {
    const std::lock_guard<std::mutex> lock(g_standard_output_mutex);
    flush_standard_streams();
  }
  fd_ = STDOUT_FILENO;
  buffer_ = std::make_unique<Buffer>(fd_, name_, /*standard_output=*/true);
  stream_ = std::make_unique<std::ostream>(buffer_.get());
  stream_->exceptions(std::ios::badbit);
}

AtomicOutputFile::~AtomicOutputFile() {
  if (fd_ >= 0 && owns_fd_) ::close(fd_);
  if (!committed_ && !temporary_.empty()) ::unlink(temporary_.c_str());
  unregister(registration_);
}

void AtomicOutputFile::write(std::string_view bytes) {
  buffer_->sputn(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::ostream& AtomicOutputFile::stream() {
  return *stream_;
}

std::uint64_t AtomicOutputFile::bytes() const {
  return buffer_->bytes();
}

void AtomicOutputFile::commit(bool sync_to_disk) {
  if (committed_ || fd_ < 0) throw Error("Output file " + name_ + " was already committed.");
  if (direct_) {
    if (!*stream_ || buffer_->failed()) throw Error("Cannot write " + name_ + ": an earlier write failed.");
    buffer_->flush_buffer();
    const int fd = fd_;
    fd_ = -1;
    committed_ = true;
    if (owns_fd_ && ::close(fd) != 0) throw_io_error("write", name_, errno);
    return;
  }
  try {
    if (!*stream_ || buffer_->failed()) throw Error("Cannot write " + name_ + ": an earlier write failed.");
    buffer_->flush_buffer();
    if (sync_to_disk && ::fsync(fd_) != 0) throw_io_error("write", name_, errno);
    const int fd = fd_;
    fd_ = -1;
    // close() can report a deferred write error (e.g. on network file systems).
    if (::close(fd) != 0) throw_io_error("write", name_, errno);

    if (overwrite_) {
      // Only a regular file is ever replaced, also if something else appeared since the constructor.
      struct stat status {};
      if (::lstat(destination_.c_str(), &status) == 0 && !S_ISREG(status.st_mode)) {
        throw Error("Output path " + name_ + " became " + type_text(status.st_mode) +
                    " while it was being written; " + std::string(kWhatIsWritten) + ".");
      }
      if (::rename(temporary_.c_str(), destination_.c_str()) != 0) throw_io_error("create", name_, errno);
    } else {
      // RENAME_NOREPLACE closes the race with a file created after the constructor's check.
      if (::renameat2(AT_FDCWD, temporary_.c_str(), AT_FDCWD, destination_.c_str(), RENAME_NOREPLACE) != 0) {
        if (errno == EEXIST) throw_exists(target_);
        // Some file systems do not support the flag; fall back to check-then-rename.
        if (errno != EINVAL && errno != ENOSYS) throw_io_error("create", name_, errno);
        if (path_exists(destination_)) throw_exists(target_);
        if (::rename(temporary_.c_str(), destination_.c_str()) != 0) throw_io_error("create", name_, errno);
      }
    }
    committed_ = true;
    unregister(registration_);
  } catch (...) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    ::unlink(temporary_.c_str());
    temporary_.clear();
    unregister(registration_);
    throw;
  }
  if (sync_to_disk) {
    // The rename is durable only once the directory is synced.
    const std::filesystem::path directory =
        destination_.has_parent_path() ? destination_.parent_path() : std::filesystem::path(".");
    const int dir_fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir_fd >= 0) {
      ::fsync(dir_fd);
      ::close(dir_fd);
    }
  }
}

void write_file_atomically(const std::filesystem::path& path, std::string_view content, bool overwrite) {
  AtomicOutputFile file(path, overwrite);
  file.write(content);
  file.commit();
}

// ---- AtomicOutputFolder ---------------------------------------------------------------------------------

AtomicOutputFolder::AtomicOutputFolder(std::filesystem::path target, std::string what)
    : what_(std::move(what)) {
  if (target == "-") {
    throw Error("Cannot write " + what_ +
                " to '-': standard output cannot hold a folder of files; give the name of a folder.");
  }
  if (target.empty()) throw Error("No folder was given for " + what_ + ".");
  // "out/" names the folder "out".
  while (!target.has_filename() && target.has_relative_path()) target = target.parent_path();
  target_ = target;
  const std::string name = quoted(target_);
  std::filesystem::path parent;
  struct stat status {};
  if (::stat(target_.c_str(), &status) == 0) {
    // A link to a folder is that folder.
    if (!S_ISDIR(status.st_mode)) {
      throw Error("Cannot write " + what_ + " into " + name + ": it exists and is " +
                  (S_ISREG(status.st_mode) ? std::string("a file") : type_text(status.st_mode)) +
                  ", not a folder.");
    }
    target_existed_ = true;
    parent = target_;
  } else if (errno == ENOENT) {
    if (::lstat(target_.c_str(), &status) == 0) {
      std::error_code ec;
      throw Error("Cannot write " + what_ + " into " + name + ": it is a symbolic link to " +
                  quoted(std::filesystem::read_symlink(target_, ec)) + ", which does not exist.");
    }
    parent = target_.has_parent_path() ? target_.parent_path() : std::filesystem::path(".");
    if (::stat(parent.c_str(), &status) != 0) {
      throw Error("Cannot write " + what_ + " into " + name + ": its parent folder " + quoted(parent) +
                  (errno == ENOENT ? std::string(" does not exist") : ": " + errno_text(errno)) + ".");
    }
    if (!S_ISDIR(status.st_mode))
      throw Error("Cannot write " + what_ + " into " + name + ": " + quoted(parent) + " is not a folder.");
  } else {
    throw Error("Cannot write " + what_ + " into " + name + ": " + errno_text(errno) + ".");
  }
  const std::string stem = target_existed_ ? "gyrocal" : target_.filename().string();
  for (int attempt = 0;; ++attempt) {
    staging_ = temporary_name(parent, stem);
    // Registered before it exists, as AtomicOutputFile's temporary is.
    registration_ = register_for_removal(staging_, /*directory=*/true);
    if (::mkdir(staging_.c_str(), 0777) == 0) break;
    const int error = errno;
    unregister(registration_);
    if (error != EEXIST || attempt == 100) {
      staging_.clear();
      throw Error("Cannot write " + what_ + " into " + name + ": cannot create a folder in " +
                  quoted(parent) + ": " + errno_text(error) + ".");
    }
  }
}

AtomicOutputFolder::~AtomicOutputFolder() {
  if (!committed_ && !staging_.empty()) {
    std::error_code ignored;
    std::filesystem::remove_all(staging_, ignored);
  }
  for (Staged& file : files_) unregister(file.registration);
  unregister(registration_);
}

std::filesystem::path AtomicOutputFolder::path(const std::string& name, ReplaceCheck may_replace) {
  Staged file{name, -1, std::move(may_replace)};
  // Before any work: what commit() would refuse is refused now.
  check_destination(file);
  const std::filesystem::path p = staging_ / name;
  file.registration = register_for_removal(p, /*directory=*/false);
  files_.push_back(std::move(file));
  return p;
}

void AtomicOutputFolder::check_destination(const Staged& file) const {
  if (!target_existed_) return;  // a new folder: nothing in it is replaced
  struct stat status {};
  const std::filesystem::path destination = target_ / file.name;
  if (::lstat(destination.c_str(), &status) != 0) return;
  if (!S_ISREG(status.st_mode)) {
    throw Error("Cannot write " + what_ + " into " + quoted(target_) + ": " + quoted(destination) +
                " exists and is " +
                (S_ISLNK(status.st_mode) ? std::string("a symbolic link") : type_text(status.st_mode)) +
                ", which gyrocal does not replace; nothing was changed.");
  }
  if (file.may_replace) file.may_replace(destination);
}

void AtomicOutputFolder::commit() {
  if (committed_) throw Error("The folder " + quoted(target_) + " was already committed.");
  const std::string name = quoted(target_);
  if (!target_existed_) {
    if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), RENAME_NOREPLACE) != 0) {
      const int error = errno;
      if (error == EEXIST || error == ENOTEMPTY)
        throw Error("Cannot write " + what_ + " into " + name +
                    ": it was created while the outputs were "
                    "being written; nothing was changed.");
      if (error != EINVAL && error != ENOSYS)
        throw Error("Cannot create " + name + ": " + errno_text(error) + ".");
      if (path_exists(target_))
        throw Error("Cannot write " + what_ + " into " + name +
                    ": it was created while the outputs were "
                    "being written; nothing was changed.");
      if (::rename(staging_.c_str(), target_.c_str()) != 0)
        throw Error("Cannot create " + name + ": " + errno_text(errno) + ".");
    }
  } else {
    // Every file is checked before any is moved, and no signal interrupts the moves.
    for (const Staged& file : files_) check_destination(file);
    const SignalsBlocked blocked;
    for (const Staged& file : files_) {
      const std::filesystem::path from = staging_ / file.name, destination = target_ / file.name;
      if (::rename(from.c_str(), destination.c_str()) != 0)
        throw Error("Cannot create " + quoted(destination) + ": " + errno_text(errno) + ".");
    }
    ::rmdir(staging_.c_str());
    for (Staged& file : files_) unregister(file.registration);
    unregister(registration_);
    committed_ = true;
    return;
  }
  committed_ = true;
  for (Staged& file : files_) unregister(file.registration);
  unregister(registration_);
}

}  // namespace gyrocal
