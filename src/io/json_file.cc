#include "flexkin/result_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <ostream>
#include <streambuf>
#include <string>
#include <system_error>
#include <vector>

#include "flexkin/error.h"

// JSON text in (with the location of a syntax error and the pointer of an overflowing number)
// and files written atomically: what result and scenario files share (include/flexkin/result_io.h).

namespace flexkin {
namespace {

using json = nlohmann::json;

std::system_error SystemError(int err, const std::string& what) {
  return std::system_error(err != 0 ? err : EIO, std::generic_category(), what);
}

// ---------------------------------------------------------------------------------------------
// Reading JSON.

// Builds the document from SAX events like nlohmann's own parser, but keeps the path to the
// value being read so that an overflowing number (1e999) can be reported by its JSON pointer.
class DomBuilder {
 public:
  explicit DomBuilder(json* root) : root_(root) {}

  bool null() { return Put(nullptr); }
  bool boolean(bool value) { return Put(value); }
  bool number_integer(json::number_integer_t value) { return Put(value); }
  bool number_unsigned(json::number_unsigned_t value) { return Put(value); }
  bool number_float(json::number_float_t value, const json::string_t&) { return Put(value); }
  bool string(json::string_t& value) { return Put(std::move(value)); }
  bool binary(json::binary_t& value) { return Put(json::binary(std::move(value))); }
  bool start_object(std::size_t) { return Open(json::object(), false); }
  bool key(json::string_t& key) {
    stack_.back().key = key;
    return true;
  }
  bool end_object() { return Close(); }
  bool start_array(std::size_t) { return Open(json::array(), true); }
  bool end_array() { return Close(); }
  bool parse_error(std::size_t position, const std::string& last_token,
                   const json::exception& error) {
    error_position_ = position;
    error_token_ = last_token;
    error_id_ = error.id;
    error_what_ = error.what();
    error_pointer_ = Pointer();
    return false;
  }

  // Throws the InputError that describes the parse error; `text` is the parsed text.
  [[noreturn]] void Throw(const std::string& text) const;

 private:
  struct Frame {
    json* value;  // the open object or array
    bool is_array;
    std::string key;   // objects: the last key read
    size_t count = 0;  // arrays: elements started so far
  };

  json* Add(json value) {
    if (stack_.empty()) {
      *root_ = std::move(value);
      return root_;
    }
    Frame& frame = stack_.back();
    if (frame.is_array) {
      ++frame.count;
      frame.value->push_back(std::move(value));
      return &frame.value->back();
    }
    json& slot = (*frame.value)[frame.key];
    slot = std::move(value);
    return &slot;
  }
  bool Put(json value) {
    Add(std::move(value));
    return true;
  }
  // The open container stays the last element of its parent until it is closed, so the pointer
  // to it stays valid while its parent grows no further.
  bool Open(json value, bool is_array) {
    json* container = Add(std::move(value));
    stack_.push_back({container, is_array, "", 0});
    return true;
  }
  bool Close() {
    stack_.pop_back();
    return true;
  }
  // The JSON pointer of the value being read: open containers use the element in progress
  // (count - 1); the innermost one the next element (count).
  std::string Pointer() const {
    std::string out;
    for (size_t f = 0; f < stack_.size(); ++f) {
      const Frame& frame = stack_[f];
      const bool innermost = f + 1 == stack_.size();
      if (frame.is_array) {
        out += "/" + std::to_string(innermost ? frame.count : frame.count - 1);
      } else {
        out += "/";
        for (char c : frame.key) {
          out += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
        }
      }
    }
    return out;
  }

  json* root_;
  std::vector<Frame> stack_;
  size_t error_position_ = 0;
  std::string error_token_, error_what_, error_pointer_;
  int error_id_ = 0;
};

// "line L, column C" of byte `offset` of `text`, both 1-based.
std::string LineColumn(const std::string& text, size_t offset) {
  offset = std::min(offset, text.size());
  size_t line = 1, line_start = 0;
  for (size_t i = 0; i < offset; ++i) {
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(offset - line_start + 1);
}

void DomBuilder::Throw(const std::string& text) const {
  if (error_id_ == 406) {  // a number literal too large for a double
    const size_t start =
        error_position_ >= error_token_.size() ? error_position_ - error_token_.size() : 0;
    throw InputError(error_pointer_, "number " + error_token_ + " (" + LineColumn(text, start) +
                                         ") is too large for a double; expected a finite "
                                         "number, |x| < 1.8e308");
  }
  // nlohmann's message is "[json.exception.parse_error.101] parse error at line L, column C:
  // <reason>"; keep the reason, with our own line and column of the last character read.
  std::string reason = error_what_;
  const size_t column = reason.find("column ");
  const size_t colon = reason.find(": ", column == std::string::npos ? 0 : column);
  if (colon != std::string::npos) reason = reason.substr(colon + 2);
  throw InputError("", LineColumn(text, error_position_ > 0 ? error_position_ - 1 : 0) +
                           ": invalid JSON: " + reason);
}

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

// ---------------------------------------------------------------------------------------------
// Writing files atomically.

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

json ParseJsonText(const std::string& text) {
  json root;
  DomBuilder builder(&root);
  if (!json::sax_parse(text, &builder)) builder.Throw(text);
  return root;
}

json ReadJsonFile(const std::string& path) { return ParseJsonText(ReadTextFile(path)); }

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
