#include "gyrocal/core/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
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

[[noreturn]] void throw_io_error(const std::string& what, const std::filesystem::path& path, int error) {
  throw Error("Cannot " + what + " '" + path.string() + "': " + errno_text(error) + ".");
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
std::filesystem::path temporary_name(const std::filesystem::path& target) {
  static std::atomic<unsigned long> counter{0};
  static thread_local std::mt19937_64 random{std::random_device{}()};
  const std::string name = "." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                           std::to_string(counter++) + "-" + std::to_string(random() % 1000000);
  return target.parent_path() / name;
}

}  // namespace

/// The write buffer, as a streambuf so that stream() and write() share it. Errors throw
/// gyrocal::Error; std::ostream rethrows them because badbit is in its exceptions().
class AtomicOutputFile::Buffer : public std::streambuf {
 public:
  Buffer(int fd, const std::filesystem::path& target) : fd_(fd), target_(target), data_(kBufferBytes) {
    setp(data_.data(), data_.data() + data_.size());
  }

  /// Writes the buffered bytes to the file.
  void flush_buffer() {
    write_all(pbase(), static_cast<std::size_t>(pptr() - pbase()));
    setp(data_.data(), data_.data() + data_.size());
  }

  bool failed() const { return failed_; }

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
    if (failed_) throw Error("Cannot write '" + target_.string() + "': an earlier write failed.");
    while (count > 0) {
      const ssize_t written = ::write(fd_, bytes, count);
      if (written < 0) {
        if (errno == EINTR) continue;
        failed_ = true;
        throw_io_error("write", target_, errno);
      }
      bytes += written;
      count -= static_cast<std::size_t>(written);
    }
  }

  int fd_;
  const std::filesystem::path& target_;
  std::vector<char> data_;
  bool failed_ = false;
};

AtomicOutputFile::AtomicOutputFile(std::filesystem::path target, bool overwrite)
    : target_(std::move(target)), overwrite_(overwrite) {
  if (target_.filename().empty()) throw Error("Output path '" + target_.string() + "' is not a file name.");
  if (!overwrite_ && path_exists(target_)) throw_exists(target_);
  for (int attempt = 0; fd_ < 0; ++attempt) {
    temporary_ = temporary_name(target_);
    // 0666 so that the process umask gives the file the permissions of any newly created file.
    fd_ = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd_ < 0 && (errno != EEXIST || attempt == 100))
      throw_io_error("create a file beside", target_, errno);
  }
  buffer_ = std::make_unique<Buffer>(fd_, target_);
  stream_ = std::make_unique<std::ostream>(buffer_.get());
  stream_->exceptions(std::ios::badbit);
}

AtomicOutputFile::~AtomicOutputFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_ && !temporary_.empty()) ::unlink(temporary_.c_str());
}

void AtomicOutputFile::write(std::string_view bytes) {
  buffer_->sputn(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::ostream& AtomicOutputFile::stream() {
  return *stream_;
}

void AtomicOutputFile::commit(bool sync_to_disk) {
  if (committed_ || fd_ < 0) throw Error("Output file '" + target_.string() + "' was already committed.");
  try {
    if (!*stream_ || buffer_->failed()) {
      throw Error("Cannot write '" + target_.string() + "': an earlier write failed.");
    }
    buffer_->flush_buffer();
    if (sync_to_disk && ::fsync(fd_) != 0) throw_io_error("write", target_, errno);
    const int fd = fd_;
    fd_ = -1;
    // close() can report a deferred write error (e.g. on network file systems).
    if (::close(fd) != 0) throw_io_error("write", target_, errno);

    if (overwrite_) {
      if (::rename(temporary_.c_str(), target_.c_str()) != 0) throw_io_error("create", target_, errno);
    } else {
      // RENAME_NOREPLACE closes the race with a file created after the constructor's check.
      if (::renameat2(AT_FDCWD, temporary_.c_str(), AT_FDCWD, target_.c_str(), RENAME_NOREPLACE) != 0) {
        if (errno == EEXIST) throw_exists(target_);
        // Some file systems do not support the flag; fall back to check-then-rename.
        if (errno != EINVAL && errno != ENOSYS) throw_io_error("create", target_, errno);
        if (path_exists(target_)) throw_exists(target_);
        if (::rename(temporary_.c_str(), target_.c_str()) != 0) throw_io_error("create", target_, errno);
      }
    }
    committed_ = true;
  } catch (...) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    ::unlink(temporary_.c_str());
    temporary_.clear();
    throw;
  }
  if (sync_to_disk) {
    // The rename is durable only once the directory is synced.
    const std::filesystem::path directory = target_.has_parent_path() ? target_.parent_path() : ".";
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

}  // namespace gyrocal
