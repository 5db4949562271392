#include "viewer_data.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <string>

#include "flexkin/error.h"
#include "flexkin/propagate.h"

namespace flexkin::viewer_internal {

void CheckResult(const ResultFile& file, const ViewerOptions& options) {
  ThrowIfAny(ValidateResult(file.result, file.dim));
  const Eigen::Index n = file.result.lengths.size();
  for (size_t i = 0; i < options.trail_points.size(); ++i) {
    if (options.trail_points[i] > n) {
      throw InputError("trail_points[" + std::to_string(i) + "]",
                       std::to_string(options.trail_points[i]) + " is not valid; the result has " +
                           "points 0 to " + std::to_string(n));
    }
  }
}

namespace {

// Appends `x` with `digits` significant digits (JSON number syntax; x is finite).
void AppendNumber(double x, int digits, std::string* out) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, x);
  out->append(buffer);
}

// Appends `x` so that it reads back exactly, in the fewest of 15 or 17 digits.
void AppendExact(double x, std::string* out) { out->append(FormatNumber(x)); }

void AppendString(const std::string& s, std::string* out) {
  out->push_back('"');
  for (const char c : s) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out->push_back('\\');
      out->push_back(c);
    } else if (u < 0x20 || c == '<' || c == '>' || c == '&') {
      char buffer[8];
      std::snprintf(buffer, sizeof buffer, "\\u%04x", u);
      out->append(buffer);
    } else {
      out->push_back(c);
    }
  }
  out->push_back('"');
}

void AppendKey(const char* key, std::string* out) {
  if (out->back() != '{') out->push_back(',');
  AppendString(key, out);
  out->push_back(':');
}

void AppendExactArray(const Eigen::VectorXd& v, std::string* out) {
  out->push_back('[');
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (i > 0) out->push_back(',');
    AppendExact(v[i], out);
  }
  out->push_back(']');
}

// Largest |(|x_i - x_{i-1}| - L_i)| / L_i of one frame, from the unrounded coordinates.
double FrameLengthError(const Points& p, const Eigen::VectorXd& lengths) {
  double worst = 0.0;
  for (Eigen::Index i = 1; i < p.rows(); ++i) {
    const double d = (p.row(i) - p.row(i - 1)).norm();
    worst = std::max(worst, std::abs(d - lengths[i - 1]) / lengths[i - 1]);
  }
  return worst;
}

}  // namespace

std::string ViewerDataJson(const ResultFile& file, const ViewerOptions& options,
                           const RobotTrajectoryFile* robot) {
  const RunResult& r = file.result;
  const size_t num_frames = r.frames.size();
  std::string out = "{";
  out.reserve(num_frames * r.frames[0].points.size() * (options.digits + 8) + 4096);

  AppendKey("title", &out);
  AppendString(!options.title.empty()        ? options.title
               : !file.scenario_name.empty() ? file.scenario_name
                                             : std::string("flexkin result"),
               &out);
  AppendKey("scenario", &out);
  AppendString(file.scenario_name, &out);
  AppendKey("method", &out);
  AppendString(robot != nullptr ? robot->method : std::string(MethodName(r.method)), &out);
  if (robot != nullptr) {
    AppendKey("robot", &out);
    out.push_back('{');
    AppendKey("links", &out);
    out += std::to_string(robot->link_lengths.size());
    AppendKey("targets", &out);
    out += std::to_string(robot->targets.rows());
    AppendKey("unreached", &out);
    out += std::to_string(robot->unreached);
    AppendKey("max_ee_error", &out);
    AppendExact(robot->max_ee_error, &out);
    out.push_back('}');
  }
  AppendKey("dim", &out);
  out += std::to_string(file.dim);
  AppendKey("num_links", &out);
  out += std::to_string(r.lengths.size());
  AppendKey("num_steps", &out);
  out += std::to_string(r.num_steps);
  AppendKey("substeps", &out);
  out += std::to_string(r.accuracy.substeps);
  AppendKey("seconds", &out);
  AppendExact(r.seconds, &out);
  AppendKey("link_lengths", &out);
  AppendExactArray(r.lengths, &out);

  // Per frame: the leader step, then the largest relative link-length error.
  AppendKey("steps", &out);
  out.push_back('[');
  for (size_t f = 0; f < num_frames; ++f) {
    if (f > 0) out.push_back(',');
    out += std::to_string(r.frames[f].step);
  }
  out.push_back(']');
  AppendKey("frame_length_error", &out);
  out.push_back('[');
  for (size_t f = 0; f < num_frames; ++f) {
    if (f > 0) out.push_back(',');
    AppendNumber(FrameLengthError(r.frames[f].points, r.lengths), 3, &out);
  }
  out.push_back(']');
  // Frame after frame, point after point (leading end first), coordinate after coordinate.
  AppendKey("positions", &out);
  out.push_back('[');
  bool first = true;
  for (const Frame& frame : r.frames) {
    const Points& p = frame.points;
    for (Eigen::Index i = 0; i < p.size(); ++i) {
      if (!first) out.push_back(',');
      first = false;
      AppendNumber(p.data()[i], options.digits, &out);  // row-major: point after point
    }
  }
  out.push_back(']');

  const Metrics& m = r.metrics;
  AppendKey("metrics", &out);
  out.push_back('{');
  AppendKey("l2_total", &out);
  AppendExact(m.l2_total, &out);
  AppendKey("l2_weighted_total", &out);
  AppendExact(m.l2_weighted_total, &out);
  AppendKey("max_relative_length_error", &out);
  AppendExact(m.max_relative_length_error, &out);
  AppendKey("path_length", &out);
  AppendExactArray(m.path_length, &out);
  AppendKey("l2_per_step", &out);
  AppendExactArray(m.l2_per_step, &out);
  out.push_back('}');

  const AccuracyReport& a = r.accuracy;
  AppendKey("accuracy", &out);
  out.push_back('{');
  AppendKey("enabled", &out);
  out += a.enabled ? "true" : "false";
  AppendKey("tolerance", &out);
  AppendExact(a.tolerance, &out);
  AppendKey("estimated_error", &out);
  AppendExact(a.estimated_error, &out);
  AppendKey("met", &out);
  out += a.met ? "true" : "false";
  out.push_back('}');
  AppendKey("overall_failures", &out);
  out += std::to_string(r.overall.failures);

  AppendKey("options", &out);
  out.push_back('{');
  AppendKey("playback_seconds", &out);
  AppendExact(options.playback_seconds, &out);
  AppendKey("autoplay", &out);
  out += options.autoplay ? "true" : "false";
  AppendKey("loop", &out);
  out += options.loop ? "true" : "false";
  AppendKey("show_leader_path", &out);
  out += options.show_leader_path ? "true" : "false";
  AppendKey("trail_points", &out);
  out.push_back('[');
  for (size_t i = 0; i < options.trail_points.size(); ++i) {
    if (i > 0) out.push_back(',');
    out += std::to_string(options.trail_points[i]);
  }
  out.push_back(']');
  AppendKey("azimuth", &out);
  AppendExact(options.azimuth, &out);
  AppendKey("elevation", &out);
  AppendExact(options.elevation, &out);
  AppendKey("perspective", &out);
  out += options.perspective ? "true" : "false";
  out.push_back('}');
  out.push_back('}');
  // Strings are escaped and numbers have no '<': nothing can close the <script> element.
  assert(out.find("</") == std::string::npos);
  return out;
}

}  // namespace flexkin::viewer_internal
