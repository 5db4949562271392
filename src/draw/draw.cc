// Draw: the table of output formats and the one dispatch from a file of any kind to its writers
// (include/flexkin/draw.h), shared by `flexkin render` and flexkin.render.
#include "flexkin/draw.h"

#include <filesystem>
#include <memory>
#include <optional>
#include <system_error>

#include "flexkin/error.h"
#include "flexkin/strand_file.h"
#include "flexkin/tree_scenario.h"

namespace flexkin {
namespace {

// How each format is written for each kind: the suffix of its file and the writer. A format a
// kind has no writer for is not drawn in for it (FormatsOf).
struct Output {
  explicit Output(const DrawOptions& draw_options) : options(draw_options) {}
  const DrawOptions& options;
  // What is drawn, checked (a chain result or a robot trajectory), or the strand file's path.
  std::optional<internal::CheckedDrawing> drawing;
  const std::string* strand_path = nullptr;
  const TreeResultFile* tree = nullptr;      // a tree result, checked
  mutable std::vector<std::string> written;  // the paths, in order

  void Write(const std::string& path, const std::function<void()>& write) const {
    if (options.writing) options.writing(path);
    write();
    written.push_back(path);
  }
};

std::string Extension(OutputFormat format) { return std::string(".") + NameOf(format); }

void Figure(const Output& o, OutputFormat format) {
  const std::string path = o.options.base + Extension(format);
  o.Write(path, [&] { internal::WriteSnapshotFigure(*o.drawing, o.options.figure, path); });
}

void Plots(const Output& o) {
  const bool have_angles = o.drawing->result.result.frames.front().link_angles.size() > 0;
  for (const auto& [kind, name, summary] : Vocabulary<PlotKind>::kEntries) {
    if (kind == PlotKind::kLinkAngles && !have_angles) {
      if (o.options.note) o.options.note("no link_angles plot: the leading end never moves");
      continue;
    }
    if (kind == PlotKind::kEnergy && !o.drawing->result.result.dynamics.enabled) continue;
    if (kind == PlotKind::kTargetMiss || kind == PlotKind::kJointAngles) continue;  // trees
    for (const char* extension : {".svg", ".png"}) {
      const std::string path = o.options.base + "_" + name + extension;
      o.Write(path, [&] { internal::WritePlot(*o.drawing, kind, o.options.plot, path); });
    }
  }
}

void Animation(const Output& o, OutputFormat format) {
  const std::string path = o.options.base + Extension(format);
  o.Write(path, [&] { internal::WriteAnimation(*o.drawing, o.options.animation, path); });
}

ViewerOptions ViewerWithTitle(const DrawOptions& options) {
  ViewerOptions viewer = options.viewer;
  if (viewer.title.empty()) viewer.title = options.figure.title;
  return viewer;
}

void Viewer(const Output& o) {
  const std::string path = o.options.base + ".html";
  o.Write(path, [&] { internal::WriteViewerHtml(*o.drawing, ViewerWithTitle(o.options), path); });
}

void Gltf(const Output& o, OutputFormat format) {
  const std::string path = o.options.base + Extension(format);
  o.Write(path, [&] { internal::WriteGltf(*o.drawing, o.options.gltf, path); });
}

// A strand file's outputs: each writer reads the whole file, with a reader of its own (a strand
// file is streamed, not held).
void StrandOutput(const Output& o, OutputFormat format) {
  const std::string path = o.options.base + Extension(format);
  o.Write(path, [&] {
    StrandFileReader reader(*o.strand_path);
    switch (format) {
      case OutputFormat::kMp4:
      case OutputFormat::kGif:
        internal::RenderStrandsAnimation(&reader, o.options.strands, path);
        return;
      case OutputFormat::kHtml:
        internal::WriteStrandsViewerHtml(&reader, o.options.strands_viewer, path);
        return;
      default:
        internal::RenderStrandsSnapshot(&reader, o.options.strands, path);
        return;
    }
  });
}

// A tree result's outputs, by the internal:: writers (flexkin/render.h, viewer.h, gltf.h): the tree
// was checked once, by Draw or by the reader, and the options by ValidateDrawOptions.
void TreeOutput(const Output& o, OutputFormat format) {
  const std::string path = o.options.base + Extension(format);
  o.Write(path, [&] {
    switch (format) {
      case OutputFormat::kMp4:
      case OutputFormat::kGif:
        internal::WriteTreeAnimation(*o.tree, o.options.animation, path);
        return;
      case OutputFormat::kGltf:
      case OutputFormat::kGlb:
        internal::WriteTreeGltf(*o.tree, o.options.gltf, path);
        return;
      case OutputFormat::kHtml:
        internal::WriteTreeViewerHtml(*o.tree, ViewerWithTitle(o.options), path);
        return;
      default:
        internal::WriteTreeFigure(*o.tree, o.options.figure, path);
        return;
    }
  });
}

// A tree result's plots: those it has the data for (TreePlotKinds), each as svg and png.
void TreePlots(const Output& o, OutputFormat) {
  for (const PlotKind kind : TreePlotKinds(*o.tree)) {
    for (const char* extension : {".svg", ".png"}) {
      const std::string path = o.options.base + "_" + PlotKindName(kind) + extension;
      o.Write(path, [&] { internal::WriteTreePlot(*o.tree, kind, o.options.plot, path); });
    }
  }
}

// The one table: for each format, its writer for each kind (null: not drawn in for that kind).
// Add a format with one line here and one in the vocabulary (flexkin/render.h).
struct FormatWriters {
  OutputFormat format;
  void (*chain)(const Output&, OutputFormat);
  void (*trajectory)(const Output&, OutputFormat);
  void (*strands)(const Output&, OutputFormat);
  void (*tree)(const Output&, OutputFormat);
};
void PlotsOf(const Output& o, OutputFormat) { Plots(o); }
void ViewerOf(const Output& o, OutputFormat) { Viewer(o); }
constexpr FormatWriters kWriters[] = {
    {OutputFormat::kSvg, Figure, Figure, StrandOutput, TreeOutput},
    {OutputFormat::kPng, Figure, Figure, StrandOutput, TreeOutput},
    {OutputFormat::kPdf, Figure, Figure, StrandOutput, TreeOutput},
    {OutputFormat::kPlots, PlotsOf, nullptr, nullptr, TreePlots},
    {OutputFormat::kMp4, Animation, Animation, StrandOutput, TreeOutput},
    {OutputFormat::kGif, Animation, Animation, StrandOutput, TreeOutput},
    {OutputFormat::kHtml, ViewerOf, ViewerOf, StrandOutput, TreeOutput},
    {OutputFormat::kGltf, Gltf, nullptr, nullptr, TreeOutput},
    {OutputFormat::kGlb, Gltf, nullptr, nullptr, TreeOutput},
};
static_assert(std::size(kWriters) == std::size(Vocabulary<OutputFormat>::kEntries),
              "every output format has a row of writers");

using Writer = void (*)(const Output&, OutputFormat);
Writer WriterOf(DrawnKind kind, OutputFormat format) {
  for (const FormatWriters& w : kWriters) {
    if (w.format != format) continue;
    switch (kind) {
      case DrawnKind::kChainResult:
        return w.chain;
      case DrawnKind::kRobotTrajectory:
        return w.trajectory;
      case DrawnKind::kStrandFile:
        return w.strands;
      case DrawnKind::kTreeResult:
        return w.tree;
    }
  }
  return nullptr;
}

constexpr DrawnKind kDrawnKinds[] = {DrawnKind::kChainResult, DrawnKind::kRobotTrajectory,
                                     DrawnKind::kStrandFile, DrawnKind::kTreeResult};

const char* KindName(DrawnKind kind) {
  switch (kind) {
    case DrawnKind::kChainResult:
      return "chain results";
    case DrawnKind::kRobotTrajectory:
      return "robot trajectories";
    case DrawnKind::kStrandFile:
      return "strand files";
    case DrawnKind::kTreeResult:
      return "tree results";
  }
  return "";
}

// "chain results only", "chain results and tree results": the kinds drawn in `format`.
std::string KindsDrawnIn(OutputFormat format) {
  std::vector<std::string> kinds;
  for (const DrawnKind kind : kDrawnKinds) {
    if (WriterOf(kind, format) != nullptr) kinds.push_back(KindName(kind));
  }
  if (kinds.size() == 1) return kinds[0] + " only";
  std::string out;
  for (size_t k = 0; k < kinds.size(); ++k) {
    out += (k == 0 ? "" : k + 1 == kinds.size() ? " and " : ", ") + kinds[k];
  }
  return out;
}

void Prefixed(const Problems& problems, const std::string& prefix, Problems* out) {
  for (Problem p : problems) {
    p.field = prefix + p.field;
    out->push_back(std::move(p));
  }
}

// The viewer's trails name points of the drawing: at most its last point (n for a chain, the
// base for a trajectory, point 0 its end effector; a tree's last point).
void CheckTrailPoints(const Output& o) {
  const std::vector<int>& trails = o.options.viewer.trail_points;
  if (!o.drawing && o.tree == nullptr) return;
  const Eigen::Index last = o.drawing ? o.drawing->result.result.lengths.size()
                                      : static_cast<Eigen::Index>(o.tree->parents.size()) - 1;
  for (size_t i = 0; i < trails.size(); ++i) {
    if (trails[i] > last) {
      throw InputError(
          Problem("viewer.trail_points[" + std::to_string(i) + "]",
                  "is not a point of the result; expected a point index <= " + std::to_string(last),
                  std::to_string(trails[i]), "<= " + std::to_string(last)));
    }
  }
}

// A trajectory as the chain result the writers draw, made and checked once for every output.
ResultFile TrajectoryAsCheckedResult(const RobotTrajectoryFile& trajectory) {
  ResultFile result = RobotTrajectoryAsResult(trajectory);
  ThrowIfAny(ValidateResult(result.result, result.dim));
  return result;
}

// Draws what was checked, with options checked for `kind`: the writers check nothing again.
std::vector<std::string> DrawChecked(DrawnKind kind, const Output& o) {
  CheckTrailPoints(o);
  const std::filesystem::path dir = std::filesystem::path(o.options.base).parent_path();
  if (!dir.empty()) {
    std::error_code error;
    std::filesystem::create_directories(dir, error);
    if (error) {
      throw std::system_error(error, "cannot create the output directory '" + dir.string() + "'");
    }
  }
  const std::vector<OutputFormat> formats =
      o.options.formats.empty() ? DefaultFormats(kind) : o.options.formats;
  for (OutputFormat format : formats) WriterOf(kind, format)(o, format);
  return o.written;
}

}  // namespace

void ApplyShorthands(const DrawShorthands& s, DrawOptions* o) {
  if (s.every) o->figure.every_k = o->strands.every_k = *s.every;
  if (s.title) {
    o->figure.title = o->animation.title = o->strands.title = o->strands_viewer.title = *s.title;
  }
  if (s.width) o->figure.width = o->plot.width = o->animation.width = o->strands.width = *s.width;
  if (s.height) {
    o->figure.height = o->animation.height = o->strands.height = *s.height;
    if (*s.height != 0) o->plot.height = *s.height;
  }
  if (s.azimuth) {
    o->figure.azimuth = o->animation.azimuth = o->strands.azimuth = o->strands_viewer.azimuth =
        *s.azimuth;
  }
  if (s.elevation) {
    o->figure.elevation = o->animation.elevation = o->strands.elevation =
        o->strands_viewer.elevation = *s.elevation;
  }
  if (s.fps) o->animation.fps = o->strands.fps = *s.fps;
  if (s.max_frames) {
    o->animation.max_frames = o->strands.max_frames = o->strands_viewer.max_frames = *s.max_frames;
  }
  if (s.max_strands) o->strands.max_strands = o->strands_viewer.max_strands = *s.max_strands;
  if (s.ffmpeg) o->animation.ffmpeg = o->strands.ffmpeg = *s.ffmpeg;
}

std::vector<OutputFormat> FormatsOf(DrawnKind kind) {
  std::vector<OutputFormat> formats;
  for (const FormatWriters& w : kWriters) {
    if (WriterOf(kind, w.format) != nullptr) formats.push_back(w.format);
  }
  return formats;
}

std::string FormatNamesOf(DrawnKind kind) {
  std::string names;
  for (OutputFormat f : FormatsOf(kind))
    names += (names.empty() ? "" : ", ") + std::string(NameOf(f));
  return names;
}

Problems ValidateDrawOptions(DrawnKind kind, const DrawOptions& options) {
  Problems problems;
  for (OutputFormat format : options.formats) {
    if (WriterOf(kind, format) != nullptr) continue;
    const std::string valid = FormatNamesOf(kind);
    const std::string name = NameOf(format);
    problems.push_back(Problem("formats",
                               "format \"" + name + "\" is not available for " + KindName(kind) +
                                   " (it draws " + KindsDrawnIn(format) +
                                   "); expected formats among " + valid,
                               "\"" + name + "\"", valid));
  }
  if (kind == DrawnKind::kStrandFile) {
    Prefixed(options.strands.Validate(), "strands.", &problems);
    Prefixed(options.strands_viewer.Validate(), "strands_viewer.", &problems);
  } else if (kind == DrawnKind::kTreeResult) {
    Prefixed(options.figure.Validate(), "figure.", &problems);
    Prefixed(options.plot.Validate(), "plot.", &problems);
    Prefixed(options.animation.Validate(), "animation.", &problems);
    Prefixed(options.viewer.Validate(), "viewer.", &problems);
    Prefixed(options.gltf.Validate(), "gltf.", &problems);
  } else {
    Prefixed(options.figure.Validate(), "figure.", &problems);
    Prefixed(options.animation.Validate(), "animation.", &problems);
    Prefixed(options.viewer.Validate(), "viewer.", &problems);
    if (kind == DrawnKind::kChainResult) {
      Prefixed(options.plot.Validate(), "plot.", &problems);
      Prefixed(options.gltf.Validate(), "gltf.", &problems);
    }
  }
  return problems;
}

std::vector<OutputFormat> DefaultFormats(DrawnKind kind) {
  if (kind == DrawnKind::kChainResult) {
    return {OutputFormat::kSvg, OutputFormat::kPng, OutputFormat::kPlots};
  }
  return {OutputFormat::kSvg, OutputFormat::kPng};
}

std::vector<OutputFormat> ParseOutputFormats(const std::vector<std::string>& names,
                                             const std::string& field) {
  std::vector<bool> chosen(std::size(Vocabulary<OutputFormat>::kEntries), false);
  for (const std::string& name : names) {
    const NamedValue<OutputFormat>* entry = FindName<OutputFormat>(name);
    if (entry == nullptr) {
      std::string valid;
      for (const std::string& n : NamesOf<OutputFormat>()) valid += (valid.empty() ? "" : ", ") + n;
      throw InputError(Problem(
          field, "unknown format \"" + name + "\"; expected a comma-separated list of " + valid,
          "\"" + name + "\"", valid));
    }
    chosen[static_cast<size_t>(entry - Vocabulary<OutputFormat>::kEntries)] = true;
  }
  std::vector<OutputFormat> formats;
  for (size_t i = 0; i < chosen.size(); ++i) {
    if (chosen[i]) formats.push_back(Vocabulary<OutputFormat>::kEntries[i].value);
  }
  if (formats.empty()) throw InputError(field, "is empty; expected at least one format name");
  return formats;
}

std::vector<OutputFormat> ParseOutputFormats(const std::string& list, const std::string& field) {
  std::vector<std::string> names;
  size_t start = 0;
  while (start <= list.size()) {
    size_t end = list.find(',', start);
    if (end == std::string::npos) end = list.size();
    names.push_back(list.substr(start, end - start));
    start = end + 1;
  }
  return ParseOutputFormats(names, field);
}

std::vector<std::string> Draw(const ResultFile& result, const DrawOptions& options) {
  ThrowIfAny(ValidateDrawOptions(DrawnKind::kChainResult, options));
  if (result.result.frames.empty()) throw InputError("frames", "no frames; nothing to draw");
  ThrowIfAny(ValidateResult(result));
  Output o(options);
  o.drawing.emplace(internal::CheckedDrawing{result});
  return DrawChecked(DrawnKind::kChainResult, o);
}

std::vector<std::string> Draw(const RobotTrajectoryFile& trajectory, const DrawOptions& options) {
  ThrowIfAny(ValidateDrawOptions(DrawnKind::kRobotTrajectory, options));
  const ResultFile result = TrajectoryAsCheckedResult(trajectory);
  Output o(options);
  o.drawing.emplace(internal::CheckedDrawing{result, &trajectory});
  return DrawChecked(DrawnKind::kRobotTrajectory, o);
}

std::vector<std::string> Draw(const TreeResultFile& tree, const DrawOptions& options) {
  ThrowIfAny(ValidateDrawOptions(DrawnKind::kTreeResult, options));
  ThrowIfAny(ValidateTreeResult(tree));
  Output o(options);
  o.tree = &tree;
  return DrawChecked(DrawnKind::kTreeResult, o);
}

std::vector<std::string> DrawStrandFile(const std::string& path, const DrawOptions& options) {
  ThrowIfAny(ValidateDrawOptions(DrawnKind::kStrandFile, options));
  StrandFileReader check(path);  // the file's own problems before any output
  Output o(options);
  o.strand_path = &path;
  return DrawChecked(DrawnKind::kStrandFile, o);
}

bool IsDrawOptionsProblem(const Problem& problem) {
  const std::string& field = problem.field;
  if (field == "formats") return true;
  for (const char* prefix : {"figure.", "plot.", "animation.", "viewer.", "gltf.", "strands.",
                             "strands_viewer.", "options."}) {
    if (field.rfind(prefix, 0) == 0) return true;
  }
  return false;
}

DrawnKind KindOfDrawnFile(const std::string& path) {
  if (IsStrandFile(path)) return DrawnKind::kStrandFile;
  if (IsTreeResultFile(path)) return DrawnKind::kTreeResult;
  if (IsRobotTrajectoryFile(path)) return DrawnKind::kRobotTrajectory;
  return DrawnKind::kChainResult;
}

std::vector<std::string> DrawFile(const std::string& path, const DrawOptions& options) {
  const DrawnKind kind = KindOfDrawnFile(path);
  ThrowIfAny(ValidateDrawOptions(kind, options));  // the options' problems first, once
  Output o(options);
  ResultFile result;
  RobotTrajectoryFile trajectory;
  TreeResultFile tree;
  try {
    // The file read once; its problems, found reading or drawing, are named by the file
    // ("r.json: /frames/3/points/2/1"), except an option found wrong only against the file
    // ("options.max_frames": the viewer page's size; "viewer.trail_points[0]"), which stays the
    // options' (IsDrawOptionsProblem).
    switch (kind) {
      case DrawnKind::kStrandFile: {
        StrandFileReader check(path);
        o.strand_path = &path;
        break;
      }
      case DrawnKind::kRobotTrajectory:
        trajectory = ReadRobotTrajectoryFile(path);
        result = TrajectoryAsCheckedResult(trajectory);
        o.drawing.emplace(internal::CheckedDrawing{result, &trajectory});
        break;
      case DrawnKind::kTreeResult:
        tree = ReadTreeResultFile(path);  // .npz or JSON, checked by the reader
        o.tree = &tree;
        break;
      case DrawnKind::kChainResult:
        result = ReadResultFile(path);  // JSON or .npz, by content; checked by the reader
        if (result.result.frames.empty()) throw InputError("/frames", "no frames; nothing to draw");
        o.drawing.emplace(internal::CheckedDrawing{result});
        break;
    }
    return DrawChecked(kind, o);
  } catch (const InputError& e) {
    if (IsDrawOptionsProblem(e.problem())) throw;
    Problem p = e.problem();
    p.field = path + (p.field.empty() ? "" : ": " + p.field);
    throw InputError(p);
  }
}

std::string OutputBaseOf(const std::string& path, const std::string& output_dir) {
  std::string stem = std::filesystem::path(path).filename().string();
  for (const std::string extension : {".json", ".npz"}) {
    if (stem.size() > extension.size() &&
        stem.compare(stem.size() - extension.size(), extension.size(), extension) == 0) {
      stem.resize(stem.size() - extension.size());
    }
  }
  std::string dir = output_dir;
  if (dir.empty()) {
    dir = std::filesystem::path(path).parent_path().string();
    if (dir.empty()) dir = ".";
  }
  return dir + "/" + stem;
}

}  // namespace flexkin
