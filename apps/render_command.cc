// flexkin render: one result file (or robot trajectory, or strand file) in, the chosen formats
// out, each file written whole or not at all. The formats are a table: an entry names a format and
// the function that writes its files.
#include "render_command.h"

#include <sys/stat.h>

#include <cerrno>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/result_io.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/strand_file.h"
#include "gltf/gltf.h"
#include "interrupt.h"
#include "render/strands_render.h"
#include "viewer/strands_viewer.h"
#include "viewer/viewer.h"

namespace flexkin::cli {
namespace {

// Everything a format's writer needs: a chain result, or a robot trajectory (drawn in the
// formats of kTrajectoryFormats only).
struct RenderJob {
  const ResultFile* file = nullptr;
  const RobotTrajectoryFile* trajectory = nullptr;  // instead of `file`
  std::string base;  // OUTDIR/<stem>: each writer appends its suffix and extension
  FigureOptions figure;
  PlotOptions plot;
  AnimationOptions animation;
  std::vector<std::string>* written = nullptr;  // paths written, for the report
};

void Figure(const RenderJob& job, const char* extension) {
  const std::string path = job.base + extension;
  Writing(path);
  if (job.trajectory != nullptr) {
    WriteSnapshotFigure(*job.trajectory, job.figure, path);
  } else {
    WriteSnapshotFigure(*job.file, job.figure, path);
  }
  job.written->push_back(path);
}

void Plots(const RenderJob& job) {
  const bool have_angles = job.file->result.frames.front().link_angles.size() > 0;
  for (const auto& [kind, name, summary] : Vocabulary<PlotKind>::kEntries) {
    if (kind == PlotKind::kLinkAngles && !have_angles) {
      std::cerr << "flexkin: note: no link_angles plot: the leading end never moves\n";
      continue;
    }
    for (const char* extension : {".svg", ".png"}) {
      const std::string path = job.base + "_" + name + extension;
      Writing(path);
      WritePlot(*job.file, kind, job.plot, path);
      job.written->push_back(path);
    }
  }
}

void Animation(const RenderJob& job, const char* extension) {
  const std::string path = job.base + extension;
  Writing(path);
  if (job.trajectory != nullptr) {
    WriteAnimation(*job.trajectory, job.animation, path);
  } else {
    WriteAnimation(*job.file, job.animation, path);
  }
  job.written->push_back(path);
}

// The interactive viewer: one self-contained HTML page (docs/viewer.md).
void Viewer(const RenderJob& job) {
  const std::string path = job.base + ".html";
  Writing(path);
  ViewerOptions options;
  options.title = job.figure.title;
  if (job.trajectory != nullptr) {
    WriteViewerHtml(*job.trajectory, options, path);
  } else {
    WriteViewerHtml(*job.file, options, path);
  }
  job.written->push_back(path);
}

// glTF 2.0: the chain as a skinned skeleton with keyframed joints (docs/gltf-export.md).
void Gltf(const RenderJob& job, const char* extension) {
  const std::string path = job.base + extension;
  Writing(path);
  WriteGltf(*job.file, GltfOptions{}, path);
  job.written->push_back(path);
}

// The writer of each output format (src/render/render.h names them), in the order they are written.
// Add a format with one line here and one in the vocabulary.
struct FormatWriter {
  OutputFormat format;
  void (*write)(const RenderJob& job);
};
const FormatWriter kWriters[] = {
    {OutputFormat::kSvg, [](const RenderJob& j) { Figure(j, ".svg"); }},
    {OutputFormat::kPng, [](const RenderJob& j) { Figure(j, ".png"); }},
    {OutputFormat::kPdf, [](const RenderJob& j) { Figure(j, ".pdf"); }},
    {OutputFormat::kPlots, Plots},
    {OutputFormat::kMp4, [](const RenderJob& j) { Animation(j, ".mp4"); }},
    {OutputFormat::kGif, [](const RenderJob& j) { Animation(j, ".gif"); }},
    {OutputFormat::kHtml, Viewer},
    {OutputFormat::kGltf, [](const RenderJob& j) { Gltf(j, ".gltf"); }},
    {OutputFormat::kGlb, [](const RenderJob& j) { Gltf(j, ".glb"); }},
};
static_assert(std::size(kWriters) == std::size(Vocabulary<OutputFormat>::kEntries),
              "every output format has a writer");

// "svg,png,plots" -> the writers, in table order, each once.
std::vector<const FormatWriter*> ParseFormats(const std::string& list) {
  std::vector<bool> chosen(std::size(kWriters), false);
  size_t start = 0;
  while (start <= list.size()) {
    size_t end = list.find(',', start);
    if (end == std::string::npos) end = list.size();
    const std::string name = list.substr(start, end - start);
    start = end + 1;
    const NamedValue<OutputFormat>* entry = FindName<OutputFormat>(name);
    size_t i = 0;
    while (entry != nullptr && i < std::size(kWriters) && kWriters[i].format != entry->value) ++i;
    if (entry != nullptr && i < std::size(kWriters)) {
      chosen[i] = true;
      continue;
    }
    std::string names;
    for (const std::string& n : NamesOf<OutputFormat>()) names += (names.empty() ? "" : ", ") + n;
    throw InputError("--formats", "unknown format \"" + name +
                                      "\"; expected a comma-separated list of " + names);
  }
  std::vector<const FormatWriter*> writers;
  for (size_t i = 0; i < chosen.size(); ++i) {
    if (chosen[i]) writers.push_back(&kWriters[i]);
  }
  return writers;
}

// The formats a strand file can be drawn in, in the order they are written, with their
// extensions.
enum class StrandOutput { kFigure, kAnimation, kViewer };
struct StrandFormat {
  OutputFormat format;
  const char* extension;
  StrandOutput output;
};
const StrandFormat kStrandFormats[] = {
    {OutputFormat::kSvg, ".svg", StrandOutput::kFigure},
    {OutputFormat::kPng, ".png", StrandOutput::kFigure},
    {OutputFormat::kPdf, ".pdf", StrandOutput::kFigure},
    {OutputFormat::kMp4, ".mp4", StrandOutput::kAnimation},
    {OutputFormat::kGif, ".gif", StrandOutput::kAnimation},
    {OutputFormat::kHtml, ".html", StrandOutput::kViewer},
};

// The chosen writers' formats that strand files support; InputError ("--formats") naming any
// other and what is valid.
std::vector<const StrandFormat*> StrandFormats(const std::vector<const FormatWriter*>& writers) {
  std::string valid;
  for (const StrandFormat& f : kStrandFormats)
    valid += (valid.empty() ? "" : ", ") + std::string(NameOf(f.format));
  std::vector<const StrandFormat*> formats;
  for (const FormatWriter* writer : writers) {
    const StrandFormat* found = nullptr;
    for (const StrandFormat& f : kStrandFormats) {
      if (f.format == writer->format) found = &f;
    }
    if (found == nullptr) {
      throw InputError("--formats", "format \"" + std::string(NameOf(writer->format)) +
                                        "\" is not available for strand files (it draws chain "
                                        "results only); expected a comma-separated list of " +
                                        valid);
    }
    formats.push_back(found);
  }
  return formats;
}

// The first problem of render options, named by the command-line option that set the member
// ("every_k" -> "--every", "max_frames" -> "--max-frames").
void CheckOptions(const Problems& problems) {
  if (problems.empty()) return;
  Problem p = problems.front();
  std::string flag = p.field == "every_k" ? "every" : p.field;
  for (char& c : flag) c = c == '_' ? '-' : c;
  p.field = "--" + flag;
  throw InputError(p);
}

// A problem found while writing the outputs: an option found wrong only against the file (the
// viewer page's size against "options.max_frames") is named by its command-line option, the rest
// by the file ("RESULT: frames[3].points[2][1]").
[[noreturn]] void ThrowForFile(const InputError& e, const std::string& result) {
  if (e.field().rfind("options.", 0) == 0) {
    Problem p = e.problem();
    p.field = p.field.substr(8);
    CheckOptions({p});
  }
  throw InputError(result + (e.field().empty() ? "" : ": " + e.field()),
                   std::string(e.what()).substr(e.field().empty() ? 0 : e.field().size() + 2));
}

// OUTDIR/<stem>: <stem> is the result file's name without ".json".
std::string OutputBase(const std::string& result, const std::string& output_dir) {
  std::string stem = std::filesystem::path(result).filename().string();
  for (const std::string extension : {".json", ".npz"}) {
    if (stem.size() > extension.size() &&
        stem.compare(stem.size() - extension.size(), extension.size(), extension) == 0) {
      stem.resize(stem.size() - extension.size());
    }
  }
  std::string dir = output_dir;
  if (dir.empty()) {
    dir = std::filesystem::path(result).parent_path().string();
    if (dir.empty()) dir = ".";
  }
  return dir + "/" + stem;
}

}  // namespace

RenderCommand::RenderCommand(CLI::App* app, const std::string& footer) {
  command_ = app->add_subcommand(
      "render", "Draw a result file or robot trajectory: figures, plots, animations.");
  command_
      ->add_option("result", args_.result,
                   "Result file (.json or .npz, docs/result-format.md), robot trajectory "
                   "(flexkin robot -o, docs/robot-format.md) or strand file (.npz)")
      ->required();
  command_->add_option("-o,--output-dir", args_.output_dir,
                       "Directory for the outputs, created if missing (default: the result's)");
  std::string formats_help = "Comma-separated outputs (default svg,png,plots):";
  for (const auto& entry : Vocabulary<OutputFormat>::kEntries)
    formats_help += std::string("\n  ") + entry.name + ": " + entry.summary;
  formats_help +=
      "\n  (robot trajectories and strand files: svg, png, pdf, mp4, gif, html; "
      "default svg,png)";
  formats_ = command_->add_option("--formats", args_.formats, formats_help);
  command_->add_option("--every", args_.every,
                       "Figures: draw every K-th recorded frame (default: about 16 frames)");
  width_ = command_->add_option(
      "--width", args_.width, "Width in pixels (default: figures 960, plots 800, animations 640)");
  height_ = command_->add_option("--height", args_.height,
                                 "Height in pixels; 0 = from the data's aspect ratio (default: "
                                 "figures and animations 0, plots 500)");
  azimuth_ = command_->add_option("--azimuth", args_.azimuth,
                                  "3D view: degrees about z from +x (default -60)");
  elevation_ = command_->add_option("--elevation", args_.elevation,
                                    "3D view: degrees above the x-y plane (default 30)");
  fps_ = command_->add_option("--fps", args_.fps, "Animations: frames per second (default 30)");
  max_frames_ = command_->add_option(
      "--max-frames", args_.max_frames,
      "Animations: at most N pictures; longer runs are subsampled (default 300)");
  command_->add_option("--max-strands", args_.max_strands,
                       "Strand files: draw at most N strands, spread evenly (default 0: all)");
  command_->add_option("--title", args_.title,
                       "Title of figures and animations (default: the scenario's name)");
  command_->add_flag("-q,--quiet", args_.quiet, "Do not list the files written");
  command_->footer(footer);
}

int RenderCommand::Run() const {
  if (IsStrandFile(args_.result)) return RunStrands();
  // A robot trajectory is drawn as a chain whose end effector leads and whose base is fixed
  // (RobotTrajectoryAsResult): the figure, animation and viewer, by default the figure.
  const bool trajectory = IsRobotTrajectoryFile(args_.result);
  const std::vector<const FormatWriter*> formats =
      ParseFormats(trajectory && !*formats_ ? "svg,png" : args_.formats);
  if (trajectory) {
    for (const FormatWriter* format : formats) CheckTrajectoryFormat(format->format, "--formats");
  }
  RenderJob job;
  job.figure.every_k = args_.every;
  job.figure.title = job.animation.title = args_.title;
  if (*width_) job.figure.width = job.plot.width = job.animation.width = args_.width;
  if (*height_) job.figure.height = job.animation.height = args_.height;
  if (*height_ && args_.height != 0) job.plot.height = args_.height;
  if (*azimuth_) job.figure.azimuth = job.animation.azimuth = args_.azimuth;
  if (*elevation_) job.figure.elevation = job.animation.elevation = args_.elevation;
  if (*fps_) job.animation.fps = args_.fps;
  if (*max_frames_) job.animation.max_frames = args_.max_frames;
  job.animation.progress = [](int64_t, int64_t) { ThrowIfInterrupted(); };
  CheckOptions(job.figure.Validate());
  CheckOptions(job.plot.Validate());
  CheckOptions(job.animation.Validate());

  ResultFile file;
  RobotTrajectoryFile robot;
  try {
    if (trajectory) {
      robot = ReadRobotTrajectoryFile(args_.result);
    } else {
      file = ReadResultFile(args_.result);  // JSON or .npz, by content
    }
  } catch (const InputError& e) {
    throw InputError(args_.result + (e.field().empty() ? "" : ": " + e.field()),
                     std::string(e.what()).substr(e.field().empty() ? 0 : e.field().size() + 2));
  }
  if (!trajectory && file.result.frames.empty())
    throw InputError(args_.result + ": /frames", "no frames; nothing to draw");

  job.file = &file;
  if (trajectory) job.trajectory = &robot;
  job.base = OutputBase(args_.result, args_.output_dir);
  const std::string dir = job.base.substr(0, job.base.rfind('/'));
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw std::system_error(error, "cannot create the output directory '" + dir + "'");
  std::vector<std::string> written;
  job.written = &written;
  try {
    for (const FormatWriter* format : formats) format->write(job);
  } catch (const InputError& e) {
    ThrowForFile(e, args_.result);
  } catch (const std::system_error&) {
    throw;
  } catch (const std::runtime_error& e) {  // ffmpeg missing or failing, cairo
    ThrowIfInterrupted();                  // an ffmpeg stopped by the same Ctrl-C
    std::cerr << "flexkin: error: " << e.what() << "\n";
    return 1;
  }
  if (!args_.quiet) {
    for (const std::string& path : written) std::cout << "wrote " << path << "\n";
  }
  return 0;
}

// A strand file: the figure (svg, png, pdf) and the animation (mp4, gif) of its strands; the
// default formats are the figure's, svg and png.
int RenderCommand::RunStrands() const {
  const std::vector<const FormatWriter*> writers =
      ParseFormats(*formats_ ? args_.formats : "svg,png");
  const std::vector<const StrandFormat*> formats = StrandFormats(writers);
  StrandsRenderOptions options;
  options.title = args_.title;
  options.every_k = args_.every;
  options.max_strands = args_.max_strands;
  if (*width_) options.width = args_.width;
  if (*height_) options.height = args_.height;
  if (*azimuth_) options.azimuth = args_.azimuth;
  if (*elevation_) options.elevation = args_.elevation;
  if (*fps_) options.fps = args_.fps;
  if (*max_frames_) options.max_frames = args_.max_frames;
  options.progress = [](int64_t, int64_t) { ThrowIfInterrupted(); };
  CheckOptions(options.Validate());
  StrandsViewerOptions viewer;
  viewer.title = args_.title;
  viewer.max_strands = args_.max_strands;
  if (*azimuth_) viewer.azimuth = args_.azimuth;
  if (*elevation_) viewer.elevation = args_.elevation;
  if (*max_frames_) viewer.max_frames = args_.max_frames;
  CheckOptions(viewer.Validate());

  const std::string base = OutputBase(args_.result, args_.output_dir);
  const std::string dir = base.substr(0, base.rfind('/'));
  std::vector<std::string> written;
  try {
    // Each writer reads the whole file: a fresh reader each time.
    StrandFileReader first(args_.result);
    std::error_code error;
    std::filesystem::create_directories(dir, error);
    if (error) throw std::system_error(error, "cannot create the output directory '" + dir + "'");
    bool fresh = true;
    for (const StrandFormat* format : formats) {
      std::unique_ptr<StrandFileReader> again;
      StrandFileReader* reader = &first;
      if (!fresh) {
        again = std::make_unique<StrandFileReader>(args_.result);
        reader = again.get();
      }
      fresh = false;
      const std::string path = base + format->extension;
      Writing(path);
      switch (format->output) {
        case StrandOutput::kFigure:
          RenderStrandsSnapshot(reader, options, path);
          break;
        case StrandOutput::kAnimation:
          RenderStrandsAnimation(reader, options, path);
          break;
        case StrandOutput::kViewer:
          WriteStrandsViewerHtml(reader, viewer, path);
          break;
      }
      written.push_back(path);
    }
  } catch (const InputError& e) {
    ThrowForFile(e, args_.result);
  } catch (const std::system_error&) {
    throw;
  } catch (const std::runtime_error& e) {  // ffmpeg missing or failing, cairo
    ThrowIfInterrupted();                  // an ffmpeg stopped by the same Ctrl-C
    std::cerr << "flexkin: error: " << e.what() << "\n";
    return 1;
  }
  if (!args_.quiet) {
    for (const std::string& path : written) std::cout << "wrote " << path << "\n";
  }
  return 0;
}

}  // namespace flexkin::cli
