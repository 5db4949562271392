// flexkin.render: the pictures, viewer page and glTF files of a Result, as `flexkin render`
// writes them (apps/render_command.cc): one writer per format of the vocabulary of
// src/render/render.h, each file written whole or not at all, with the GIL released.
#include "render/render.h"

#include <pybind11/stl.h>

#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "convert.h"
#include "flexkin/vocabulary.h"
#include "gltf/gltf.h"
#include "viewer/viewer.h"

namespace flexkin::python {
namespace {

struct RenderJob {
  const ResultFile* file = nullptr;
  std::string base;  // out_dir/<stem>
  FigureOptions figure;
  PlotOptions plot;
  AnimationOptions animation;
  std::vector<std::string> written;
};

void WriteFormat(OutputFormat format, RenderJob* job) {
  const std::string& base = job->base;
  auto add = [job](const std::string& path) { job->written.push_back(path); };
  switch (format) {
    case OutputFormat::kSvg:
    case OutputFormat::kPng:
    case OutputFormat::kPdf: {
      const std::string path = base + "." + NameOf(format);
      WriteSnapshotFigure(*job->file, job->figure, path);
      add(path);
      return;
    }
    case OutputFormat::kPlots: {
      const bool have_angles = job->file->result.frames.front().link_angles.size() > 0;
      for (const auto& entry : Vocabulary<PlotKind>::kEntries) {
        if (entry.value == PlotKind::kLinkAngles && !have_angles) continue;
        for (const char* extension : {".svg", ".png"}) {
          const std::string path = base + "_" + entry.name + extension;
          WritePlot(*job->file, entry.value, job->plot, path);
          add(path);
        }
      }
      return;
    }
    case OutputFormat::kMp4:
    case OutputFormat::kGif: {
      const std::string path = base + "." + NameOf(format);
      WriteAnimation(*job->file, job->animation, path);
      add(path);
      return;
    }
    case OutputFormat::kHtml: {
      const std::string path = base + ".html";
      ViewerOptions options;
      options.title = job->figure.title;
      WriteViewerHtml(*job->file, options, path);
      add(path);
      return;
    }
    case OutputFormat::kGltf:
    case OutputFormat::kGlb: {
      const std::string path = base + "." + NameOf(format);
      WriteGltf(*job->file, GltfOptions{}, path);
      add(path);
      return;
    }
  }
}

// The formats, from a list of names or one comma-separated string, in the vocabulary's order,
// each once.
std::vector<OutputFormat> FormatsArg(py::handle formats) {
  std::vector<std::string> names;
  if (py::isinstance<py::str>(formats)) {
    const std::string list = py::cast<std::string>(formats);
    size_t start = 0;
    while (start <= list.size()) {
      size_t end = list.find(',', start);
      if (end == std::string::npos) end = list.size();
      names.push_back(list.substr(start, end - start));
      start = end + 1;
    }
  } else {
    for (py::handle item : formats) {
      if (!py::isinstance<py::str>(item)) ThrowInput("formats", "expected a list of format names");
      names.push_back(py::cast<std::string>(item));
    }
  }
  std::vector<bool> chosen(std::size(Vocabulary<OutputFormat>::kEntries), false);
  for (const std::string& name : names) {
    const NamedValue<OutputFormat>* entry = FindName<OutputFormat>(name);
    if (entry == nullptr) {
      std::string valid;
      for (const std::string& n : NamesOf<OutputFormat>()) valid += (valid.empty() ? "" : ", ") + n;
      ThrowInput("formats", "unknown format \"" + name + "\"; expected a list of " + valid,
                 "\"" + name + "\"", valid);
    }
    chosen[static_cast<size_t>(entry - Vocabulary<OutputFormat>::kEntries)] = true;
  }
  std::vector<OutputFormat> out;
  for (size_t i = 0; i < chosen.size(); ++i) {
    if (chosen[i]) out.push_back(Vocabulary<OutputFormat>::kEntries[i].value);
  }
  return out;
}

void CheckOptions(const Problems& problems) {
  if (problems.empty()) return;
  Problem p = problems.front();
  if (p.field == "every_k") p.field = "every";
  throw InputError(p);
}

std::vector<std::string> Render(py::handle result, py::handle out_dir, py::handle formats,
                                const std::string& stem, int every, py::object width,
                                py::object height, py::object azimuth, py::object elevation,
                                py::object fps, py::object max_frames, const std::string& title,
                                const std::string& ffmpeg) {
  const std::vector<OutputFormat> chosen = FormatsArg(formats);
  const std::string dir = PathArg(out_dir);
  if (dir.empty()) ThrowInput("out_dir", "is not a path; expected a str or os.PathLike");
  if (stem.empty() || stem.find('/') != std::string::npos) {
    ThrowInput("stem", "must be a file name without '/'", Quoted(stem));
  }
  RenderJob job;
  job.figure.every_k = every;
  job.figure.title = job.animation.title = title;
  if (!width.is_none())
    job.figure.width = job.plot.width = job.animation.width = py::cast<int>(width);
  if (!height.is_none()) {
    job.figure.height = job.animation.height = py::cast<int>(height);
    if (job.figure.height != 0) job.plot.height = job.figure.height;
  }
  if (!azimuth.is_none()) job.figure.azimuth = job.animation.azimuth = py::cast<double>(azimuth);
  if (!elevation.is_none()) {
    job.figure.elevation = job.animation.elevation = py::cast<double>(elevation);
  }
  if (!fps.is_none()) job.animation.fps = py::cast<int>(fps);
  if (!max_frames.is_none()) job.animation.max_frames = py::cast<int>(max_frames);
  job.animation.ffmpeg = ffmpeg;
  CheckOptions(job.figure.Validate());
  CheckOptions(job.plot.Validate());
  CheckOptions(job.animation.Validate());
  const ResultFile file = ResultFileOfObject(result);
  if (file.result.frames.empty()) ThrowInput("result.frames", "no frames; nothing to draw");
  job.file = &file;
  job.base = dir + "/" + stem;
  {
    py::gil_scoped_release release;
    std::error_code error;
    std::filesystem::create_directories(dir, error);
    if (error) throw std::system_error(error, "cannot create the output directory '" + dir + "'");
    for (OutputFormat format : chosen) WriteFormat(format, &job);
  }
  return job.written;
}

}  // namespace

void BindRender(py::module_& m) {
  std::string formats_doc;
  for (const auto& entry : Vocabulary<OutputFormat>::kEntries) {
    formats_doc += std::string("\n  ") + entry.name + ": " + entry.summary;
  }
  m.def("render", &Render, py::arg("result"), py::arg("out_dir"),
        py::arg("formats") = std::vector<std::string>{"svg", "png", "plots"}, py::kw_only(),
        py::arg("stem") = "result", py::arg("every") = 0, py::arg("width") = py::none(),
        py::arg("height") = py::none(), py::arg("azimuth") = py::none(),
        py::arg("elevation") = py::none(), py::arg("fps") = py::none(),
        py::arg("max_frames") = py::none(), py::arg("title") = "", py::arg("ffmpeg") = "ffmpeg",
        ("Draws a Result as `flexkin render` does (docs/rendering.md): the chosen formats (a "
         "list of names or a comma-separated string; default svg, png, plots) written to "
         "out_dir/<stem>.<ext>, out_dir created if missing, each file whole or not at all. "
         "Options as the command's: every (figures: every K-th frame, 0 automatic), width, "
         "height (0 = from the data), azimuth, elevation (3D view, degrees), fps, max_frames "
         "(animations), title, ffmpeg (the program for mp4 and gif). The GIL is released while "
         "drawing. Returns the paths written. Raises InputError for an unknown format (listing "
         "the valid names) or an invalid option, OSError for a file that cannot be written, "
         "RuntimeError when ffmpeg is missing or fails. Formats:" +
         formats_doc)
            .c_str());
}

}  // namespace flexkin::python
