// Validation of the render options and results; ImageFormatFromPath, SnapshotFrames,
// plot-kind names and FrameLengthErrors.
#include "render/checks.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "flexkin/error.h"
#include "flexkin/propagate.h"
#include "flexkin/render.h"

namespace flexkin {
namespace render {

void CheckDrawable(const ResultFile& file) { ThrowIfAny(ValidateResult(file)); }

void CheckRange(const char* field, double value, double lo, double hi, bool integer,
                Problems* problems) {
  if (value >= lo && value <= hi) return;
  const std::string expected = std::string(integer ? "an integer" : "a number") + " from " +
                               FormatNumber(lo) + " to " + FormatNumber(hi);
  problems->emplace_back(field, FormatNumber(value) + " is not valid; expected " + expected,
                         FormatNumber(value), expected);
}

std::string MainTitle(const ResultFile& file, const std::string& title) {
  if (!title.empty()) return title;
  return file.scenario_name.empty() ? "flexkin result" : file.scenario_name;
}

std::string RunSummary(const ResultFile& file) {
  const RunResult& r = file.result;
  const long long n = r.lengths.size();
  if (r.dynamics.enabled) {
    // A dynamic chain: its projection, and its leader steps are frames.
    return "dynamic, projection " + r.dynamics.projection + " \u00b7 " + std::to_string(file.dim) +
           "D \u00b7 " + std::to_string(n) + (n == 1 ? " link" : " links") + " \u00b7 " +
           std::to_string(r.num_steps) + (r.num_steps == 1 ? " frame" : " frames");
  }
  return std::string(MethodName(r.method)) + " \u00b7 " + std::to_string(file.dim) + "D \u00b7 " +
         std::to_string(n) + (n == 1 ? " link" : " links") + " \u00b7 " +
         std::to_string(r.num_steps) + (r.num_steps == 1 ? " leader step" : " leader steps");
}

Look ChainLook(const ResultFile& file) { return {RunSummary(file), "leading end", false}; }

Look LookOf(const internal::CheckedDrawing& drawing) {
  return drawing.trajectory != nullptr ? TrajectoryLook(*drawing.trajectory)
                                       : ChainLook(drawing.result);
}

Look TrajectoryLook(const RobotTrajectoryFile& t) {
  const long long n = t.link_lengths.size(), targets = t.targets.rows();
  std::string summary = "robot \u00b7 " + t.method + " \u00b7 " + std::to_string(t.dim) +
                        "D \u00b7 " + std::to_string(n) + (n == 1 ? " link" : " links") +
                        " \u00b7 " + std::to_string(targets) +
                        (targets == 1 ? " target" : " targets") + " \u00b7 ";
  summary +=
      t.unreached == 0 ? std::string("all reached") : std::to_string(t.unreached) + " not reached";
  return {summary, "end effector", true};
}

}  // namespace render

namespace {
constexpr int kMinSize = 64, kMaxSize = 8192;

void CheckSize(int width, int height, Problems* problems) {
  render::CheckRange("width", width, kMinSize, kMaxSize, true, problems);
  render::CheckRange("height", height, kMinSize, kMaxSize, true, problems);
}

// 0 (automatic) or an integer from 64 to 8192.
void CheckAutoHeight(int height, Problems* problems) {
  if (height != 0 && (height < kMinSize || height > kMaxSize)) {
    problems->emplace_back(
        "height",
        FormatNumber(height) +
            " is not valid; expected 0 (automatic) or an integer from 64 to 8192",
        FormatNumber(height), "0 (automatic) or an integer from 64 to 8192");
  }
}

void CheckEveryK(int every_k, Problems* problems) {
  if (every_k < 0) {
    problems->emplace_back("every_k",
                           FormatNumber(every_k) + " is not valid; expected 0 (automatic) or more",
                           FormatNumber(every_k), "0 (automatic) or more");
  }
}

void CheckAzimuth(double azimuth, Problems* problems) {
  if (!std::isfinite(azimuth)) {
    problems->emplace_back(
        "azimuth", FormatNumber(azimuth) + " is not valid; expected a finite number of degrees",
        FormatNumber(azimuth), "a finite number of degrees");
  }
}
}  // namespace

ImageFormat ImageFormatFromPath(const std::string& path, const std::string& field) {
  const size_t dot = path.rfind('.');
  const size_t slash = path.rfind('/');
  std::string ext = dot == std::string::npos || (slash != std::string::npos && dot < slash)
                        ? ""
                        : path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (ext == ".svg") return ImageFormat::kSvg;
  if (ext == ".png") return ImageFormat::kPng;
  if (ext == ".pdf") return ImageFormat::kPdf;
  throw InputError(field,
                   "\"" + path + "\" has no known image extension; expected .svg, .png or .pdf");
}

Problems FigureOptions::Validate() const {
  Problems problems;
  CheckEveryK(every_k, &problems);
  render::CheckRange("width", width, kMinSize, kMaxSize, true, &problems);
  CheckAutoHeight(height, &problems);
  CheckAzimuth(azimuth, &problems);
  render::CheckRange("elevation", elevation, -90, 90, false, &problems);
  return problems;
}

Problems PlotOptions::Validate() const {
  Problems problems;
  CheckSize(width, height, &problems);
  return problems;
}

Problems AnimationOptions::Validate() const {
  Problems problems;
  render::CheckRange("width", width, kMinSize, kMaxSize, true, &problems);
  CheckAutoHeight(height, &problems);
  render::CheckRange("fps", fps, 1, 120, true, &problems);
  CheckEveryK(every_k, &problems);
  if (max_frames < 2) {
    problems.emplace_back("max_frames",
                          FormatNumber(max_frames) + " is not valid; expected an integer >= 2",
                          FormatNumber(max_frames), "an integer >= 2");
  }
  render::CheckRange("min_seconds", min_seconds, 0, 3600, false, &problems);
  render::CheckRange("end_pause", end_pause, 0, 60, false, &problems);
  CheckAzimuth(azimuth, &problems);
  render::CheckRange("elevation", elevation, -90, 90, false, &problems);
  render::CheckRange("crf", crf, 0, 51, true, &problems);
  if (ffmpeg.empty()) {
    problems.emplace_back("ffmpeg",
                          "the program's name is empty; expected a name or path such as "
                          "\"ffmpeg\"");
  }
  return problems;
}

void CheckTrajectoryFormat(OutputFormat format, const std::string& field) {
  std::string valid;
  for (OutputFormat f : kTrajectoryFormats) {
    if (f == format) return;
    valid += (valid.empty() ? "" : ", ") + std::string(NameOf(f));
  }
  const std::string name = NameOf(format);
  throw InputError(Problem(field,
                           "format \"" + name +
                               "\" is not available for robot trajectories (it draws chain "
                               "results only); expected formats among " +
                               valid,
                           "\"" + name + "\"", valid));
}

std::vector<int> SnapshotFrames(int num_frames, int every_k) {
  constexpr int kAutoFrames = 16;
  // The smallest k with ceil((num_frames - 1) / k) + 1 <= kAutoFrames.
  if (every_k == 0) every_k = std::max(1, (num_frames - 1 + kAutoFrames - 2) / (kAutoFrames - 1));
  std::vector<int> frames;
  for (int f = 0; f < num_frames; f += every_k) frames.push_back(f);
  if (frames.back() != num_frames - 1) frames.push_back(num_frames - 1);
  return frames;
}

Eigen::VectorXd FrameLengthErrors(const RunResult& result) {
  Eigen::VectorXd errors = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(result.frames.size()));
  for (size_t f = 0; f < result.frames.size(); ++f) {
    const Points& p = result.frames[f].points;
    for (Eigen::Index i = 0; i < result.lengths.size() && i + 1 < p.rows(); ++i) {
      const double d = (p.row(i + 1) - p.row(i)).norm();
      errors[f] = std::max(errors[f], std::abs(d - result.lengths[i]) / result.lengths[i]);
    }
  }
  return errors;
}

}  // namespace flexkin
