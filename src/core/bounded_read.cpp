#include "gyrocal/core/bounded_read.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <system_error>

#include "gyrocal/core/error.hpp"

namespace gyrocal {

BoundedRead read_bounded(const std::filesystem::path& path, std::size_t max_bytes, std::string_view what,
                         const std::function<bool(std::string_view)>& stop) {
  const std::string name = path.string();
  const auto fail = [&](const std::string& why) {
    throw Error("Cannot read " + std::string(what) + " " + name + ": " + why + ".");
  };
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    const int error = errno;
    if (error == ENOENT) fail("it does not exist");
    fail(std::error_code(error, std::generic_category()).message());
  }
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat status {};
  if (::fstat(fd, &status) == 0 && S_ISDIR(status.st_mode)) fail("it is a directory");
  BoundedRead out;
  constexpr std::size_t kChunk = 64 << 10;
  while (out.text.size() <= max_bytes) {
    const std::size_t old_size = out.text.size();
    // Grown by doubling, but never beyond the limit and one read: a file at the limit is held once, not in a
    // buffer of twice its size.
    if (out.text.capacity() < old_size + kChunk)
      out.text.reserve(std::min(std::max(2 * out.text.capacity(), old_size + kChunk), max_bytes + kChunk));
    out.text.resize(old_size + kChunk);
    const ssize_t count = ::read(fd, out.text.data() + old_size, kChunk);
    if (count < 0) {
      const int error = errno;
      out.text.resize(old_size);
      if (error == EINTR) continue;
      fail(std::error_code(error, std::generic_category()).message());
    }
    out.text.resize(old_size + static_cast<std::size_t>(count));
    if (count == 0) break;
    if (stop && stop(out.text)) {
      out.stopped = true;
      return out;
    }
  }
  out.too_large = out.text.size() > max_bytes;
  return out;
}

}  // namespace gyrocal
