#include <cerrno>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <system_error>

#include "flexkin/error.h"
#include "flexkin/result_io.h"
#include "io/atomic_file.h"

// Result files and frame CSV files out (docs/result-format.md).

namespace flexkin {
namespace {

using json = nlohmann::json;

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

// The result's dimension, after the one check of results (ValidateResult): consistent shapes and
// finite numbers everywhere, which JSON needs.
int CheckResult(const RunResult& r) {
  const int dim = r.frames.empty() ? 0 : static_cast<int>(r.frames[0].points.cols());
  if (Problems problems = ValidateResult(r, dim); !problems.empty()) {
    problems.front().message += "; nothing was written";
    ThrowIfAny(problems);
  }
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
    if (!out_)
      throw std::system_error(EIO, std::generic_category(), "cannot write to the output stream");
  }

 private:
  std::ostream& out_;
  std::string text_;
};

}  // namespace

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
    const OverallRunReport& o = result.overall;
    const ObjectiveWeights& w = result.weights;
    t += "\"overall\": {\"objective\": {";
    for (const auto& [term, name, summary] : Vocabulary<ObjectiveTerm>::kEntries) {
      t += std::string(term == ObjectiveTerm::kL2 ? "" : ", ") + "\"" + name + "\": ";
      AppendDouble(w[term], &t);
    }
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

}  // namespace flexkin
