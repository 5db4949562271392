#pragma once
// `flexkin render RESULT.json [-o OUTDIR] [--formats ...]`: figures, plots and animations of a
// result file, and the figure, animation and viewer of a robot trajectory or a strand file
// (docs/rendering.md). Kept apart from flexkin_main.cc, which only registers it.

#include <CLI/CLI.hpp>
#include <string>

namespace flexkin::cli {

class RenderCommand {
 public:
  // Adds the "render" subcommand to `app`; `footer` is the exit-code help shown under --help.
  RenderCommand(CLI::App* app, const std::string& footer);

  // Whether the command line chose this subcommand.
  bool Parsed() const { return command_->parsed(); }
  // Reads the result (or robot trajectory or strand file, told apart by content) and writes the
  // chosen formats (flexkin/draw.h).
  // Returns the exit status for failures it reports itself (ffmpeg missing or failing: 1); throws
  // InputError (bad option or result: exit 1) and std::system_error (a file: exit 4) for
  // flexkin_main to report.
  int Run() const;

  struct Args {
    std::string result, output_dir, formats, title;
    int every = 0, width = 0, height = 0, fps = 0, max_frames = 0, max_strands = 0;
    double azimuth = 0.0, elevation = 0.0;
    bool quiet = false;
  };

 private:
  CLI::App* command_ = nullptr;
  Args args_;
  // Which of the shared options were given (the defaults differ per output).
  CLI::Option *width_ = nullptr, *height_ = nullptr, *azimuth_ = nullptr, *elevation_ = nullptr,
              *fps_ = nullptr, *max_frames_ = nullptr, *formats_ = nullptr;
};

}  // namespace flexkin::cli
