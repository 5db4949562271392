// flexkin render: one result file (or robot trajectory, or strand file) in, the chosen formats
// out, each file written whole or not at all. A shell over the library's one call
// (flexkin/draw.h: DrawFile), which tells the file's kind and holds the table of formats; this
// file only maps the flags to its options and its errors to the flags.
#include "render_command.h"

#include <iostream>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "flexkin/draw.h"
#include "flexkin/error.h"
#include "interrupt.h"

namespace flexkin::cli {
namespace {

// A problem of the options, named by the command-line option that set the member
// ("figure.every_k" -> "--every", "strands.max_frames" -> "--max-frames", "formats" ->
// "--formats", "options.max_frames" from a writer -> "--max-frames").
[[noreturn]] void ThrowForFlag(Problem p) {
  const size_t dot = p.field.find('.');
  std::string flag = dot == std::string::npos ? p.field : p.field.substr(dot + 1);
  if (flag == "every_k") flag = "every";
  for (char& c : flag) c = c == '_' ? '-' : c;
  p.field = "--" + flag;
  throw InputError(p);
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
  formats_help += "\n  (robot trajectories: " + FormatNamesOf(DrawnKind::kRobotTrajectory) +
                  "; strand files: " + FormatNamesOf(DrawnKind::kStrandFile) +
                  "; tree results: " + FormatNamesOf(DrawnKind::kTreeResult) + "; default svg,png)";
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
  DrawOptions options;
  if (*formats_) options.formats = ParseOutputFormats(args_.formats, "--formats");
  DrawShorthands flags;
  flags.every = args_.every;
  flags.title = args_.title;
  flags.max_strands = args_.max_strands;
  if (*width_) flags.width = args_.width;
  if (*height_) flags.height = args_.height;
  if (*azimuth_) flags.azimuth = args_.azimuth;
  if (*elevation_) flags.elevation = args_.elevation;
  if (*fps_) flags.fps = args_.fps;
  if (*max_frames_) flags.max_frames = args_.max_frames;
  ApplyShorthands(flags, &options);
  options.animation.progress =
      options.strands.progress = [](int64_t, int64_t) { ThrowIfInterrupted(); };
  options.base = OutputBaseOf(args_.result, args_.output_dir);
  options.writing = Writing;
  options.note = [](const std::string& note) { std::cerr << "flexkin: note: " << note << "\n"; };
  std::vector<std::string> written;
  try {
    written = DrawFile(args_.result, options);
  } catch (const InputError& e) {
    // DrawFile checks the options first, once; a problem of the file is named by the file.
    if (!IsDrawOptionsProblem(e.problem())) throw;
    ThrowForFlag(e.problem());
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
