// Files read whole and written atomically (src/io/atomic_file.h): what every reader and writer of
// flexkin's files shares.
#include "io/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <fstream>
#include <memory>
#include <ostream>
#include <streambuf>
#include <string>
#include <system_error>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/result_io.h"

namespace flexkin {

void ThrowNothingWritten(Problem problem) {
  problem.message += "; nothing was written";
  throw InputError(problem);
}
namespace {

std::system_error SystemError(int err, const std::string& what) {
  return std::system_error(err != 0 ? err : EIO, std::generic_category(), what);
}

// A stream buffer over a POSIX file descriptor that remembers the errno of a failed write.
class FdStreamBuf : public std::streambuf {
 public:
  explicit FdStreamBuf(int fd) : fd_(fd) { setp(buffer_, buffer_ + sizeof buffer_); }
  int error() const { return error_; }
  // Bytes handed to the buffer so far, written or not.
  uint64_t position() const { return drained_ + static_cast<uint64_t>(pptr() - pbase()); }

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
      drained_ += static_cast<uint64_t>(n);
    }
    setp(buffer_, buffer_ + sizeof buffer_);
    return 0;
  }

  int fd_;
  int error_ = 0;
  uint64_t drained_ = 0;
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

struct AtomicFile::State {
  std::string path, dir, what;
  mode_t mode = 0;
  TempFile temp;
  std::unique_ptr<FdStreamBuf> buffer;
  std::unique_ptr<std::ostream> out;
};

AtomicFile::AtomicFile(const std::string& path) : state_(std::make_unique<State>()) {
  if (path.empty()) throw InputError("path", "is empty; expected a file name");
  State& s = *state_;
  const size_t slash = path.rfind('/');
  s.path = path;
  s.dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
  s.what = "cannot write '" + path + "'";
  struct stat existing;
  s.mode = 0666 & ~CurrentUmask();
  if (base.empty() || (::stat(path.c_str(), &existing) == 0 && S_ISDIR(existing.st_mode))) {
    throw SystemError(EISDIR, s.what);
  }
  if (::stat(path.c_str(), &existing) == 0) s.mode = existing.st_mode & 07777;
  s.temp.name = s.dir + "." + base + ".tmp-XXXXXX";
  s.temp.fd = ::mkstemp(s.temp.name.data());
  if (s.temp.fd < 0) {
    s.temp.committed = true;  // nothing to remove
    throw SystemError(errno, s.what + " (creating a temporary file in its directory failed)");
  }
  s.buffer = std::make_unique<FdStreamBuf>(s.temp.fd);
  s.out = std::make_unique<std::ostream>(s.buffer.get());
}

AtomicFile::~AtomicFile() = default;

const std::string& AtomicFile::path() const { return state_->path; }
const std::string& AtomicFile::directory() const { return state_->dir; }
std::ostream& AtomicFile::stream() { return *state_->out; }
uint64_t AtomicFile::position() const { return state_->buffer->position(); }

std::system_error AtomicFile::Error(int fallback) const {
  const int err = state_->buffer->error();
  return SystemError(err != 0 ? err : fallback, state_->what);
}

void AtomicFile::Check() const {
  if (!*state_->out || state_->buffer->error() != 0) throw Error();
}

void AtomicFile::WriteAt(uint64_t offset, const void* data, size_t size) {
  State& s = *state_;
  s.out->flush();
  Check();
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::pwrite(s.temp.fd, p, size, static_cast<off_t>(offset));
    if (n < 0) {
      if (errno == EINTR) continue;
      throw SystemError(errno, s.what);
    }
    p += n;
    offset += static_cast<uint64_t>(n);
    size -= static_cast<size_t>(n);
  }
}

namespace {
std::atomic<void (*)()> g_before_commit{nullptr};
}  // namespace

void SetBeforeOutputCommit(void (*check)()) { g_before_commit.store(check); }

void AtomicFile::Commit() {
  State& s = *state_;
  s.out->flush();
  Check();
  if (::fchmod(s.temp.fd, s.mode) != 0) throw SystemError(errno, s.what);
  // Data on disk before the rename, so a crash leaves the old file or the whole new one.
  if (::fsync(s.temp.fd) != 0 && errno != EINVAL && errno != EROFS) {
    throw SystemError(errno, s.what);
  }
  if (void (*check)() = g_before_commit.load()) check();
  const int fd = s.temp.fd;
  s.temp.fd = -1;
  if (::close(fd) != 0) throw SystemError(errno, s.what);
  if (std::rename(s.temp.name.c_str(), s.path.c_str()) != 0) throw SystemError(errno, s.what);
  s.temp.committed = true;
}

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  AtomicFile file(path);
  try {
    write(file.stream());
    file.stream().flush();
  } catch (...) {
    // A failed write(2) is the cause, whatever the writer made of it: report its errno.
    file.Check();
    throw;
  }
  file.Commit();
}

ScratchFile::ScratchFile(const std::string& directory, const std::string& what) : what_(what) {
  std::string name = directory + ".flexkin-scratch-XXXXXX";
  fd_ = ::mkstemp(name.data());
  if (fd_ < 0)
    throw SystemError(errno, what_ + " (creating a scratch file in its directory failed)");
  ::unlink(name.c_str());
  buffer_.reserve(1 << 16);
}

ScratchFile::~ScratchFile() {
  if (fd_ >= 0) ::close(fd_);
}

void ScratchFile::Drain() {
  const char* p = buffer_.data();
  size_t left = buffer_.size();
  while (left > 0) {
    const ssize_t n = ::write(fd_, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw SystemError(errno, what_);
    }
    p += n;
    left -= static_cast<size_t>(n);
  }
  buffer_.clear();
}

void ScratchFile::Write(const void* data, size_t size) {
  if (buffer_.size() + size > (1u << 16)) Drain();
  if (size >= (1u << 16)) {
    buffer_.assign(static_cast<const char*>(data), size);
    Drain();
  } else {
    buffer_.append(static_cast<const char*>(data), size);
  }
  size_ += size;
}

void ScratchFile::CopyTo(const std::function<void(const char* data, size_t size)>& write) {
  Drain();
  std::vector<char> chunk(1 << 20);
  uint64_t offset = 0;
  while (offset < size_) {
    const ssize_t n = ::pread(fd_, chunk.data(), chunk.size(), static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw SystemError(n < 0 ? errno : EIO, what_ + " (reading the scratch file back)");
    write(chunk.data(), static_cast<size_t>(n));
    offset += static_cast<uint64_t>(n);
  }
}

}  // namespace flexkin
