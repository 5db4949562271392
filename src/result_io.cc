#include "flexkin/result_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <ostream>
#include <streambuf>
#include <string>
#include <system_error>
#include <vector>

#include "flexkin/error.h"

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

// ---------------------------------------------------------------------------------------------
// Writing results.

// %.17g reads back to the same double. Negative zero is written "-0.0": some parsers (nlohmann
// among them) read "-0" as the integer 0 and would lose the sign.
void AppendDouble(double x, std::string* out) {
  if (x == 0.0 && std::signbit(x)) {
    out->append("-0.0");
    return;
  }
  char buffer[32];
  const int n = std::snprintf(buffer, sizeof buffer, "%.17g", x);
  out->append(buffer, static_cast<size_t>(n));
}

void AppendVector(const Eigen::VectorXd& v, std::string* out) {
  out->push_back('[');
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (i > 0) out->push_back(',');
    AppendDouble(v[i], out);
  }
  out->push_back(']');
}

void CheckFinite(const Eigen::Ref<const Eigen::VectorXd>& v, const std::string& field) {
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) {
      char value[32];
      std::snprintf(value, sizeof value, "%g", v[i]);
      throw InputError(field + "[" + std::to_string(i) + "]",
                       std::string("value ") + value +
                           " is not finite; a result file holds finite numbers only, so nothing "
                           "was written");
    }
  }
}

// Checks what the writers rely on: consistent shapes and finite numbers everywhere.
int CheckResult(const RunResult& r) {
  if (r.frames.empty()) throw InputError("frames", "is empty; expected at least the initial frame");
  const int dim = static_cast<int>(r.frames[0].points.cols());
  const Eigen::Index n = r.lengths.size();
  CheckFinite(r.lengths, "lengths");
  for (size_t f = 0; f < r.frames.size(); ++f) {
    const Frame& frame = r.frames[f];
    const std::string field = "frames[" + std::to_string(f) + "]";
    if (frame.points.rows() != n + 1 || frame.points.cols() != dim || (dim != 2 && dim != 3)) {
      throw InputError(field + ".points", "is " + std::to_string(frame.points.rows()) + " by " +
                                              std::to_string(frame.points.cols()) +
                                              "; expected (links + 1) by dim = " +
                                              std::to_string(n + 1) + " by 2 or 3, as frame 0");
    }
    for (Eigen::Index i = 0; i <= n; ++i) {
      CheckFinite(frame.points.row(i).transpose(), field + ".points[" + std::to_string(i) + "]");
    }
    CheckFinite(frame.link_angles, field + ".link_angles");
  }
  const Metrics& m = r.metrics;
  CheckFinite(m.l2_per_step, "metrics.l2_per_step");
  CheckFinite(m.l2_weighted_per_step, "metrics.l2_weighted_per_step");
  CheckFinite(m.path_length, "metrics.path_length");
  Eigen::Vector4d scalars(m.l2_total, m.l2_weighted_total, m.max_relative_length_error,
                          r.accuracy.estimated_error);
  CheckFinite(scalars,
              "metrics (l2_total, l2_weighted_total, max_relative_length_error, "
              "estimated_error)");
  return dim;
}

// Appends to `text` and hands it to `out` in pieces, so that a result of any size is written
// with a bounded buffer.
class ChunkWriter {
 public:
  explicit ChunkWriter(std::ostream& out) : out_(out) {}
  std::string& text() { return text_; }
  void MaybeFlush() {
    if (text_.size() >= (1u << 16)) Flush();
  }
  // Throws as soon as the stream fails, rather than formatting the rest for nothing.
  void Flush() {
    out_.write(text_.data(), static_cast<std::streamsize>(text_.size()));
    text_.clear();
    if (!out_) throw SystemError(EIO, "cannot write to the output stream");
  }

 private:
  std::ostream& out_;
  std::string text_;
};

// ---------------------------------------------------------------------------------------------
// Reading results: the first problem is thrown, naming its JSON pointer.

std::string Show(const json& v) {
  std::string text = v.dump(-1, ' ', false, json::error_handler_t::replace);
  return text.size() > 60 ? text.substr(0, 56) + " ..." : text;
}

const json& Member(const json& object, const std::string& ptr, const char* key) {
  if (!object.is_object()) throw InputError(ptr, "value " + Show(object) + " is not an object");
  const auto it = object.find(key);
  if (it == object.end()) throw InputError(ptr + "/" + key, "is missing");
  return *it;
}

double ReadNumber(const json& v, const std::string& ptr) {
  if (!v.is_number() || !std::isfinite(v.get<double>())) {
    throw InputError(ptr, "value " + Show(v) + " is not valid; expected a finite number");
  }
  return v.get<double>();
}

int64_t ReadInteger(const json& v, const std::string& ptr, int64_t min) {
  if (!v.is_number_integer() || v.get<int64_t>() < min) {
    throw InputError(
        ptr, "value " + Show(v) + " is not valid; expected an integer >= " + std::to_string(min));
  }
  return v.get<int64_t>();
}

bool ReadBool(const json& v, const std::string& ptr) {
  if (!v.is_boolean()) throw InputError(ptr, "value " + Show(v) + " is not true or false");
  return v.get<bool>();
}

// An array of numbers; `size` < 0 accepts any length.
Eigen::VectorXd ReadVector(const json& v, const std::string& ptr, Eigen::Index size) {
  if (!v.is_array() || (size >= 0 && v.size() != static_cast<size_t>(size))) {
    throw InputError(ptr, "value " + Show(v) + " is not valid; expected an array of " +
                              (size >= 0 ? std::to_string(size) + " " : std::string()) + "numbers");
  }
  Eigen::VectorXd out(v.size());
  for (size_t i = 0; i < v.size(); ++i) out[i] = ReadNumber(v[i], ptr + "/" + std::to_string(i));
  return out;
}

Points ReadPoints(const json& v, const std::string& ptr, Eigen::Index rows, int dim) {
  if (!v.is_array() || v.size() != static_cast<size_t>(rows)) {
    throw InputError(ptr, "is not valid; expected an array of " + std::to_string(rows) +
                              " points (one per link end)");
  }
  Points points(rows, dim);
  for (Eigen::Index i = 0; i < rows; ++i) {
    points.row(i) = ReadVector(v[i], ptr + "/" + std::to_string(i), dim).transpose();
  }
  return points;
}

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

void WriteResultJson(const RunResult& result, std::ostream& out, const std::string& scenario_name) {
  const int dim = CheckResult(result);
  const Metrics& m = result.metrics;
  const AccuracyReport& a = result.accuracy;
  ChunkWriter writer(out);
  std::string& t = writer.text();
  t += "{\n\"format\": \"" + std::string(kResultFormat) + "\",\n";
  t += "\"version\": " + std::to_string(kResultVersion) + ",\n";
  if (!scenario_name.empty()) {
    t += "\"scenario\": " +
         json(scenario_name).dump(-1, ' ', false, json::error_handler_t::replace) + ",\n";
  }
  t += "\"method\": \"" + std::string(MethodName(result.method)) + "\",\n";
  t += "\"dim\": " + std::to_string(dim) + ",\n";
  t += "\"num_links\": " + std::to_string(result.lengths.size()) + ",\n";
  t += "\"link_lengths\": ";
  AppendVector(result.lengths, &t);
  t += ",\n\"num_steps\": " + std::to_string(result.num_steps) + ",\n";
  t += "\"substeps\": " + std::to_string(a.substeps) + ",\n";
  t += "\"seconds\": ";
  AppendDouble(std::isfinite(result.seconds) ? result.seconds : 0.0, &t);
  t += ",\n\"accuracy\": {\"enabled\": " + std::string(a.enabled ? "true" : "false") +
       ", \"tolerance\": ";
  AppendDouble(a.tolerance, &t);
  t += ", \"max_substeps\": " + std::to_string(a.max_substeps) +
       ", \"substeps\": " + std::to_string(a.substeps) + ", \"order\": " + std::to_string(a.order) +
       ", \"estimated_error\": ";
  AppendDouble(a.estimated_error, &t);
  t += ", \"met\": " + std::string(a.met ? "true" : "false") + "},\n";
  if (result.method == Method::kOverall) {
    const OverallSummary& o = result.overall;
    const ObjectiveWeights& w = result.weights;
    t += "\"overall\": {\"objective\": {\"l2\": ";
    AppendDouble(w.l2, &t);
    t += ", \"l2_weighted\": ";
    AppendDouble(w.l2_weighted, &t);
    t += ", \"squared\": ";
    AppendDouble(w.squared, &t);
    t += ", \"squared_weighted\": ";
    AppendDouble(w.squared_weighted, &t);
    t += ", \"rotation\": ";
    AppendDouble(w.rotation, &t);
    t += ", \"joint_angle\": ";
    AppendDouble(w.joint_angle, &t);
    t += "}, \"solves\": " + std::to_string(o.solves) +
         ", \"failures\": " + std::to_string(o.failures) +
         ", \"iterations\": " + std::to_string(o.iterations) +
         ", \"max_iterations\": " + std::to_string(o.max_iterations) +
         ", \"constraint_violation\": ";
    AppendDouble(o.constraint_violation, &t);
    t += ", \"optimality\": ";
    AppendDouble(o.optimality, &t);
    t += ", \"first_failure\": " +
         json(o.first_failure).dump(-1, ' ', false, json::error_handler_t::replace) + "},\n";
  }
  t += "\"metrics\": {\n\"l2_total\": ";
  AppendDouble(m.l2_total, &t);
  t += ",\n\"l2_weighted_total\": ";
  AppendDouble(m.l2_weighted_total, &t);
  t += ",\n\"max_relative_length_error\": ";
  AppendDouble(m.max_relative_length_error, &t);
  t += ",\n\"path_length\": ";
  AppendVector(m.path_length, &t);
  t += ",\n\"l2_per_step\": ";
  AppendVector(m.l2_per_step, &t);
  t += ",\n\"l2_weighted_per_step\": ";
  AppendVector(m.l2_weighted_per_step, &t);
  t += "\n},\n\"frames\": [\n";
  for (size_t f = 0; f < result.frames.size(); ++f) {
    const Frame& frame = result.frames[f];
    t += "{\"step\": " + std::to_string(frame.step) + ", \"points\": [";
    for (Eigen::Index i = 0; i < frame.points.rows(); ++i) {
      if (i > 0) t += ',';
      AppendVector(frame.points.row(i).transpose(), &t);
      writer.MaybeFlush();
    }
    t += "], \"link_angles\": ";
    AppendVector(frame.link_angles, &t);
    t += f + 1 < result.frames.size() ? "},\n" : "}\n";
    writer.MaybeFlush();
  }
  t += "]\n}\n";
  writer.Flush();
}

void WriteResultJson(const RunResult& result, const std::string& path,
                     const std::string& scenario_name) {
  CheckResult(result);  // before the destination is touched at all
  WriteFileAtomically(path,
                      [&](std::ostream& out) { WriteResultJson(result, out, scenario_name); });
}

void WriteFramesCsv(const RunResult& result, std::ostream& out) {
  const int dim = CheckResult(result);
  ChunkWriter writer(out);
  std::string& t = writer.text();
  t += dim == 3 ? "step,point,x,y,z\n" : "step,point,x,y\n";
  for (const Frame& frame : result.frames) {
    const std::string step = std::to_string(frame.step) + ",";
    for (Eigen::Index i = 0; i < frame.points.rows(); ++i) {
      t += step + std::to_string(i);
      for (int k = 0; k < dim; ++k) {
        t += ',';
        AppendDouble(frame.points(i, k), &t);
      }
      t += '\n';
      writer.MaybeFlush();
    }
  }
  writer.Flush();
}

void WriteFramesCsv(const RunResult& result, const std::string& path) {
  CheckResult(result);
  WriteFileAtomically(path, [&](std::ostream& out) { WriteFramesCsv(result, out); });
}

ResultFile ResultFromJson(const json& j) {
  ResultFile file;
  RunResult& r = file.result;
  const json& format = Member(j, "", "format");
  if (format != kResultFormat) {
    throw InputError("/format",
                     "value " + Show(format) + " is not valid; expected \"" + kResultFormat + "\"");
  }
  const json& version = Member(j, "", "version");
  if (version != kResultVersion) {
    throw InputError("/version", "value " + Show(version) + " is not supported; expected " +
                                     std::to_string(kResultVersion));
  }
  const json& method = Member(j, "", "method");
  if (!method.is_string())
    throw InputError("/method", "value " + Show(method) + " is not a string");
  r.method = ParseMethod(method.get<std::string>(), "/method");
  if (const auto it = j.find("scenario"); it != j.end()) {
    if (!it->is_string()) throw InputError("/scenario", "value " + Show(*it) + " is not a string");
    file.scenario_name = it->get<std::string>();
  }
  file.dim = static_cast<int>(ReadInteger(Member(j, "", "dim"), "/dim", 2));
  if (file.dim > 3)
    throw InputError("/dim", "value " + std::to_string(file.dim) + " is not 2 or 3");
  r.lengths = ReadVector(Member(j, "", "link_lengths"), "/link_lengths", -1);
  const Eigen::Index n = r.lengths.size();
  if (n < 1 || !(r.lengths.minCoeff() > 0.0)) {
    throw InputError("/link_lengths", "is not valid; expected at least one positive length");
  }
  r.num_steps = ReadInteger(Member(j, "", "num_steps"), "/num_steps", 0);

  const json& accuracy = Member(j, "", "accuracy");
  r.accuracy.enabled = ReadBool(Member(accuracy, "/accuracy", "enabled"), "/accuracy/enabled");
  r.accuracy.tolerance =
      ReadNumber(Member(accuracy, "/accuracy", "tolerance"), "/accuracy/tolerance");
  r.accuracy.max_substeps = static_cast<int>(
      ReadInteger(Member(accuracy, "/accuracy", "max_substeps"), "/accuracy/max_substeps", 0));
  r.accuracy.substeps = static_cast<int>(
      ReadInteger(Member(accuracy, "/accuracy", "substeps"), "/accuracy/substeps", 1));
  r.accuracy.order =
      static_cast<int>(ReadInteger(Member(accuracy, "/accuracy", "order"), "/accuracy/order", 0));
  r.accuracy.estimated_error =
      ReadNumber(Member(accuracy, "/accuracy", "estimated_error"), "/accuracy/estimated_error");
  r.accuracy.met = ReadBool(Member(accuracy, "/accuracy", "met"), "/accuracy/met");
  if (const auto it = j.find("overall"); it != j.end()) {
    const json& o = *it;
    const json& w = Member(o, "/overall", "objective");
    // (The L2 terms are optional: files written before they existed lack them.)
    for (const auto& [name, weight] : {std::pair<const char*, double*>{"l2", &r.weights.l2},
                                       {"l2_weighted", &r.weights.l2_weighted}}) {
      if (const auto term = w.find(name); term != w.end()) {
        *weight = ReadNumber(*term, std::string("/overall/objective/") + name);
      }
    }
    r.weights.squared =
        ReadNumber(Member(w, "/overall/objective", "squared"), "/overall/objective/squared");
    r.weights.squared_weighted = ReadNumber(Member(w, "/overall/objective", "squared_weighted"),
                                            "/overall/objective/squared_weighted");
    r.weights.rotation =
        ReadNumber(Member(w, "/overall/objective", "rotation"), "/overall/objective/rotation");
    r.weights.joint_angle = ReadNumber(Member(w, "/overall/objective", "joint_angle"),
                                       "/overall/objective/joint_angle");
    r.overall.solves = ReadInteger(Member(o, "/overall", "solves"), "/overall/solves", 0);
    r.overall.failures = ReadInteger(Member(o, "/overall", "failures"), "/overall/failures", 0);
    r.overall.iterations =
        ReadInteger(Member(o, "/overall", "iterations"), "/overall/iterations", 0);
    r.overall.max_iterations = static_cast<int>(
        ReadInteger(Member(o, "/overall", "max_iterations"), "/overall/max_iterations", 0));
    r.overall.constraint_violation =
        ReadNumber(Member(o, "/overall", "constraint_violation"), "/overall/constraint_violation");
    r.overall.optimality = ReadNumber(Member(o, "/overall", "optimality"), "/overall/optimality");
  }

  const json& metrics = Member(j, "", "metrics");
  Metrics& m = r.metrics;
  m.l2_total = ReadNumber(Member(metrics, "/metrics", "l2_total"), "/metrics/l2_total");
  m.l2_weighted_total =
      ReadNumber(Member(metrics, "/metrics", "l2_weighted_total"), "/metrics/l2_weighted_total");
  m.max_relative_length_error = ReadNumber(Member(metrics, "/metrics", "max_relative_length_error"),
                                           "/metrics/max_relative_length_error");
  m.path_length =
      ReadVector(Member(metrics, "/metrics", "path_length"), "/metrics/path_length", n + 1);
  m.l2_per_step =
      ReadVector(Member(metrics, "/metrics", "l2_per_step"), "/metrics/l2_per_step", r.num_steps);
  m.l2_weighted_per_step = ReadVector(Member(metrics, "/metrics", "l2_weighted_per_step"),
                                      "/metrics/l2_weighted_per_step", r.num_steps);
  if (const auto it = j.find("seconds"); it != j.end()) r.seconds = ReadNumber(*it, "/seconds");

  const json& frames = Member(j, "", "frames");
  if (!frames.is_array() || frames.empty()) {
    throw InputError("/frames", "is not valid; expected an array of at least one frame");
  }
  r.frames.reserve(frames.size());
  for (size_t f = 0; f < frames.size(); ++f) {
    const std::string ptr = "/frames/" + std::to_string(f);
    Frame frame;
    frame.step = ReadInteger(Member(frames[f], ptr, "step"), ptr + "/step", 0);
    frame.points = ReadPoints(Member(frames[f], ptr, "points"), ptr + "/points", n + 1, file.dim);
    const json& angles = Member(frames[f], ptr, "link_angles");
    frame.link_angles = ReadVector(angles, ptr + "/link_angles", angles.empty() ? 0 : n);
    r.frames.push_back(std::move(frame));
  }
  return file;
}

ResultFile ReadResultJson(const std::string& path) { return ResultFromJson(ReadJsonFile(path)); }

}  // namespace flexkin
