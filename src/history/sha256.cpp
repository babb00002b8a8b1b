// SHA-256 through OpenSSL's EVP interface (history/sha256.hpp).
#include "gyrocal/history/sha256.hpp"

#include <fcntl.h>
#include <openssl/evp.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"

namespace gyrocal::history {
namespace {

struct MdCtxFree {
  void operator()(EVP_MD_CTX* c) const { EVP_MD_CTX_free(c); }
};
using MdCtx = std::unique_ptr<EVP_MD_CTX, MdCtxFree>;

/// An EVP context initialised for SHA-256 (an internal error if libcrypto cannot: no input causes it).
MdCtx new_context() {
  MdCtx ctx(EVP_MD_CTX_new());
  if (!ctx || EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("OpenSSL could not start a SHA-256 digest");
  return ctx;
}

void update(EVP_MD_CTX* ctx, const void* data, std::size_t n) {
  if (n > 0 && EVP_DigestUpdate(ctx, data, n) != 1)
    throw std::runtime_error("OpenSSL's SHA-256 update failed");
}

std::string finish(EVP_MD_CTX* ctx) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  if (EVP_DigestFinal_ex(ctx, digest, &n) != 1 || n != 32)
    throw std::runtime_error("OpenSSL's SHA-256 did not finish");
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex(64, '0');
  for (unsigned i = 0; i < n; ++i) {
    hex[2 * i] = kHex[digest[i] >> 4];
    hex[2 * i + 1] = kHex[digest[i] & 15];
  }
  return hex;
}

struct FileClose {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

}  // namespace

std::string sha256_hex(std::string_view bytes) {
  MdCtx ctx = new_context();
  update(ctx.get(), bytes.data(), bytes.size());
  return finish(ctx.get());
}

std::string sha256_file(const std::filesystem::path& path, std::string_view what) {
  // Opened without blocking (a FIFO would wait for a writer), then only a regular file is read: a pipe or a
  // device is read once (its SHA-256 would identify nothing) or never ends.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw Error(fmt::format("Cannot read {} {}: {}.", what, path.string(), std::strerror(errno)));
  std::unique_ptr<std::FILE, FileClose> f(::fdopen(fd, "rb"));
  if (!f) {
    ::close(fd);
    throw Error(fmt::format("Cannot read {} {}: {}.", what, path.string(), std::strerror(errno)));
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0)
    throw Error(fmt::format("Cannot read {} {}: {}.", what, path.string(), std::strerror(errno)));
  if (S_ISDIR(st.st_mode))
    throw Error(fmt::format("Cannot read {} {}: it is a folder.", what, path.string()));
  if (!S_ISREG(st.st_mode))
    throw Error(
        fmt::format("Cannot take the SHA-256 of {} {}: it is not a regular file (a pipe or a device).", what,
                    path.string()));
  MdCtx ctx = new_context();
  std::vector<unsigned char> chunk(std::size_t{1} << 20);  // 1 MiB at a time
  for (;;) {
    const std::size_t n = std::fread(chunk.data(), 1, chunk.size(), f.get());
    update(ctx.get(), chunk.data(), n);
    if (n < chunk.size()) {
      if (std::ferror(f.get()))
        throw Error(fmt::format("Cannot read {} {}: {}.", what, path.string(), std::strerror(errno)));
      break;
    }
  }
  return finish(ctx.get());
}

bool is_sha256_hex(std::string_view text) {
  if (text.size() != 64) return false;
  for (const char c : text)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

}  // namespace gyrocal::history
