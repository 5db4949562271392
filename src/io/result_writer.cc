#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <system_error>
#include <utility>

#include "flexkin/error.h"
#include "flexkin/result_io.h"
#include "io/atomic_file.h"
#include "io/colliders_json.h"
#include "io/result_check.h"
#include "io/result_writers.h"

// Result files and frame CSV files out (docs/result-format.md): the streaming writers
// (ResultFileWriter, FramesCsvWriter) and the whole-result writers built on the same streams.

namespace flexkin {
namespace {

using json = nlohmann::json;

void AppendVector(const Eigen::Ref<const Eigen::VectorXd>& v, std::string* out) {
  out->push_back('[');
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (i > 0) out->push_back(',');
    AppendJsonDouble(v[i], out);
  }
  out->push_back(']');
}

std::string JsonString(const std::string& s) {
  return json(s).dump(-1, ' ', false, json::error_handler_t::replace);
}

// The result's dimension, after the one check of results (ValidateResult): consistent shapes and
// finite numbers everywhere, which JSON needs.
int CheckResult(const RunResult& r) {
  const int dim = r.frames.empty() ? 0 : static_cast<int>(r.frames[0].points.cols());
  if (Problems problems = ValidateResult(r, dim); !problems.empty()) {
    ThrowNothingWritten(problems.front());
  }
  return dim;
}

ResultHeader HeaderOfResult(const RunResult& r, int dim, const std::string& scenario_name,
                            const std::vector<Collider>& colliders = {},
                            const Eigen::VectorXd& link_radii = Eigen::VectorXd()) {
  ResultHeader h;
  h.method = r.method;
  h.dim = dim;
  h.lengths = r.lengths;
  h.scenario_name = scenario_name;
  h.colliders = colliders;
  h.link_radii = link_radii;
  return h;
}

// ValidateResult of a ResultFile, before the destination is touched; its dimension.
int CheckResultFile(const ResultFile& file) {
  if (Problems problems = ValidateResult(file); !problems.empty()) {
    ThrowNothingWritten(problems.front());
  }
  return file.dim;
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
    if (!out_)
      throw std::system_error(EIO, std::generic_category(), "cannot write to the output stream");
  }

 private:
  std::ostream& out_;
  std::string text_;
};

// A result document written as its frames come: the header, the frames one per line, the summary.
class JsonResultStream {
 public:
  JsonResultStream(std::ostream& out, const ResultHeader& header) : writer_(out) {
    std::string& t = writer_.text();
    t += "{\n";
    AppendResultHeaderJson(header, true, &t);
    t += "\"frames\": [\n";
  }
  void Add(int64_t step, const PointsRef& points, const VectorRef& link_angles) {
    std::string& t = writer_.text();
    t += first_ ? "{\"step\": " : ",\n{\"step\": ";
    first_ = false;
    t += std::to_string(step) + ", \"points\": [";
    for (Eigen::Index i = 0; i < points.rows(); ++i) {
      if (i > 0) t += ',';
      AppendVector(points.row(i).transpose(), &t);
      writer_.MaybeFlush();
    }
    t += "], \"link_angles\": ";
    AppendVector(link_angles, &t);
    t += "}";
    writer_.MaybeFlush();
  }
  void End(const RunResult& result) {
    std::string& t = writer_.text();
    t += "\n],\n";
    AppendResultSummaryJson(result, true, &t);
    t += "\n}\n";
    writer_.Flush();
  }

 private:
  ChunkWriter writer_;
  bool first_ = true;
};

// Frames as CSV rows, as they come.
class CsvFramesStream {
 public:
  CsvFramesStream(std::ostream& out, int dim) : writer_(out), dim_(dim) {
    writer_.text() += dim == 3 ? "step,point,x,y,z\n" : "step,point,x,y\n";
  }
  void Add(int64_t step_number, const Points& points) {
    std::string& t = writer_.text();
    const std::string step = std::to_string(step_number) + ",";
    for (Eigen::Index i = 0; i < points.rows(); ++i) {
      t += step + std::to_string(i);
      for (int k = 0; k < dim_; ++k) {
        t += ',';
        AppendJsonDouble(points(i, k), &t);
      }
      t += '\n';
      writer_.MaybeFlush();
    }
  }
  void End() { writer_.Flush(); }

 private:
  ChunkWriter writer_;
  int dim_;
};

class JsonResultWriter : public ResultFileWriter::Impl {
 public:
  JsonResultWriter(const std::string& path, const ResultHeader& header)
      : file_(path), stream_(file_.stream(), header) {}
  void Add(int64_t step, const PointsRef& points, const VectorRef& link_angles) override {
    try {
      stream_.Add(step, points, link_angles);
    } catch (const std::system_error&) {
      throw file_.Error(EIO);  // the failed write's errno, with the path
    }
  }
  void Commit(const RunResult& result) override {
    try {
      stream_.End(result);
    } catch (const std::system_error&) {
      throw file_.Error(EIO);
    }
    file_.Commit();
  }

 private:
  AtomicFile file_;
  JsonResultStream stream_;
};

}  // namespace

void AppendJsonDouble(double x, std::string* out) {
  // %.17g reads back to the same double. Negative zero is written "-0.0": some parsers (nlohmann
  // among them) read "-0" as the integer 0 and would lose the sign.
  if (x == 0.0 && std::signbit(x)) {
    out->append("-0.0");
    return;
  }
  char buffer[32];
  const int n = std::snprintf(buffer, sizeof buffer, "%.17g", x);
  out->append(buffer, static_cast<size_t>(n));
}

void AppendResultHeaderJson(const ResultHeader& h, bool with_lengths, std::string* out) {
  std::string& t = *out;
  t += "\"format\": \"" + std::string(kResultFormat) + "\",\n";
  t += "\"version\": " + std::to_string(kResultVersion) + ",\n";
  if (!h.scenario_name.empty()) t += "\"scenario\": " + JsonString(h.scenario_name) + ",\n";
  t += "\"method\": \"" + std::string(MethodName(h.method)) + "\",\n";
  t += "\"dim\": " + std::to_string(h.dim) + ",\n";
  t += "\"num_links\": " + std::to_string(h.lengths.size()) + ",\n";
  if (with_lengths) {
    t += "\"link_lengths\": ";
    AppendVector(h.lengths, &t);
    t += ",\n";
  }
  // Only with colliders: a result without them is the file it was before they existed.
  if (!h.colliders.empty()) {
    t += "\"colliders\": [\n";
    for (size_t k = 0; k < h.colliders.size(); ++k) {
      if (k > 0) t += ",\n";
      AppendColliderJson(h.colliders[k], h.dim, &t);
    }
    t += "\n],\n";
  }
  if (h.link_radii.size() > 0) {
    t += "\"link_radii\": ";
    AppendVector(h.link_radii, &t);
    t += ",\n";
  }
}

void AppendResultSummaryJson(const RunResult& result, bool with_arrays, std::string* out) {
  std::string& t = *out;
  const Metrics& m = result.metrics;
  const AccuracyReport& a = result.accuracy;
  t += "\"num_steps\": " + std::to_string(result.num_steps) + ",\n";
  t += "\"substeps\": " + std::to_string(a.substeps) + ",\n";
  t += "\"seconds\": ";
  AppendJsonDouble(std::isfinite(result.seconds) ? result.seconds : 0.0, &t);
  t += ",\n\"accuracy\": {\"enabled\": " + std::string(a.enabled ? "true" : "false") +
       ", \"tolerance\": ";
  AppendJsonDouble(a.tolerance, &t);
  t += ", \"max_substeps\": " + std::to_string(a.max_substeps) +
       ", \"substeps\": " + std::to_string(a.substeps) + ", \"order\": " + std::to_string(a.order) +
       ", \"estimated_error\": ";
  AppendJsonDouble(a.estimated_error, &t);
  t += ", \"met\": " + std::string(a.met ? "true" : "false") + "},\n";
  if (result.method == Method::kOverall) {
    const OverallRunReport& o = result.overall;
    const ObjectiveWeights& w = result.weights;
    t += "\"overall\": {\"objective\": {";
    for (const auto& [term, name, summary] : Vocabulary<ObjectiveTerm>::kEntries) {
      t += std::string(term == ObjectiveTerm::kL2 ? "" : ", ") + "\"" + name + "\": ";
      AppendJsonDouble(w[term], &t);
    }
    t += "}, \"solves\": " + std::to_string(o.solves) +
         ", \"failures\": " + std::to_string(o.failures) +
         ", \"iterations\": " + std::to_string(o.iterations) +
         ", \"max_iterations\": " + std::to_string(o.max_iterations) +
         ", \"constraint_violation\": ";
    AppendJsonDouble(o.constraint_violation, &t);
    t += ", \"optimality\": ";
    AppendJsonDouble(o.optimality, &t);
    t += ", \"first_failure\": " + JsonString(o.first_failure) + "},\n";
  }
  // A dynamic chain's (docs/dynamics.md): its energy, one number a frame, also in an npz's
  // result.json (small beside the frames).
  if (result.dynamics.enabled) {
    const DynamicRunReport& d = result.dynamics;
    t += "\"dynamics\": {\"projection\": " + JsonString(d.projection) + ", \"frame_rate\": ";
    AppendJsonDouble(d.frame_rate, &t);
    t += ", \"substeps\": " + std::to_string(d.substeps) +
         ", \"failures\": " + std::to_string(d.failures) +
         ", \"contact_substeps\": " + std::to_string(d.contact_substeps) +
         ", \"contact_solves\": " + std::to_string(d.contact_solves) +
         ", \"contact_solve_failures\": " + std::to_string(d.contact_solve_failures) +
         ",\n\"energy\": ";
    AppendVector(d.energy, &t);
    t += "},\n";
  }
  t += "\"metrics\": {";
  const std::pair<const char*, double> totals[] = {
      {"l2_total", m.l2_total},
      {"l2_weighted_total", m.l2_weighted_total},
      {"max_relative_length_error", m.max_relative_length_error}};
  const std::pair<const char*, const Eigen::VectorXd*> arrays[] = {
      {"path_length", &m.path_length},
      {"l2_per_step", &m.l2_per_step},
      {"l2_weighted_per_step", &m.l2_weighted_per_step}};
  for (const auto& [key, value] : totals) {
    t += std::string(key == totals[0].first ? "\n\"" : ",\n\"") + key + "\": ";
    AppendJsonDouble(value, &t);
  }
  for (const auto& [key, values] : arrays) {
    if (!with_arrays) break;
    t += std::string(",\n\"") + key + "\": ";
    AppendVector(*values, &t);
  }
  t += "\n}";
}

const char* ResultFileFormatName(ResultFileFormat format) {
  return format == ResultFileFormat::kNpz ? "npz" : "json";
}

ResultFileFormat ResultFileFormatOfPath(const std::string& path, const std::string& field) {
  const size_t dot = path.rfind('.');
  const size_t slash = path.rfind('/');
  std::string extension;
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) {
    extension = path.substr(dot);
    for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  if (extension == ".json") return ResultFileFormat::kJson;
  if (extension == ".npz") return ResultFileFormat::kNpz;
  throw InputError(Problem(field,
                           "'" + path + "' has " +
                               (extension.empty() ? std::string("no extension")
                                                  : "the extension \"" + extension + "\"") +
                               "; expected a result file name ending in .json (JSON) or .npz "
                               "(NumPy archive)",
                           path, ".json or .npz"));
}

ResultHeader MakeResultHeader(const Chain& chain, const RunOptions& options,
                              const std::string& scenario_name) {
  ResultHeader h;
  h.method = options.method;
  h.dim = chain.dim();
  h.lengths = chain.lengths;
  h.scenario_name = scenario_name;
  h.colliders = options.colliders;
  if (options.link_radius > 0.0) {
    h.link_radii = Eigen::VectorXd::Constant(chain.num_links(), options.link_radius);
  }
  return h;
}

ResultFileWriter::ResultFileWriter(const std::string& path, ResultFileFormat format,
                                   const ResultHeader& header)
    : header_(header) {
  if (auto problem = ResultHeaderProblem(header.lengths, header.dim)) {
    ThrowNothingWritten(*problem);
  }
  if (Problems problems = CollidersProblems(header.colliders, header.dim); !problems.empty()) {
    ThrowNothingWritten(problems.front());
  }
  if (auto problem = LinkRadiiProblem(header.link_radii, header.lengths.size())) {
    ThrowNothingWritten(*problem);
  }
  if (format == ResultFileFormat::kNpz) {
    impl_ = MakeNpzResultWriter(path, header);
  } else {
    impl_ = std::make_unique<JsonResultWriter>(path, header);
  }
}

ResultFileWriter::~ResultFileWriter() = default;

int64_t ResultFileWriter::frames() const { return frames_; }

void ResultFileWriter::Add(int64_t step, const PointsRef& points, const VectorRef& link_angles) {
  if (impl_ == nullptr) {
    throw std::logic_error("ResultFileWriter::Add after Commit or after a failure");
  }
  if (auto problem = ResultFrameProblem(static_cast<size_t>(frames_), step, points, link_angles,
                                        last_step_, header_.lengths.size(), header_.dim)) {
    impl_.reset();  // removes the temporary file
    ThrowNothingWritten(*problem);
  }
  try {
    impl_->Add(step, points, link_angles);
  } catch (...) {
    impl_.reset();
    throw;
  }
  ++frames_;
  last_step_ = step;
}

void ResultFileWriter::Commit(const RunResult& result) {
  if (impl_ == nullptr) {
    throw std::logic_error("ResultFileWriter::Commit after Commit or after a failure");
  }
  std::optional<Problem> problem;
  if (frames_ == 0) {
    problem = Problem("frames", "the result has no frames; expected at least the initial frame");
  } else if (result.method != header_.method) {
    problem = Problem("method", std::string("is \"") + MethodName(result.method) +
                                    "\", but the file was started for \"" +
                                    MethodName(header_.method) + "\"");
  } else if (result.lengths.size() != header_.lengths.size() ||
             std::memcmp(result.lengths.data(), header_.lengths.data(),
                         sizeof(double) * static_cast<size_t>(header_.lengths.size())) != 0) {
    problem = Problem("link_lengths", "differ from the link lengths the file was started with");
  } else {
    problem = ResultSummaryProblem(result);
  }
  std::unique_ptr<Impl> impl = std::move(impl_);  // whatever happens, once only
  if (problem) ThrowNothingWritten(*problem);
  impl->Commit(result);
}

void WriteResultJson(const RunResult& result, std::ostream& out, const std::string& scenario_name) {
  const int dim = CheckResult(result);
  JsonResultStream stream(out, HeaderOfResult(result, dim, scenario_name));
  for (const Frame& frame : result.frames) stream.Add(frame.step, frame.points, frame.link_angles);
  stream.End(result);
}

void WriteResultFile(const RunResult& result, const std::string& path, ResultFileFormat format,
                     const std::string& scenario_name) {
  const int dim = CheckResult(result);  // before the destination is touched at all
  ResultFileWriter writer(path, format, HeaderOfResult(result, dim, scenario_name));
  for (const Frame& frame : result.frames) writer.Add(frame.step, frame.points, frame.link_angles);
  writer.Commit(result);
}

void WriteResultJson(const RunResult& result, const std::string& path,
                     const std::string& scenario_name) {
  WriteResultFile(result, path, ResultFileFormat::kJson, scenario_name);
}

void WriteResultJson(const ResultFile& file, std::ostream& out) {
  const int dim = CheckResultFile(file);
  JsonResultStream stream(
      out, HeaderOfResult(file.result, dim, file.scenario_name, file.colliders, file.link_radii));
  for (const Frame& frame : file.result.frames) {
    stream.Add(frame.step, frame.points, frame.link_angles);
  }
  stream.End(file.result);
}

void WriteResultFile(const ResultFile& file, const std::string& path, ResultFileFormat format) {
  const int dim = CheckResultFile(file);
  ResultFileWriter writer(
      path, format,
      HeaderOfResult(file.result, dim, file.scenario_name, file.colliders, file.link_radii));
  for (const Frame& frame : file.result.frames) {
    writer.Add(frame.step, frame.points, frame.link_angles);
  }
  writer.Commit(file.result);
}

class FramesCsvWriter::Impl {
 public:
  Impl(const std::string& path, int dim) : file(path), stream(file.stream(), dim) {}
  AtomicFile file;
  CsvFramesStream stream;
  int dim;
  int64_t frames = 0, last_step = -1;
  Eigen::Index n = -1;
};

FramesCsvWriter::FramesCsvWriter(const std::string& path, int dim) {
  if (dim != 2 && dim != 3)
    ThrowNothingWritten(Problem::Invalid("dim", std::to_string(dim), "2 or 3"));
  impl_ = std::make_unique<Impl>(path, dim);
  impl_->dim = dim;
}

FramesCsvWriter::~FramesCsvWriter() = default;

void FramesCsvWriter::Add(int64_t step, const PointsRef& points, const VectorRef& link_angles) {
  if (impl_ == nullptr) throw std::logic_error("FramesCsvWriter::Add after Commit or a failure");
  Impl& s = *impl_;
  if (s.n < 0) s.n = points.rows() - 1;
  if (auto problem = ResultFrameProblem(static_cast<size_t>(s.frames), step, points, link_angles,
                                        s.last_step, s.n, s.dim)) {
    impl_.reset();
    ThrowNothingWritten(*problem);
  }
  try {
    s.stream.Add(step, points);
  } catch (const std::system_error&) {
    const std::system_error error = s.file.Error(EIO);
    impl_.reset();
    throw error;
  }
  ++s.frames;
  s.last_step = step;
}

void FramesCsvWriter::Commit() {
  if (impl_ == nullptr) throw std::logic_error("FramesCsvWriter::Commit after Commit or a failure");
  std::unique_ptr<Impl> impl = std::move(impl_);
  if (impl->frames == 0) {
    ThrowNothingWritten(
        Problem("frames", "the result has no frames; expected at least the initial frame"));
  }
  try {
    impl->stream.End();
  } catch (const std::system_error&) {
    throw impl->file.Error(EIO);
  }
  impl->file.Commit();
}

void WriteFramesCsv(const RunResult& result, std::ostream& out) {
  const int dim = CheckResult(result);
  CsvFramesStream stream(out, dim);
  for (const Frame& frame : result.frames) stream.Add(frame.step, frame.points);
  stream.End();
}

void WriteFramesCsv(const RunResult& result, const std::string& path) {
  const int dim = CheckResult(result);
  FramesCsvWriter writer(path, dim);
  for (const Frame& frame : result.frames) writer.Add(frame.step, frame.points, frame.link_angles);
  writer.Commit();
}

RunResult RunToFiles(const Chain& chain, const Points& leader_steps, const RunOptions& options,
                     const std::string& scenario_name, const RunFiles& files, FrameSink* also) {
  std::optional<ResultFileWriter> writer;
  std::vector<FrameSink*> sinks;
  if (!files.result.empty()) {
    sinks.push_back(&writer.emplace(files.result, ResultFileFormatOfPath(files.result),
                                    MakeResultHeader(chain, options, scenario_name)));
  }
  std::optional<FramesCsvWriter> csv;
  if (!files.csv.empty()) sinks.push_back(&csv.emplace(files.csv, chain.dim()));
  if (also != nullptr) sinks.push_back(also);
  FrameFanOut sink(sinks);
  RunResult result = Run(chain, leader_steps, options, &sink);
  if (writer) writer->Commit(result);
  if (csv) csv->Commit();
  return result;
}

}  // namespace flexkin
