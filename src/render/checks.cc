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

void CheckDrawable(const ResultFile& file) {
  const RunResult& r = file.result;
  if (file.dim != 2 && file.dim != 3) {
    throw InputError("dim", FormatNumber(file.dim) + " is not valid; expected 2 or 3");
  }
  if (r.frames.empty()) throw InputError("frames", "the result has no frames; nothing to draw");
  const Eigen::Index n = r.lengths.size();
  for (size_t f = 0; f < r.frames.size(); ++f) {
    const Points& p = r.frames[f].points;
    const std::string field = "frames[" + std::to_string(f) + "]";
    if (p.rows() != n + 1 || p.cols() != file.dim) {
      throw InputError(field + ".points", "has " + std::to_string(p.rows()) + " by " +
                                              std::to_string(p.cols()) + " values; expected " +
                                              std::to_string(n + 1) + " by " +
                                              std::to_string(file.dim));
    }
    for (Eigen::Index i = 0; i < p.rows(); ++i) {
      for (Eigen::Index k = 0; k < p.cols(); ++k) {
        if (!std::isfinite(p(i, k))) {
          throw InputError(field + ".points[" + std::to_string(i) + "][" + std::to_string(k) + "]",
                           FormatNumber(p(i, k)) + " is not valid; expected a finite number");
        }
      }
    }
    const Eigen::VectorXd& a = r.frames[f].link_angles;
    for (Eigen::Index i = 0; i < a.size(); ++i) {
      if (!std::isfinite(a[i])) {
        throw InputError(field + ".link_angles[" + std::to_string(i) + "]",
                         FormatNumber(a[i]) + " is not valid; expected a finite number");
      }
    }
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!(r.lengths[i] > 0.0) || !std::isfinite(r.lengths[i])) {
      throw InputError("link_lengths[" + std::to_string(i) + "]",
                       FormatNumber(r.lengths[i]) + " is not valid; expected a positive number");
    }
  }
  for (Eigen::Index i = 0; i < r.metrics.path_length.size(); ++i) {
    if (!std::isfinite(r.metrics.path_length[i])) {
      throw InputError(
          "metrics.path_length[" + std::to_string(i) + "]",
          FormatNumber(r.metrics.path_length[i]) + " is not valid; expected a finite number");
    }
  }
}

void ThrowIfInvalid(const std::string& why) {
  if (why.empty()) return;
  const size_t colon = why.find(": ");
  if (colon == std::string::npos) throw InputError("", why);
  throw InputError(why.substr(0, colon), why.substr(colon + 2));
}

std::string CheckRange(const char* field, double value, double lo, double hi, bool integer) {
  if (value >= lo && value <= hi) return "";
  return std::string(field) + ": " + FormatNumber(value) + " is not valid; expected " +
         (integer ? "an integer" : "a number") + " from " + FormatNumber(lo) + " to " +
         FormatNumber(hi);
}

std::string MainTitle(const ResultFile& file, const std::string& title) {
  if (!title.empty()) return title;
  return file.scenario_name.empty() ? "flexkin result" : file.scenario_name;
}

std::string RunSummary(const ResultFile& file) {
  const RunResult& r = file.result;
  const long long n = r.lengths.size();
  return std::string(MethodName(r.method)) + " \u00b7 " + std::to_string(file.dim) + "D \u00b7 " +
         std::to_string(n) + (n == 1 ? " link" : " links") + " \u00b7 " +
         std::to_string(r.num_steps) + (r.num_steps == 1 ? " leader step" : " leader steps");
}

}  // namespace render

namespace {
constexpr int kMinSize = 64, kMaxSize = 8192;

std::string SizeCheck(int width, int height) {
  std::string why = render::CheckRange("width", width, kMinSize, kMaxSize, true);
  if (why.empty()) why = render::CheckRange("height", height, kMinSize, kMaxSize, true);
  return why;
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

std::string FigureOptions::Validate() const {
  if (every_k < 0)
    return "every_k: " + FormatNumber(every_k) + " is not valid; expected 0 (automatic) or more";
  std::string why = render::CheckRange("width", width, kMinSize, kMaxSize, true);
  if (why.empty() && height != 0 && (height < kMinSize || height > kMaxSize)) {
    why = "height: " + FormatNumber(height) +
          " is not valid; expected 0 (automatic) or an integer from 64 to 8192";
  }
  if (why.empty() && !std::isfinite(azimuth))
    why =
        "azimuth: " + FormatNumber(azimuth) + " is not valid; expected a finite number of degrees";
  if (why.empty()) why = render::CheckRange("elevation", elevation, -90, 90, false);
  return why;
}

std::string PlotOptions::Validate() const { return SizeCheck(width, height); }

std::string AnimationOptions::Validate() const {
  std::string why = render::CheckRange("width", width, kMinSize, kMaxSize, true);
  if (why.empty() && height != 0 && (height < kMinSize || height > kMaxSize)) {
    why = "height: " + FormatNumber(height) +
          " is not valid; expected 0 (automatic) or an integer from 64 to 8192";
  }
  if (why.empty()) why = render::CheckRange("fps", fps, 1, 120, true);
  if (why.empty() && every_k < 0)
    why = "every_k: " + FormatNumber(every_k) + " is not valid; expected 0 (automatic) or more";
  if (why.empty() && max_frames < 2)
    why = "max_frames: " + FormatNumber(max_frames) + " is not valid; expected an integer >= 2";
  if (why.empty()) why = render::CheckRange("min_seconds", min_seconds, 0, 3600, false);
  if (why.empty()) why = render::CheckRange("end_pause", end_pause, 0, 60, false);
  if (why.empty() && !std::isfinite(azimuth))
    why =
        "azimuth: " + FormatNumber(azimuth) + " is not valid; expected a finite number of degrees";
  if (why.empty()) why = render::CheckRange("elevation", elevation, -90, 90, false);
  if (why.empty()) why = render::CheckRange("crf", crf, 0, 51, true);
  if (why.empty() && ffmpeg.empty())
    why = "ffmpeg: the program's name is empty; expected a name or path such as \"ffmpeg\"";
  return why;
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

const char* PlotKindName(PlotKind kind) {
  switch (kind) {
    case PlotKind::kPathLength:
      return "path_length";
    case PlotKind::kLinkAngles:
      return "link_angles";
    case PlotKind::kLengthError:
      return "length_error";
  }
  return "?";
}

PlotKind ParsePlotKind(const std::string& name, const std::string& field) {
  for (PlotKind kind : kAllPlotKinds) {
    if (name == PlotKindName(kind)) return kind;
  }
  throw InputError(field, "unknown plot \"" + name +
                              "\"; expected \"path_length\", \"link_angles\" or \"length_error\"");
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
