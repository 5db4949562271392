// Files read whole and written atomically (src/io/atomic_file.h): what every reader and writer of
// flexkin's files shares.
#include "io/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <fstream>
#include <ostream>
#include <streambuf>
#include <string>
#include <system_error>

#include "flexkin/error.h"

namespace flexkin {
namespace {

std::system_error SystemError(int err, const std::string& what) {
  return std::system_error(err != 0 ? err : EIO, std::generic_category(), what);
}

// A stream buffer over a POSIX file descriptor that remembers the errno of a failed write.
class FdStreamBuf : public std::streambuf {
 public:
  explicit FdStreamBuf(int fd) : fd_(fd) { setp(buffer_, buffer_ + sizeof buffer_); }
  int error() const { return error_; }

 protected:
  int_type overflow(int_type c) override {
    if (Drain() != 0) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return Drain(); }

 private:
  int Drain() {
    const char* p = pbase();
    size_t left = static_cast<size_t>(pptr() - pbase());
    while (left > 0) {
      const ssize_t n = ::write(fd_, p, left);
      if (n < 0) {
        if (errno == EINTR) continue;
        error_ = errno;
        return -1;
      }
      p += n;
      left -= static_cast<size_t>(n);
    }
    setp(buffer_, buffer_ + sizeof buffer_);
    return 0;
  }

  int fd_;
  int error_ = 0;
  char buffer_[1 << 16];
};

// The process umask, read without changing it (umask(2) would, racing other threads).
mode_t CurrentUmask() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("Umask:", 0) == 0) return static_cast<mode_t>(std::stoul(line.substr(6), 0, 8));
  }
  return 022;
}

// The temporary file until it is renamed into place: closed and removed unless committed.
struct TempFile {
  std::string name;
  int fd = -1;
  bool committed = false;
  ~TempFile() {
    if (fd >= 0) ::close(fd);
    if (!committed) ::unlink(name.c_str());
  }
};

}  // namespace

std::string ReadTextFile(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) throw SystemError(errno, "cannot read '" + path + "'");
  std::string text;
  char buffer[1 << 16];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, file)) > 0) text.append(buffer, n);
  const int err = errno;
  const bool failed = std::ferror(file) != 0;
  std::fclose(file);
  if (failed) throw SystemError(err, "cannot read '" + path + "'");
  return text;
}

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  if (path.empty()) throw InputError("path", "is empty; expected a file name");
  const size_t slash = path.rfind('/');
  const std::string dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::string what = "cannot write '" + path + "'";
  struct stat existing;
  mode_t mode = 0666 & ~CurrentUmask();
  if (base.empty() || (::stat(path.c_str(), &existing) == 0 && S_ISDIR(existing.st_mode))) {
    throw SystemError(EISDIR, what);
  }
  if (::stat(path.c_str(), &existing) == 0) mode = existing.st_mode & 07777;

  TempFile temp;
  temp.name = dir + "." + base + ".tmp-XXXXXX";
  temp.fd = ::mkstemp(temp.name.data());
  if (temp.fd < 0) {
    temp.committed = true;  // nothing to remove
    throw SystemError(errno, what + " (creating a temporary file in its directory failed)");
  }
  {
    FdStreamBuf buffer(temp.fd);
    std::ostream out(&buffer);
    try {
      write(out);
      out.flush();
    } catch (...) {
      // A failed write(2) is the cause, whatever the writer made of it: report its errno.
      if (buffer.error() != 0) throw SystemError(buffer.error(), what);
      throw;
    }
    if (!out || buffer.error() != 0) throw SystemError(buffer.error(), what);
  }
  if (::fchmod(temp.fd, mode) != 0) throw SystemError(errno, what);
  // Data on disk before the rename, so a crash leaves the old file or the whole new one.
  if (::fsync(temp.fd) != 0 && errno != EINVAL && errno != EROFS) {
    throw SystemError(errno, what);
  }
  const int fd = temp.fd;
  temp.fd = -1;
  if (::close(fd) != 0) throw SystemError(errno, what);
  if (std::rename(temp.name.c_str(), path.c_str()) != 0) throw SystemError(errno, what);
  temp.committed = true;
}

}  // namespace flexkin
