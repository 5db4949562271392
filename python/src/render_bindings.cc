// flexkin.render: the pictures, viewer page and glTF files of a Result, a RobotResult or a file of
// any kind flexkin writes (a result, a robot trajectory, a strand file), through the library's one
// call (flexkin/draw.h), as `flexkin render` writes them (apps/render_command.cc), with the GIL
// released. This file maps the keywords and option objects to its options; every member of the
// components' options is reachable through FigureOptions, PlotOptions, AnimationOptions,
// ViewerOptions and GltfOptions (or dicts of their fields).
#include <pybind11/stl.h>

#include <algorithm>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "convert.h"
#include "fields.h"
#include "flexkin/draw.h"
#include "flexkin/vocabulary.h"

namespace flexkin::python {

// A flexkin.RobotResult as the trajectory the pictures and the viewer take; nullopt for another
// object (robot_bindings.cc). Declared here, its one user, rather than in convert.h.
std::optional<RobotTrajectoryFile> RobotTrajectoryOfObject(py::handle object);

namespace {

// render()'s own argument types, named in help() as convert.h's are.
struct DrawableTag {
  static constexpr char kText[] = "Union[Result, RobotResult, str, os.PathLike]";
};
using Drawable = Typed<DrawableTag>;
struct OptionalFormatsTag {
  static constexpr char kText[] = "Union[str, Sequence[str], None]";
};
using OptionalFormats = Typed<OptionalFormatsTag>;

// The formats, from a list of names or one comma-separated string.
std::vector<OutputFormat> FormatsArg(py::handle formats) {
  if (py::isinstance<py::str>(formats)) {
    return ParseOutputFormats(py::cast<std::string>(formats), "formats");
  }
  std::vector<std::string> names;
  for (py::handle item : formats) {
    if (!py::isinstance<py::str>(item)) ThrowInput("formats", "expected a list of format names");
    names.push_back(py::cast<std::string>(item));
  }
  return ParseOutputFormats(names, "formats");
}

// The first problem of options, its field `prefix` and the member ("gltf.tube_sides") for an
// options object; for the keywords, the keyword that set the member ("figure.every_k" -> "every").
void CheckOptions(const Problems& problems, const std::string& prefix) {
  if (problems.empty()) return;
  Problem p = problems.front();
  p.field = prefix + p.field;
  throw InputError(p);
}

// A problem Draw found in the options, named by the keyword that set the member where a keyword
// did ("figure.every_k" -> "every", "animation.fps" -> "fps"), else as Draw names it: the option
// objects were checked on their own before the keywords were applied.
[[noreturn]] void ThrowForKeyword(Problem p) {
  const size_t dot = p.field.find('.');
  std::string member = dot == std::string::npos ? p.field : p.field.substr(dot + 1);
  if (member == "every_k") member = "every";
  for (const char* keyword : {"every", "width", "height", "azimuth", "elevation", "fps",
                              "max_frames", "max_strands", "title", "ffmpeg"}) {
    if (member == keyword) p.field = member;
  }
  throw InputError(p);
}

template <typename T>
T CheckedOptions(py::handle object, const std::string& name) {
  T options = OptionsArg<T>(object, name);
  CheckOptions(options.Validate(), name + ".");
  return options;
}

template <typename T>
std::optional<T> Optional(py::handle value) {
  if (value.is_none()) return std::nullopt;
  return py::cast<T>(value);
}

std::vector<std::string> Render(Drawable result, PathLike out_dir, OptionalFormats formats,
                                OptionalStr stem_arg, OptionalInt every, OptionalInt width,
                                OptionalInt height, OptionalFloat azimuth, OptionalFloat elevation,
                                OptionalInt fps, OptionalInt max_frames, OptionalInt max_strands,
                                OptionalStr title, OptionalStr ffmpeg, FigureLike figure,
                                PlotLike plot, AnimationLike animation, ViewerLike viewer,
                                GltfLike gltf) {
  // What is drawn: a Result, a RobotResult (as `flexkin render` draws a trajectory file) or a
  // file of any kind, told apart by its content.
  const std::optional<RobotTrajectoryFile> trajectory = RobotTrajectoryOfObject(result);
  const std::string path = trajectory ? "" : PathArg(result);
  const ResultFile* file = trajectory || !path.empty() ? nullptr : &ResultFileOfObject(result);
  DrawOptions options;
  if (!formats.is_none()) options.formats = FormatsArg(formats);
  const std::string dir = RequiredPath(out_dir, "out_dir");
  const std::string stem = stem_arg.is_none() ? "" : py::cast<std::string>(stem_arg);
  if (!stem_arg.is_none() && (stem.empty() || stem.find('/') != std::string::npos)) {
    ThrowInput("stem", "must be a file name without '/'", Quoted(stem));
  }
  // A file's outputs are named after it, as the command names them; an object's "result".
  options.base = !stem.empty()   ? dir + "/" + stem
                 : !path.empty() ? OutputBaseOf(path, dir)
                                 : dir + "/result";
  options.figure = CheckedOptions<FigureOptions>(figure, "figure");
  options.plot = CheckedOptions<PlotOptions>(plot, "plot");
  options.animation = CheckedOptions<AnimationOptions>(animation, "animation");
  options.viewer = CheckedOptions<ViewerOptions>(viewer, "viewer");
  options.gltf = CheckedOptions<GltfOptions>(gltf, "gltf");
  // The keywords of `flexkin render`, set as the command sets them.
  DrawShorthands keywords;
  keywords.every = Optional<int>(every);
  keywords.width = Optional<int>(width);
  keywords.height = Optional<int>(height);
  keywords.azimuth = Optional<double>(azimuth);
  keywords.elevation = Optional<double>(elevation);
  keywords.fps = Optional<int>(fps);
  keywords.max_frames = Optional<int>(max_frames);
  keywords.max_strands = Optional<int>(max_strands);
  keywords.title = Optional<std::string>(title);
  keywords.ffmpeg = Optional<std::string>(ffmpeg);
  ApplyShorthands(keywords, &options);
  if (file != nullptr && file->result.frames.empty()) {
    ThrowInput("result.frames", "no frames; nothing to draw");
  }
  try {
    py::gil_scoped_release release;
    if (trajectory) return Draw(*trajectory, options);
    if (file != nullptr) return Draw(*file, options);
    return DrawFile(path, options);  // names the file in its problems
  } catch (const InputError& e) {
    // Draw checks the options first, once; a problem of the result or the file stays as it is.
    if (IsDrawOptionsProblem(e.problem())) ThrowForKeyword(e.problem());
    throw;
  } catch (const std::system_error& e) {
    if (path.empty()) throw;
    RethrowWithPath(e, path);
  }
}

void BindOptionClasses(py::module_& m) {
  py::class_<FigureOptions> figure(m, "FigureOptions", R"doc(
Options of the snapshot figure (formats svg, png, pdf; docs/rendering.md).
FigureOptions(**fields): every field below by keyword, the rest at their defaults.
)doc");
  Fields<FigureOptions>(figure, "FigureOptions")
      .KeywordInit()
      .Validate("width")
      .Member("every_k", &FigureOptions::every_k,
              "Draw recorded frames 0, k, 2k, ... and the last; 0 (default) = automatic, at most "
              "16 frames.",
              true)
      .Member("width", &FigureOptions::width,
              "Pixels (SVG px, PDF points), 64 to 8192 (default 960).", true)
      .Member("height", &FigureOptions::height,
              "Pixels; 0 (default) = from the data's aspect ratio.", true)
      .Member("azimuth", &FigureOptions::azimuth, "3D view: degrees about z from +x (default -60).",
              true)
      .Member("elevation", &FigureOptions::elevation,
              "3D view: degrees above the x-y plane, -90 to 90 (default 30).", true)
      .Member("title", &FigureOptions::title,
              "The title's first line; '' (default) = the scenario's name.", true)
      .Member("show_leader_path", &FigureOptions::show_leader_path,
              "Draw the leading end's path with an arrowhead (default True).", true)
      .Member("show_legend", &FigureOptions::show_legend, "Draw the legend (default True).", true)
      .Finish();

  py::class_<PlotOptions> plot(m, "PlotOptions", R"doc(
Options of the plots (format plots: path_length, link_angles, length_error; docs/rendering.md).
PlotOptions(**fields): every field below by keyword, the rest at their defaults.
)doc");
  Fields<PlotOptions>(plot, "PlotOptions")
      .KeywordInit()
      .Validate("height")
      .Member("width", &PlotOptions::width, "Pixels, 64 to 8192 (default 800).", true)
      .Member("height", &PlotOptions::height, "Pixels, 64 to 8192 (default 500).", true)
      .Member("title", &PlotOptions::title,
              "The title; '' (default) = what is plotted and the scenario's name.", true)
      .Finish();

  py::class_<AnimationOptions> animation(m, "AnimationOptions", R"doc(
Options of the animations (formats mp4, gif; need ffmpeg; docs/rendering.md).
AnimationOptions(**fields): every field below by keyword, the rest at their defaults.
)doc");
  Fields<AnimationOptions>(animation, "AnimationOptions")
      .KeywordInit()
      .Validate("fps")
      .Member("width", &AnimationOptions::width,
              "Pixels, 64 to 8192, odd rounded up to even (default 640).", true)
      .Member("height", &AnimationOptions::height,
              "Pixels; 0 (default) = from the data's aspect ratio.", true)
      .Member("fps", &AnimationOptions::fps, "Frames per second, 1 to 120 (default 30).", true)
      .Member("every_k", &AnimationOptions::every_k,
              "Draw recorded frames 0, k, 2k, ... and the last; 0 (default) = automatic, at most "
              "max_frames.",
              true)
      .Member("max_frames", &AnimationOptions::max_frames,
              "Pictures at most when every_k is 0, >= 2 (default 300).", true)
      .Member("min_seconds", &AnimationOptions::min_seconds,
              "Short runs play at least this long (seconds, default 3; 0 = one video frame per "
              "picture).",
              true)
      .Member("end_pause", &AnimationOptions::end_pause,
              "The last picture is held this long (seconds, default 1).", true)
      .Member("azimuth", &AnimationOptions::azimuth,
              "3D view: degrees about z from +x (default -60).", true)
      .Member("elevation", &AnimationOptions::elevation,
              "3D view: degrees above the x-y plane (default 30).", true)
      .Member("title", &AnimationOptions::title,
              "The title's first line; '' (default) = the scenario's name.", true)
      .Member("ffmpeg", &AnimationOptions::ffmpeg,
              "The ffmpeg program: a name looked up in PATH or a path (default 'ffmpeg').", true)
      .Member("crf", &AnimationOptions::crf,
              "H.264 constant rate factor of mp4, 0 (lossless) to 51 (default 20).", true)
      .Finish();

  py::class_<ViewerOptions> viewer(m, "ViewerOptions", R"doc(
Options of the interactive viewer page (format html; docs/viewer.md).
ViewerOptions(**fields): every field below by keyword, the rest at their defaults.
)doc");
  Fields<ViewerOptions>(viewer, "ViewerOptions")
      .KeywordInit()
      .Validate("digits")
      .Member("title", &ViewerOptions::title,
              "Page title and heading; '' (default) = the figure's title, else the scenario's "
              "name.",
              true)
      .Member("playback_seconds", &ViewerOptions::playback_seconds,
              "Wall time of one play-through at 1x (seconds, > 0, <= 86400; default 10).", true)
      .Member("autoplay", &ViewerOptions::autoplay, "Start playing when opened (default True).",
              true)
      .Member("loop", &ViewerOptions::loop, "Start again after the last frame (default True).",
              true)
      .Member("show_leader_path", &ViewerOptions::show_leader_path,
              "Show the leading end's path at the start (default True).", true)
      .Member("trail_points", &ViewerOptions::trail_points,
              "list of int: points (0 = leading end, <= n) whose trails are shown at the start "
              "(default []).",
              true)
      .Member("azimuth", &ViewerOptions::azimuth,
              "Initial 3D view: degrees about z from +x (default -60).", true)
      .Member("elevation", &ViewerOptions::elevation,
              "Initial 3D view: degrees above the x-y plane, -90 to 90 (default 25).", true)
      .Member("perspective", &ViewerOptions::perspective,
              "Initial 3D projection perspective, else orthographic (default False).", true)
      .Member("digits", &ViewerOptions::digits,
              "Significant digits of the embedded coordinates, 6 to 17 (default 9; 17 exact).",
              true)
      .Finish();

  py::class_<GltfOptions> gltf(m, "GltfOptions", R"doc(
Options of the glTF 2.0 export (formats gltf, glb; docs/gltf-export.md).
GltfOptions(**fields): every field below by keyword, the rest at their defaults.
)doc");
  Fields<GltfOptions>(gltf, "GltfOptions")
      .KeywordInit()
      .Validate("tube_sides")
      .Member("steps_per_second", &GltfOptions::steps_per_second,
              "Playback speed: leader steps per second of animation, > 0 (default 30).", true)
      .Member("include_mesh", &GltfOptions::include_mesh,
              "Include a tube mesh skinned to the joints (default True).", true)
      .Member("tube_radius", &GltfOptions::tube_radius,
              "Radius of the tube (length unit, before scale); 0 (default) = min(0.25 mean link "
              "length, 0.02 total length).",
              true)
      .Member("tube_sides", &GltfOptions::tube_sides,
              "Vertices around the tube, 3 to 64 (default 12).", true)
      .Member("scale", &GltfOptions::scale,
              "Metres (glTF's unit) per length unit of the chain, > 0 (default 1).", true)
      .Property(
          "up_axis", [](const GltfOptions& o) { return std::string(GltfUpAxisName(o.up_axis)); },
          [](GltfOptions& o, py::handle name) {
            o.up_axis = ParseGltfUpAxis(py::cast<std::string>(name));
          },
          "Which flexkin axis points up in glTF: 'auto' (default: y for 2D, z for 3D), 'y' or "
          "'z'.",
          true)
      .Finish();
}

// The joint positions of a glTF file at its keyframes: (times (K,), positions (K, joints, dim)).
py::tuple GltfJointPositions(PathLike path_arg) {
  const std::string path = RequiredPath(path_arg, "path");
  const GltfJointMotion motion = OnFile(path, [&] { return ReadGltfJointPositions(path); });
  const int64_t count = static_cast<int64_t>(motion.positions.size());
  const int64_t joints = count > 0 ? motion.positions.front().rows() : 0;
  py::array_t<double> times(count), positions({count, joints, static_cast<int64_t>(motion.dim)});
  for (int64_t k = 0; k < count; ++k) {
    const Points& p = motion.positions[static_cast<size_t>(k)];
    if (p.rows() != joints || p.cols() != motion.dim) {
      throw std::logic_error("flexkin: glTF keyframes of different shapes");
    }
    times.mutable_data()[k] = motion.times[static_cast<size_t>(k)];
    std::copy(p.data(), p.data() + p.size(), positions.mutable_data() + k * p.size());
  }
  return py::make_tuple(times, positions);
}

}  // namespace

void BindRender(py::module_& m) {
  BindOptionClasses(m);
  m.def("gltf_joint_positions", &GltfJointPositions, py::arg("path"), R"doc(
Reads a .gltf or .glb file (told apart by content) and evaluates its first animation at each
keyframe: returns (times, positions), times (K,) float64 seconds and positions (K, joints, dim)
float64, the world positions of the first skin's joints. For a file written by flexkin.render
(formats gltf, glb) they are in flexkin's coordinates and length unit (the axis mapping and
scale undone; dim the result's), one joint per point, leading end first: the frames to float32
precision, at the times steps / GltfOptions.steps_per_second. A tree result's file has a joint
per link on the link's parent point, then a tip joint on each leaf (docs/gltf-export.md, "Trees";
the file's asset.extras.flexkin.joint_points names each joint's point), frame f at
f / steps_per_second. Other files: glTF world
coordinates, metres, dim 3. Raises OSError for a file that cannot be read, InputError for one
that is not valid glTF, has no skin, or uses what the reader does not support.
)doc");
  std::string formats_doc;
  for (const auto& entry : Vocabulary<OutputFormat>::kEntries) {
    formats_doc += std::string("\n  ") + entry.name + ": " + entry.summary;
  }
  m.def("render", &Render, py::arg("result"), py::arg("out_dir"), py::arg("formats") = py::none(),
        py::kw_only(), py::arg("stem") = py::none(), py::arg("every") = py::none(),
        py::arg("width") = py::none(), py::arg("height") = py::none(),
        py::arg("azimuth") = py::none(), py::arg("elevation") = py::none(),
        py::arg("fps") = py::none(), py::arg("max_frames") = py::none(),
        py::arg("max_strands") = py::none(), py::arg("title") = py::none(),
        py::arg("ffmpeg") = py::none(), py::arg("figure") = py::none(),
        py::arg("plot") = py::none(), py::arg("animation") = py::none(),
        py::arg("viewer") = py::none(), py::arg("gltf") = py::none(),
        (R"doc(
Draws a Result, a RobotResult, or a file flexkin wrote (a result file, a robot trajectory, a
strand file or a tree result, told apart by content) as `flexkin render` draws it (docs/rendering.md), through the
same library call, and returns the paths written.

render(result, out_dir, formats=None, *, stem=None, every=None,
       width=None, height=None, azimuth=None, elevation=None, fps=None, max_frames=None,
       max_strands=None, title=None, ffmpeg=None, figure=None, plot=None, animation=None,
       viewer=None, gltf=None)
  formats: a list of names or a comma-separated string, written to out_dir/<stem>.<ext>
    (out_dir created if missing), each file whole or not at all. None: svg, png, plots for a
    Result; svg, png for a RobotResult or a strand file, which are drawn in svg, png, pdf, mp4,
    gif and html only (an arm as a chain whose end effector leads, the fixed base marked).
  stem: the outputs' name; None: the file's name without .json/.npz, or "result" for an object.
  The command's options, None = its default: every (figures: every K-th frame, 0 automatic),
    width, height (pixels; height 0 = from the data), azimuth, elevation (3D view, degrees),
    fps, max_frames (animations), max_strands (strand files), title, ffmpeg (the program for mp4
    and gif).
  Every other member of the components' options: figure (FigureOptions), plot (PlotOptions),
    animation (AnimationOptions), viewer (ViewerOptions: playback, trails, digits, ...), gltf
    (GltfOptions: tube_radius, tube_sides, scale, up_axis, ...), each an options object or a
    dict of its fields; the keywords above are applied on top of them.
The GIL is released while drawing. Raises InputError for an unknown format (listing the valid
names), a format a RobotResult or strand file is not drawn in (naming the ones it is), or an
invalid option (field the keyword, or "gltf.tube_sides" for an options object),
OSError for a file that cannot be written, RuntimeError when ffmpeg is missing or fails.
Formats:)doc" +
         formats_doc)
            .c_str());
}

}  // namespace flexkin::python
