#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "flexkin/result_io.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/tree_scenario.h"
#include "flexkin/vocabulary.h"

namespace flexkin {

// Pictures of a result (docs/rendering.md): snapshot figures (SVG, PNG, PDF), plots of the
// paper's claims, and animations (MP4, GIF). cairo draws; ffmpeg encodes the animations.
//
// Library target flexkin_render (built with the apps or the tests; not installed).
//
// Errors: InputError for an invalid option (field: the option's name, e.g. "width") or a result
// that cannot be drawn (field: "frames[f].points[i][k]" for a non-finite number, "frames" if there
// are none); std::system_error for a file that cannot be written; std::runtime_error when ffmpeg
// is missing or fails. Every writer is all-or-nothing: it writes a temporary file in the
// destination's directory and renames it over the destination only on success, so on any error
// an existing destination is left untouched and no partial file remains.

// Image formats of figures and plots, chosen by the file name's extension.
enum class ImageFormat {
  kSvg,  // ".svg": vector, sizes in px
  kPng,  // ".png": raster, 8-bit RGB
  kPdf,  // ".pdf": vector, one pixel of the options = one point (1/72 in)
};
// The format of `path` by its extension (case-insensitive); throws InputError (field `field`)
// for any other extension.
ImageFormat ImageFormatFromPath(const std::string& path, const std::string& field = "path");

// What `flexkin render --formats` can write, one entry per format.
enum class OutputFormat { kSvg, kPng, kPdf, kPlots, kMp4, kGif, kHtml, kGltf, kGlb };

template <>
struct Vocabulary<OutputFormat> {
  static constexpr const char* kKind = "format";
  // The summary says which files a format writes.
  static constexpr NamedValue<OutputFormat> kEntries[] = {
      {OutputFormat::kSvg, "svg", "<stem>.svg"},
      {OutputFormat::kPng, "png", "<stem>.png"},
      {OutputFormat::kPdf, "pdf", "<stem>.pdf"},
      {OutputFormat::kPlots, "plots",
       "<stem>_{path_length,link_angles,length_error}.{svg,png}; a tree's path_length, "
       "length_error, target_miss, joint_angles"},
      {OutputFormat::kMp4, "mp4", "<stem>.mp4"},
      {OutputFormat::kGif, "gif", "<stem>.gif"},
      {OutputFormat::kHtml, "html", "<stem>.html"},
      {OutputFormat::kGltf, "gltf", "<stem>.gltf"},
      {OutputFormat::kGlb, "glb", "<stem>.glb"},
  };
};

// The formats a robot trajectory (flexkin/robot_scenario.h, RobotTrajectoryFile) is drawn in: the
// figure, the animation and the viewer. Not "plots" (they plot a chain result's claims: its
// metrics, link angles and length errors) nor glTF (a chain's skeleton).
inline constexpr OutputFormat kTrajectoryFormats[] = {
    OutputFormat::kSvg, OutputFormat::kPng, OutputFormat::kPdf,
    OutputFormat::kMp4, OutputFormat::kGif, OutputFormat::kHtml,
};
// Throws InputError (field `field`) naming `format` and the ones above unless it is one of them.
void CheckTrajectoryFormat(OutputFormat format, const std::string& field);

// The snapshot figure: the chain every k-th recorded frame, overlaid, in the style of the paper's
// Figs. 6 to 12.
struct FigureOptions {
  // Draw recorded frames 0, k, 2k, ... and the last one. 0 = automatic: the smallest k that
  // draws at most 16 frames (every frame when there are at most 16). Typical: 0, 1, 10.
  int every_k = 0;
  // Size of the picture in pixels (SVG px; PDF points), 64 to 8192. Height 0 = automatic: the
  // data's aspect ratio (equal scales) with little white space, 0.4 to 1.2 times the width.
  int width = 960;
  int height = 0;
  // 3D only: the direction the chain is seen from (orthographic projection). Azimuth: degrees
  // about the z axis from the +x axis (any value); elevation: degrees above the x-y plane,
  // -90 to 90. The default is matplotlib's usual 3D view.
  double azimuth = -60.0;
  double elevation = 30.0;
  // The title's first line; "" = the scenario's name (or "flexkin result" without one). A second,
  // smaller line always gives the method, links, steps and k.
  std::string title;
  // Draw the path of the leading end (point 0) through every recorded frame, with an arrowhead.
  bool show_leader_path = true;
  // Draw the legend (in the corner of the plot that covers the fewest drawn points).
  bool show_legend = true;

  // Every problem (empty if valid), each naming its member ("width").
  Problems Validate() const;
};

// The recorded frames a figure draws: 0, k, 2k, ... and the last one (indices into frames).
// `every_k` = 0 picks k as FigureOptions::every_k says. Requires num_frames >= 1, every_k >= 0.
std::vector<int> SnapshotFrames(int num_frames, int every_k);

// Writes the snapshot figure of `file` to `path` (.svg, .png or .pdf).
void WriteSnapshotFigure(const ResultFile& file, const FigureOptions& options,
                         const std::string& path);
// The same for a robot trajectory, drawn as RobotTrajectoryAsResult makes it a chain: the end
// effector leads (its path is drawn), the fixed base is drawn as a support, and the subtitle says
// "robot", the method, the targets and how many were not reached.
void WriteSnapshotFigure(const RobotTrajectoryFile& trajectory, const FigureOptions& options,
                         const std::string& path);

// Plots of one quantity of a result.
enum class PlotKind {
  kPathLength,   // "path_length": distance travelled by each point (metrics.path_length) against
                 // the point's index: the motion dying out along the chain
  kLinkAngles,   // "link_angles": each link's angle to the pull direction (frame.link_angles)
                 // against the leader step, coloured by link index: the alignment
  kLengthError,  // "length_error": largest relative link-length error of each recorded frame
                 // against the leader step, log scale (FrameLengthErrors)
  kEnergy,       // "energy": a dynamic run's energy (dynamics.energy) at every frame against the
                 // time in seconds; dynamic chains only
  kTargetMiss,   // "target_miss": a tree result's distance of each driven point from its goal
                 // (relative to the longest link) against the frame, log scale; trees only
  kJointAngles,  // "joint_angles": a robot tree's joint angles against the frame; robot trees only
};
template <>
struct Vocabulary<PlotKind> {
  static constexpr const char* kKind = "plot";
  static constexpr NamedValue<PlotKind> kEntries[] = {
      {PlotKind::kPathLength, "path_length", "distance travelled by each point against its index"},
      {PlotKind::kLinkAngles, "link_angles", "each link's angle to the pull against the step"},
      {PlotKind::kLengthError, "length_error", "largest relative link-length error per frame"},
      {PlotKind::kEnergy, "energy", "a dynamic run's energy against the time"},
      {PlotKind::kTargetMiss, "target_miss", "a tree's miss of each target against the frame"},
      {PlotKind::kJointAngles, "joint_angles", "a robot tree's joint angles against the frame"},
  };
};
inline const char* PlotKindName(PlotKind kind) { return NameOf(kind); }
// Throws InputError naming `field` and listing the names.
inline PlotKind ParsePlotKind(const std::string& name, const std::string& field = "plot") {
  return ParseName<PlotKind>(name, field);
}

struct PlotOptions {
  // Size in pixels (SVG px; PDF points). 64 to 8192. Typical: 800 x 500.
  int width = 800;
  int height = 500;
  // The title; "" = what is plotted and the scenario's name.
  std::string title;

  // Every problem (empty if valid), each naming its member ("width").
  Problems Validate() const;
};

// Writes one plot of `file` to `path` (.svg, .png or .pdf). kLinkAngles needs link angles
// (InputError "frames[f].link_angles" if a frame has none); kTargetMiss and kJointAngles are
// trees' (InputError "plot").
void WritePlot(const ResultFile& file, PlotKind kind, const PlotOptions& options,
               const std::string& path);

// For each recorded frame, max over the links of |(|x_i - x_{i-1}| - L_i)| / L_i.
Eigen::VectorXd FrameLengthErrors(const RunResult& result);

// The animation: one picture per drawn frame, axes fixed over the whole motion.
struct AnimationOptions {
  // Size in pixels, 64 to 8192; an odd value is rounded up to even (H.264 in yuv420p needs
  // even sizes). Height 0 = automatic, as FigureOptions::height. Typical: 640 x 0.
  int width = 640;
  int height = 0;
  // Frames per second of the video, 1 to 120. Typical: 30.
  int fps = 30;
  // Draw recorded frames 0, k, 2k, ... and the last one. 0 = automatic: the smallest k that
  // draws at most `max_frames` frames. Typical: 0 or 1.
  int every_k = 0;
  // Upper bound of the pictures when every_k = 0: long runs are subsampled. >= 2. Typical: 300
  // (10 s at 30 fps).
  int max_frames = 300;
  // Short runs play at least this long, in seconds: each picture is shown ceil(min_seconds x
  // fps / pictures) times. 0 = one video frame per picture. Typical: 3.
  double min_seconds = 3.0;
  // The last picture is held this long at the end, in seconds (GIFs loop). Typical: 1.
  double end_pause = 1.0;
  // 3D view, as FigureOptions.
  double azimuth = -60.0;
  double elevation = 30.0;
  // The title's first line; "" = the scenario's name.
  std::string title;
  // The ffmpeg program: a name looked up in PATH or a path.
  std::string ffmpeg = "ffmpeg";
  // H.264 constant rate factor for MP4, 0 (lossless) to 51; lower is better and larger.
  // Typical: 20.
  int crf = 20;
  // Called before each picture is drawn (done of total pictures); empty = none. It may throw
  // to stop the writing (a signal's handler, say): the video's temporary file is removed, ffmpeg
  // is killed and reaped, an existing file at the path is left untouched and the exception
  // propagates.
  std::function<void(int64_t done, int64_t total)> progress;

  // Every problem (empty if valid), each naming its member ("width").
  Problems Validate() const;
};

// Writes the animation of `file` to `path`: ".mp4" (H.264, yuv420p) or ".gif" (palette made from
// the whole animation), by extension; InputError (field "path") for any other. Frames are drawn
// with cairo and piped raw into an ffmpeg process; the output goes to a temporary file in the
// destination's directory that is renamed over `path` only when ffmpeg succeeds.
void WriteAnimation(const ResultFile& file, const AnimationOptions& options,
                    const std::string& path);
// The same for a robot trajectory, drawn as its snapshot figure is.
void WriteAnimation(const RobotTrajectoryFile& trajectory, const AnimationOptions& options,
                    const std::string& path);

// Tree results (flexkin/tree_scenario.h; docs/trees.md, "Pictures"), drawn as a chain result's:
// the figure shows every k-th frame fading from old to new, the first dashed, the last bold, each
// link a line from its parent's point, the driven points' paths (show_leader_path) and the fixed
// points' supports; the animation plays the frames with the driven points' paths so far. Throw
// InputError for invalid options or a tree result ValidateTreeResult refuses, as the chain
// writers do.
void WriteTreeFigure(const TreeResultFile& tree, const FigureOptions& options,
                     const std::string& path);
void WriteTreeAnimation(const TreeResultFile& tree, const AnimationOptions& options,
                        const std::string& path);

// The plots of a tree result (docs/trees.md, "Plots"), against the frame: kPathLength (the
// distance each point travelled, by its index: the targets' in red, the fixed points' grey),
// kLengthError (each frame's largest relative link-length error against the first frame's
// lengths), kTargetMiss (each position target's distance from its goal, relative to the longest
// link; pointing goals are not drawn) and kJointAngles (a robot tree's). TreePlotKinds: the ones
// `tree` has the data for (target_miss: goals and a position target; joint_angles: a robot
// tree's angles). WriteTreePlot throws InputError for invalid options, a tree ValidateTreeResult
// refuses, or a kind not among TreePlotKinds(tree) ("plot", naming those that are).
std::vector<PlotKind> TreePlotKinds(const TreeResultFile& tree);
void WriteTreePlot(const TreeResultFile& tree, PlotKind kind, const PlotOptions& options,
                   const std::string& path);

namespace internal {

void WriteSnapshotFigure(const CheckedDrawing& drawing, const FigureOptions& options,
                         const std::string& path);
void WritePlot(const CheckedDrawing& drawing, PlotKind kind, const PlotOptions& options,
               const std::string& path);
void WriteAnimation(const CheckedDrawing& drawing, const AnimationOptions& options,
                    const std::string& path);
// The same for a tree and options Draw has checked (ValidateTreeResult, Validate): no check again.
void WriteTreeFigure(const TreeResultFile& tree, const FigureOptions& options,
                     const std::string& path);
void WriteTreeAnimation(const TreeResultFile& tree, const AnimationOptions& options,
                        const std::string& path);
void WriteTreePlot(const TreeResultFile& tree, PlotKind kind, const PlotOptions& options,
                   const std::string& path);

}  // namespace internal

}  // namespace flexkin
