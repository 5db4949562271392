#pragma once
// One call draws a file of any kind flexkin writes (a chain result, a robot trajectory, a strand
// file) in a list of formats, each output written whole or not at all: the command line's
// `flexkin render` and Python's flexkin.render are shells over it (docs/rendering.md). A
// component header, like render.h, viewer.h and gltf.h: built with them, not installed.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "flexkin/gltf.h"
#include "flexkin/render.h"
#include "flexkin/result_io.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/strands_render.h"
#include "flexkin/strands_viewer.h"
#include "flexkin/viewer.h"

namespace flexkin {

// What a file to draw holds.
enum class DrawnKind { kChainResult, kRobotTrajectory, kStrandFile, kTreeResult };

// The options every component reads, and where the outputs go.
struct DrawOptions {
  // The formats, written in the vocabulary's order; empty: the kind's default (DefaultFormats).
  std::vector<OutputFormat> formats;
  // Outputs are written to `base` + each format's suffix ("out/result" -> "out/result.svg",
  // "out/result_path_length.png"); the directory is created if missing.
  std::string base;
  FigureOptions figure;
  PlotOptions plot;
  AnimationOptions animation;
  ViewerOptions viewer;
  GltfOptions gltf;
  StrandsRenderOptions strands;
  StrandsViewerOptions strands_viewer;
  // Called with each output's path before it is written, and with a note for an output left out
  // ("no link_angles plot: the leading end never moves"); either may be empty.
  std::function<void(const std::string& path)> writing;
  std::function<void(const std::string& note)> note;
};

// The settings the command line's flags and Python's keywords share, each applied to every
// component that has it (a width to the figure, the plots, the animation and the strands'
// pictures), as `flexkin render` documents them. nullopt leaves the components' own values.
struct DrawShorthands {
  std::optional<int> every;         // figures: every K-th recorded frame (0 automatic)
  std::optional<int> width;         // pixels
  std::optional<int> height;        // pixels; 0 = from the data (the plots keep their own)
  std::optional<double> azimuth;    // 3D view, degrees about z from +x
  std::optional<double> elevation;  // 3D view, degrees above the x-y plane
  std::optional<int> fps;           // animations
  std::optional<int> max_frames;    // animations and the strands viewer
  std::optional<int> max_strands;   // strand files: at most N strands drawn
  std::optional<std::string> title;
  std::optional<std::string> ffmpeg;  // the program for mp4 and gif
};
void ApplyShorthands(const DrawShorthands& shorthands, DrawOptions* options);

// Every problem of the options a file of `kind` is drawn with, each naming its member
// ("figure.width", "strands.max_frames") or "formats" for a format the kind is not drawn in.
Problems ValidateDrawOptions(DrawnKind kind, const DrawOptions& options);

// The formats a file of `kind` is drawn in by default: svg, png, plots for a chain result; svg
// and png for the others.
std::vector<OutputFormat> DefaultFormats(DrawnKind kind);
// "svg,png,plots" (or a list of names) -> formats, in the vocabulary's order, each once;
// InputError naming `field` for an unknown name (listing the valid ones) or an empty list.
std::vector<OutputFormat> ParseOutputFormats(const std::string& list, const std::string& field);
std::vector<OutputFormat> ParseOutputFormats(const std::vector<std::string>& names,
                                             const std::string& field);
// The formats a file of `kind` can be drawn in, and their names ("svg, png, ...").
std::vector<OutputFormat> FormatsOf(DrawnKind kind);
std::string FormatNamesOf(DrawnKind kind);

// Draws a chain result, a robot trajectory or the strand file at `path` and returns the paths
// written, in order. Throws InputError for invalid options (ValidateDrawOptions's first problem)
// or a result that cannot be drawn, std::system_error when a file cannot be written,
// std::runtime_error when ffmpeg is missing or fails; an output that fails is not left behind
// (those written before it are).
std::vector<std::string> Draw(const ResultFile& result, const DrawOptions& options);
std::vector<std::string> Draw(const RobotTrajectoryFile& trajectory, const DrawOptions& options);
std::vector<std::string> DrawStrandFile(const std::string& path, const DrawOptions& options);
// A tree result (flexkin/tree_scenario.h) in svg, png, pdf, mp4, gif, gltf or glb; InputError
// also for a tree ValidateTreeResult refuses.
std::vector<std::string> Draw(const TreeResultFile& tree, const DrawOptions& options);

// Whether a problem Draw, DrawStrandFile or DrawFile threw is one of the options (its field
// "formats", a component's member such as "figure.width" or "strands.max_frames", or a writer's
// "options.max_frames"), which a front end names by its own flag or keyword, rather than one of
// what is drawn.
bool IsDrawOptionsProblem(const Problem& problem);

// A file of any kind, told apart by its content (IsStrandFile, IsTreeResultFile,
// IsRobotTrajectoryFile, else a result file, JSON or .npz), read once and drawn. A problem of the
// file is named by it
// ("r.json: /frames/3/points/2/1"); the options' problems by their member.
DrawnKind KindOfDrawnFile(const std::string& path);
std::vector<std::string> DrawFile(const std::string& path, const DrawOptions& options);

// DIR/STEM, STEM the file's name without ".json" or ".npz", DIR `output_dir` or, if empty, the
// file's directory: the base of `flexkin render`'s outputs.
std::string OutputBaseOf(const std::string& path, const std::string& output_dir);

}  // namespace flexkin
