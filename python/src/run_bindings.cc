// Runs: flexkin.run (a chain and its leader steps), flexkin.load_scenario and run_scenario (the
// `flexkin run` of a scenario file or dict), and their Result. The run records its frames densely
// (flexkin/frames.h) with the GIL released; the progress callback takes it back, and Ctrl-C (or
// an exception in the callback) stops the run. Result.frames, steps and link_angles are numpy
// views of those dense arrays, as are those of a result file read back: nothing is copied or
// converted on the way to Python or back to the writers and renderers.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cstring>
#include <limits>
#include <string>
#include <system_error>
#include <vector>

#include "convert.h"
#include "fields.h"
#include "flexkin/any_scenario.h"
#include "flexkin/groom.h"
#include "flexkin/result_io.h"
#include "flexkin/run.h"
#include "flexkin/scenario.h"
#include "progress.h"

namespace flexkin::python {
namespace {

// A run's result, or a result file read back: its frames dense in file.result.frames, which
// the arrays of the Python object view.
struct Result {
  ResultFile file;
};

// A numpy view of `count` values at `data` shaped `shape`, kept alive by the Python Result that
// holds them (`r` is always one: these are its attributes' getters).
template <typename T>
py::array View(const Result& r, std::vector<py::ssize_t> shape, const T* data) {
  const py::object owner = py::cast(&r, py::return_value_policy::reference);
  return py::array_t<T>(std::move(shape), data, owner);
}

py::array FramesView(const Result& r) {
  const Frames& f = r.file.result.frames;
  return View(r, {static_cast<py::ssize_t>(f.size()), f.num_points(), f.dim()},
              f.points_data().data());
}

py::array StepsView(const Result& r) {
  const Frames& f = r.file.result.frames;
  return View(r, {static_cast<py::ssize_t>(f.size())}, f.steps().data());
}

py::object LinkAnglesView(const Result& r) {
  const Frames& f = r.file.result.frames;
  if (!f.has_link_angles()) return py::none();
  return View(r, {static_cast<py::ssize_t>(f.size()), f.num_points() - 1},
              f.link_angles_data().data());
}

// The setters of unpickling: frames, then steps, then link angles, each checked against the
// ones before.
void SetFrames(Result& r, py::handle value) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a || a.ndim() != 3 || (a.shape(2) != 2 && a.shape(2) != 3) || a.shape(1) < 2) {
    PyErr_Clear();
    ThrowInput("state", "the pickled Result's frames are not an (F, n+1, dim) array");
  }
  Frames& f = r.file.result.frames;
  f.Resize(a.shape(0), a.shape(1), static_cast<int>(a.shape(2)), false);
  std::memcpy(f.mutable_points_data(), a.data(), sizeof(double) * static_cast<size_t>(a.size()));
  r.file.dim = static_cast<int>(a.shape(2));
}

void SetSteps(Result& r, py::handle value) {
  const auto a = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(value);
  Frames& f = r.file.result.frames;
  if (!a || a.ndim() != 1 || a.shape(0) != static_cast<py::ssize_t>(f.size())) {
    PyErr_Clear();
    ThrowInput("state", "the pickled Result's frames and steps disagree");
  }
  std::memcpy(f.mutable_steps(), a.data(), sizeof(int64_t) * f.size());
}

void SetLinkAngles(Result& r, py::handle value) {
  Frames& f = r.file.result.frames;
  if (value.is_none()) {
    f.DropLinkAngles();
    return;
  }
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a || a.ndim() != 2 || a.shape(0) != static_cast<py::ssize_t>(f.size()) ||
      a.shape(1) != f.num_points() - 1) {
    PyErr_Clear();
    ThrowInput("state", "the pickled Result's link_angles and frames disagree");
  }
  Frames with;
  with.Resize(static_cast<int64_t>(f.size()), f.num_points(), f.dim(), true);
  std::memcpy(with.mutable_points_data(), f.points_data().data(),
              sizeof(double) * f.points_data().size());
  std::memcpy(with.mutable_steps(), f.steps().data(), sizeof(int64_t) * f.size());
  std::memcpy(with.mutable_link_angles_data(), a.data(),
              sizeof(double) * static_cast<size_t>(a.size()));
  f = std::move(with);
}

// A member of the run (result.metrics, result.seconds) as a read-only attribute (a copy).
template <typename M>
auto RunGet(M RunResult::*member) {
  return [member](const Result& r) -> M { return r.file.result.*member; };
}
template <typename M>
auto RunSet(M RunResult::*member) {
  return [member](Result& r, py::handle value) { r.file.result.*member = py::cast<M>(value); };
}

// The run, its frames kept densely for the Result; with `files`, streamed to them as well
// through the library's one call (RunToFiles), as `flexkin run -o --csv` writes them.
Result RunToArrays(const Chain& chain, const Points& leader_steps, RunOptions options,
                   py::object progress, std::string scenario, const RunFiles& files = {}) {
  Result result;
  result.file.dim = chain.dim();
  result.file.scenario_name = std::move(scenario);
  result.file.colliders = options.colliders;  // written with the result, drawn with it
  ProgressHook hook(std::move(progress));
  hook.Install(&options.progress);
  try {
    py::gil_scoped_release release;
    if (files.result.empty() && files.csv.empty()) {
      result.file.result = Run(chain, leader_steps, options);  // checks the inputs (InputError)
    } else {
      FrameRecorder recorder;
      result.file.result =
          RunToFiles(chain, leader_steps, options, result.file.scenario_name, files, &recorder);
      result.file.result.frames = std::move(recorder.frames);
    }
  } catch (const StopRun&) {
    hook.Rethrow();
  }
  return result;
}

// A chain scenario: a kinematic one as RunToArrays runs it; a dynamic one ("dynamics",
// docs/dynamics.md) through the library's one call for chain scenarios (RunChainScenario), its
// frames kept for the Result.
Result RunScenarioToArrays(const Scenario& s, py::object progress, const RunFiles& files) {
  if (!s.dynamics) {
    return RunToArrays(s.chain, s.leader_steps, s.options, std::move(progress), s.name, files);
  }
  Result result;
  result.file.dim = s.chain.dim();
  result.file.scenario_name = s.name;
  result.file.colliders = s.options.colliders;
  Scenario run = s;
  ProgressHook hook(std::move(progress));
  hook.Install(&run.options.progress);
  try {
    py::gil_scoped_release release;
    FrameRecorder recorder;
    result.file.result = RunChainScenario(run, files, &recorder);
    result.file.result.frames = std::move(recorder.frames);
  } catch (const StopRun&) {
    hook.Rethrow();
  }
  return result;
}

Scenario ScenarioArg(ScenarioSource scenario) {
  if (py::isinstance<Scenario>(scenario)) return py::cast<Scenario>(scenario);
  if (py::isinstance<py::dict>(scenario))
    return ParseScenarioText(JsonOfDict(scenario, "scenario"));
  const std::string path = PathArg(scenario);
  if (path.empty()) {
    ThrowInput("scenario",
               "is a " + std::string(py::str(py::type::of(scenario).attr("__name__"))) +
                   "; expected a path to a scenario file, a dict of its JSON form or a Scenario");
  }
  const ScenarioReadOptions options{RobotReaderOptions(py::none())};
  return OnFile(path, [&] {
    // The front door (flexkin/any_scenario.h): one read, the kind told apart in the library.
    AnyScenario any = ReadScenarioFile(path, options);
    if (any.kind != ScenarioKind::kChain) {
      const char* runner = any.kind == ScenarioKind::kGroom   ? "run_groom"
                           : any.kind == ScenarioKind::kRobot ? "run_robot"
                                                              : "run_scenario";
      throw InputError(Problem("", std::string("is a ") + NameOf(any.kind) +
                                       " scenario, not a chain one; run it with flexkin." +
                                       runner));
    }
    any.ThrowIfInvalid();
    return std::move(*any.chain);
  });
}

std::string ResultRepr(const Result& r) {
  const RunResult& run = r.file.result;
  return "Result(method=" + Quoted(MethodName(run.method)) + ", " + std::to_string(r.file.dim) +
         "D, " + std::to_string(run.lengths.size()) + " links, " + std::to_string(run.num_steps) +
         " leader steps, " + std::to_string(run.frames.size()) +
         " frames, substeps=" + std::to_string(run.accuracy.substeps) +
         ", l2_total=" + Num(run.metrics.l2_total) +
         ", max_relative_length_error=" + Num(run.metrics.max_relative_length_error) +
         (r.file.scenario_name.empty() ? "" : ", scenario=" + Quoted(r.file.scenario_name)) + ")";
}

const char* kRunDoc = R"doc(
Runs a chain whose leading end moves in straight lines through leader_steps.

run(points, leader_steps, *, method="tractrix", substeps=1, record_every=1, tolerance=0.0,
    max_substeps=65536, link_angles=True, overall=None, colliders=None, link_radius=0.0,
    progress=None) -> Result

  points: (n+1, dim) array-like (row 0 the leading end; link lengths the distances between
          the points) or a Chain.
  leader_steps: (m, dim) array-like, m >= 1: the successive targets of the leading end, not
          including its start (flexkin.split_pull, flexkin.resample_path make them).
  method: "tractrix", "ftl", "min_rotation", "min_joint_angle", "overall" or "follow_path".
  substeps: equal sub-steps per leader step (>= 1).
  record_every: keep frame 0, every record_every-th leader step and the last.
  tolerance: if > 0, sub-steps are doubled until the estimated largest distance to the
          continuous motion is at most tolerance (length unit), up to max_substeps.
  link_angles: compute each frame's link angles to the pull (radians).
  overall: OverallOptions, ObjectiveWeights or a dict of term weights (method "overall").
  colliders: things the chain stays outside of, a list of dicts in the form of a scenario's
          "colliders" (docs/scenario-format.md, docs/colliders.md; keyframed ones with
          "motion", times in leader steps); methods tractrix, ftl and follow_path.
  link_radius: each link a capsule of this radius (length unit) kept outside the colliders.
  progress: callable(done, total) called about every 0.1 s with leader steps done.

The GIL is released during the run; Ctrl-C stops it (KeyboardInterrupt). Raises InputError
for invalid input, naming the argument ("leader_steps[2][0]", "substeps").
)doc";

}  // namespace

Result ReadResult(PathLike path_arg) {
  const std::string path = RequiredPath(path_arg, "path");
  return Result{OnFile(path, [&] { return ReadResultFile(path); })};
}

void WriteResult(const Result& r, PathLike path_arg) {
  const std::string path = RequiredPath(path_arg, "path");
  const ResultFileFormat format = ResultFileFormatOfPath(path);
  OnFile(path, [&] { WriteResultFile(r.file, path, format); });
}

void WriteCsv(const Result& r, PathLike path_arg) {
  const std::string path = RequiredPath(path_arg, "path");
  OnFile(path, [&] { WriteFramesCsv(r.file.result, path); });
}

py::list ProblemList(const Problems& problems) {
  py::list out;
  for (const Problem& p : problems) {
    py::dict d;
    d["field"] = p.field;
    d["message"] = p.message;
    d["value"] = p.value;
    d["expected"] = p.expected;
    out.append(d);
  }
  return out;
}

py::list ValidateScenario(ScenarioFile scenario, OptionalPath directory) {
  // Any kind, read once by the front door (flexkin/any_scenario.h).
  ScenarioReadOptions options;
  options.robot = RobotReaderOptions(directory);
  if (py::isinstance<py::dict>(scenario)) {
    return ProblemList(ReadScenarioText(JsonOfDict(scenario, "scenario"), options).problems);
  }
  const std::string path = PathArg(scenario);
  if (path.empty()) {
    ThrowInput("scenario", "is not a path or a dict; expected a path to a scenario file or a dict");
  }
  return ProblemList(OnFile(path, [&] { return ReadScenarioFile(path, options).problems; }));
}

py::dict EstimateOutput(int num_links, int dim, int64_t num_steps, int record_every,
                        bool link_angles) {
  RunOptions options;
  options.record_every = record_every;
  options.link_angles = link_angles;
  ThrowIfAny(options.Validate());
  if (num_links < 1) ThrowInput("num_links", "must be at least 1", std::to_string(num_links));
  if (dim != 2 && dim != 3) ThrowInput("dim", "must be 2 or 3", std::to_string(dim));
  if (num_steps < 0) ThrowInput("num_steps", "must not be negative", std::to_string(num_steps));
  const ResultSizeEstimate e = EstimateResultSize(num_links, dim, num_steps, options);
  py::dict d;
  d["frames"] = e.frames;
  d["link_angles"] = e.link_angles;
  d["json_bytes"] = e.json_bytes;
  d["npz_bytes"] = e.npz_bytes;
  d["csv_bytes"] = e.csv_bytes;
  d["recorder_bytes"] = e.recorder_bytes;
  return d;
}

const ResultFile& ResultFileOfObject(py::handle object) {
  if (!py::isinstance<Result>(object)) {
    ThrowInput("result",
               "is a " + std::string(py::str(py::type::of(object).attr("__name__"))) +
                   "; expected a flexkin.Result (flexkin.run, run_scenario, read_result)");
  }
  return py::cast<const Result&>(object).file;
}

namespace {

// A scenario of any kind from a path or a dict, through the front door (flexkin/any_scenario.h);
// InputError for its first problem (named by the file for a path).
AnyScenario AnyScenarioArg(py::handle scenario) {
  const ScenarioReadOptions options{RobotReaderOptions(py::none())};
  if (py::isinstance<py::dict>(scenario)) {
    AnyScenario any = ReadScenarioText(JsonOfDict(scenario, "scenario"), options);
    any.ThrowIfInvalid();
    return any;
  }
  const std::string path = PathArg(scenario);
  if (path.empty()) {
    ThrowInput("scenario",
               "is a " + std::string(py::str(py::type::of(scenario).attr("__name__"))) +
                   "; expected a path to a scenario file, a dict of its JSON form or a Scenario");
  }
  return OnFile(path, [&] {
    AnyScenario any = ReadScenarioFile(path, options);
    any.ThrowIfInvalid();
    return any;
  });
}

// A tree scenario (docs/trees.md): run (into `files.result` where given, .npz or .json) and
// returned as a dict of arrays: frames (F, n+1, dim), parents (n+1,), and per frame after the
// start passes, residual, reached, converged; a robot tree's angles (F, joints) and joints too.
py::dict RunTreeToDict(const AnyScenario& any, ProgressCallback progress, const RunFiles& files) {
  if (!files.csv.empty()) {
    ThrowInput("csv", "is not written for a tree scenario", Quoted(files.csv), "None");
  }
  ProgressHook hook(std::move(progress));
  TreeRunResult r;
  try {
    const auto tick = [&hook](int64_t done, int64_t total) { hook.Tick(done, total); };
    if (files.result.empty()) {
      r = RunTree(*any.tree, tick);
    } else {
      r = OnFile(files.result, [&] {
        return RunScenarioToFiles(any, {files.result, ""}, tick).tree;
      });
    }
  } catch (const StopRun&) {
    hook.Rethrow();
  }
  const py::ssize_t count = static_cast<py::ssize_t>(r.frames.size()),
                    rows = any.tree->tree.points.rows(), dim = any.tree->tree.points.cols();
  py::array_t<double> frames({count, rows, dim});
  for (py::ssize_t f = 0; f < count; ++f) {
    std::copy(r.frames[f].data(), r.frames[f].data() + rows * dim,
              frames.mutable_data() + f * rows * dim);
  }
  py::dict out;
  out["frames"] = frames;
  out["parents"] = py::array_t<int>(static_cast<py::ssize_t>(any.tree->tree.parents.size()),
                                    any.tree->tree.parents.data());
  out["passes"] = py::array_t<int>(static_cast<py::ssize_t>(r.passes.size()), r.passes.data());
  out["residual"] =
      py::array_t<double>(static_cast<py::ssize_t>(r.residual.size()), r.residual.data());
  py::array_t<bool> reached(static_cast<py::ssize_t>(r.reached.size())),
      converged(static_cast<py::ssize_t>(r.converged.size())),
      finished(static_cast<py::ssize_t>(r.finished.size()));
  for (size_t i = 0; i < r.reached.size(); ++i) {
    reached.mutable_data()[i] = r.reached[i] != 0;
    converged.mutable_data()[i] = r.converged[i] != 0;
    finished.mutable_data()[i] = r.finished[i] != 0;
  }
  out["reached"] = reached;
  out["converged"] = converged;
  out["finished"] = finished;
  out["max_length_error"] = r.max_length_error;
  if (any.tree->robot) {  // a robot tree: its joints' names and angles, every frame
    const RobotTree& robot = *any.tree->robot;
    const py::ssize_t n = robot.joints();
    py::array_t<double> angles({count, n});
    for (py::ssize_t f = 0; f < count; ++f) {
      std::copy(r.angles[f].data(), r.angles[f].data() + n, angles.mutable_data() + f * n);
    }
    out["angles"] = angles;
    out["joints"] = robot.joint_names;
    // Sliding joints (prismatic): per joint, and the points whose link into them slides.
    std::vector<bool> prismatic(static_cast<size_t>(n), false);
    for (size_t j = 0; j < robot.prismatic.size(); ++j) prismatic[j] = robot.prismatic[j] != 0;
    out["prismatic"] = prismatic;
    out["sliding"] = any.tree->sliding;
  }
  return out;
}

// flexkin.run_scenario: a chain to a Result, a robot to a RobotResult, any other kind into its
// files through the library's one call, its report returned.
py::object RunAnyScenario(ScenarioSource scenario, ProgressCallback progress, OptionalPath output,
                          OptionalPath csv) {
  const RunFiles files{RequiredPath(output, "output", true), RequiredPath(csv, "csv", true)};
  // A Scenario object, or a chain read from a path or a dict: a Result.
  AnyScenario any;
  const Scenario* chain = nullptr;
  if (py::isinstance<Scenario>(scenario)) {
    chain = &py::cast<const Scenario&>(scenario);
  } else {
    any = AnyScenarioArg(scenario);
    if (any.kind == ScenarioKind::kChain) chain = &*any.chain;
    if (any.kind == ScenarioKind::kRobot) {
      return TrackToResult(*any.robot, std::move(progress), output, csv);
    }
    if (any.kind == ScenarioKind::kTree) return RunTreeToDict(any, std::move(progress), files);
  }
  if (chain != nullptr) {
    if (!files.result.empty()) ResultFileFormatOfPath(files.result, "output");
    return py::cast(RunScenarioToArrays(*chain, std::move(progress), files));
  }
  // Every other kind runs into its files.
  if (files.result.empty()) {
    ThrowInput("output",
               std::string("is required for a ") + NameOf(any.kind) +
                   " scenario, which runs into its file; expected a path",
               "None", "a path");
  }
  ProgressHook hook(std::move(progress));
  try {
    const ScenarioRunReport report = OnFile(files.result, [&] {
      return RunScenarioToFiles(any, {files.result, files.csv},
                                [&hook](int64_t done, int64_t total) { hook.Tick(done, total); });
    });
    return py::cast(report.strands);
  } catch (const StopRun&) {
    hook.Rethrow();
  }
}

}  // namespace

void BindRun(py::module_& m) {
  py::class_<Result> result(m, "Result", R"doc(
The result of a run (flexkin.run, flexkin.run_scenario), as in a result file
(docs/result-format.md).
  frames: (F, n+1, dim) float64, the recorded configurations, row 0 the leading end
  steps: (F,) int64, leader steps done at each frame (0 the initial configuration)
  link_angles: (F, n) float64 (radians, each link's angle to the pull) or None
  metrics: Metrics; accuracy: AccuracyReport; overall: OverallRunReport (method "overall");
  contacts: ContactReport (colliders); path: PathReport (method "follow_path")
  method, lengths (n,), num_steps, substeps (used), weights, seconds, scenario, dim, num_links
)doc");
  Fields<Result>(result, "Result")
      .Property(
          "method", [](const Result& r) { return std::string(MethodName(r.file.result.method)); },
          [](Result& r, py::handle name) {
            r.file.result.method = MethodArg(py::cast<std::string>(name));
          },
          "The method of the run: 'tractrix', 'ftl', 'min_rotation', 'min_joint_angle', "
          "'overall' or 'follow_path'.")
      .Property("lengths", RunGet(&RunResult::lengths), RunSet(&RunResult::lengths),
                "(n,) float64, a copy: the link lengths, fixed at the start (length unit).")
      .Property("num_steps", RunGet(&RunResult::num_steps), RunSet(&RunResult::num_steps),
                "Leader steps of the run.")
      .Property("frames", &FramesView, &SetFrames,
                "(F, n+1, dim) float64, a view (no copy) of the result's frames: the recorded "
                "configurations, row 0 the leading end: frame 0, every record_every-th leader "
                "step and the last (length unit). Changing its values changes what write, "
                "write_csv and render see.")
      .Property("steps", &StepsView, &SetSteps,
                "(F,) int64, a view: the leader steps done at each frame (0: the initial "
                "configuration).")
      .Property("link_angles", &LinkAnglesView, &SetLinkAngles,
                "(F, n) float64, a view: each link's angle to the pull (radians, [0, pi]); None "
                "if the run computed none (link_angles=False).")
      .Property("metrics", RunGet(&RunResult::metrics), RunSet(&RunResult::metrics),
                "Metrics: L2 per step and total, length error, path length of each point.")
      .Property("accuracy", RunGet(&RunResult::accuracy), RunSet(&RunResult::accuracy),
                "AccuracyReport: what the accuracy control did (RunOptions.tolerance).")
      .Property(
          "overall", RunGet(&RunResult::overall), RunSet(&RunResult::overall),
          "OverallRunReport: what the overall solver did (method 'overall'; zeros otherwise).")
      .Property("contacts", RunGet(&RunResult::contacts), RunSet(&RunResult::contacts),
                "ContactReport: what the colliders did (a scenario's \"colliders\"; "
                "num_colliders 0 otherwise).")
      .Property("path", RunGet(&RunResult::path), RunSet(&RunResult::path),
                "PathReport: clearance, tip error and deviation from the head's path per leader "
                "step (method 'follow_path'; enabled False otherwise).")
      .Property("weights", RunGet(&RunResult::weights), RunSet(&RunResult::weights),
                "ObjectiveWeights: the overall method's metric (method 'overall').")
      .Property("seconds", RunGet(&RunResult::seconds), RunSet(&RunResult::seconds),
                "Wall time of the computation (seconds).")
      .Property(
          "scenario", [](const Result& r) { return r.file.scenario_name; },
          [](Result& r, py::handle name) { r.file.scenario_name = py::cast<std::string>(name); },
          "The scenario's name; '' if none.")
      .Finish(false, [](Result& r) {
        // The setters checked frames, steps and link angles against each other.
        if (r.file.result.frames.num_points() != r.file.result.lengths.size() + 1) {
          ThrowInput("state", "the pickled Result's frames, steps and lengths disagree");
        }
      });
  result
      .def_property_readonly(
          "substeps", [](const Result& r) { return r.file.result.accuracy.substeps; },
          "Sub-steps per leader step used (accuracy.substeps).")
      .def_property_readonly(
          "dynamics",
          [](const Result& r) -> py::object {
            const DynamicRunReport& d = r.file.result.dynamics;
            if (!d.enabled) return py::none();
            py::dict out;
            out["projection"] = d.projection;
            out["frame_rate"] = d.frame_rate;
            out["substeps"] = d.substeps;
            out["failures"] = d.failures;
            out["contact_substeps"] = d.contact_substeps;
            out["contact_solves"] = d.contact_solves;
            out["contact_solve_failures"] = d.contact_solve_failures;
            out["energy"] = ToArray(d.energy);
            return std::move(out);
          },
          "A dynamic chain's (a scenario's \"dynamics\", docs/dynamics.md): a dict with "
          "projection, frame_rate, substeps, failures, contact_substeps, contact_solves, "
          "contact_solve_failures and energy ((num_steps + 1,) float64, the energy at every "
          "frame); None for a kinematic run.")
      .def_property_readonly(
          "dim", [](const Result& r) { return r.file.dim; }, "2 or 3.")
      .def_property_readonly(
          "num_links",
          [](const Result& r) { return static_cast<int>(r.file.result.lengths.size()); },
          "n, the number of links.")
      .def(
          "brief_report", [](const Result& r) { return r.file.result.BriefReport(); },
          "One line: method, steps, length error, L2 total, accuracy, time.")
      .def(
          "full_report", [](const Result& r) { return r.file.result.FullReport(); },
          "Several lines, with the path-length profile.")
      .def("__repr__", &ResultRepr, "A summary: method, size, frames, L2 total, length error.")
      .def("write", &WriteResult, py::arg("path"),
           "Writes the result file `path`: JSON (.json) or NumPy .npz (.npz) by its extension, "
           "as `flexkin run -o`; all-or-nothing (an existing file is left untouched on error).")
      .def("write_csv", &WriteCsv, py::arg("path"),
           "Writes the frames as CSV, as `flexkin run --csv`: a header step,point,x,y (,z), "
           "then one row per point per frame, 17 significant digits; all-or-nothing.");

  m.def(
      "path_deviation",
      [](PointsOrChain points, ArrayLike leader_steps, const Result& result) {
        const Chain chain = ChainArg(points);
        const Points steps = ReadPoints(leader_steps, "leader_steps", 1, chain.dim());
        PathComparison c;
        {
          py::gil_scoped_release release;
          c = PathDeviation(chain, steps, result.file.result.frames);
        }
        py::dict out;
        out["deviation"] = ToArray(Points(c.deviation));
        out["tip_error"] = ToArray(c.tip_error);
        return out;
      },
      py::arg("points"), py::arg("leader_steps"), py::arg("result"), R"doc(
How far a run's frames are from the head's path (flexkin::PathDeviation), for any method: a
"follow_path" run's points lie on it, a "tractrix" run's cut its corners.

path_deviation(points, leader_steps, result) -> dict
  points: (n+1, dim) array-like or Chain: the run's initial chain.
  leader_steps: (m, dim) array-like: the run's targets.
  result: the Result of the run of points through leader_steps.
The head's path is the polyline through the initial points reversed (point n first), then the
targets. Returns {"deviation": (F, n+1) float64, each point's distance from that path up to the
head's position at the frame's step; "tip_error": (F,) float64, the distance of the last point
from the path's point at arc length s_head - (L_1 + ... + L_n)} (length unit). Raises
InputError if the frames do not fit the chain or the targets.
)doc");
  m.def("read_result", &ReadResult, py::arg("path"),
        "Reads a result file (JSON or .npz, recognised by its content) as a Result. Raises "
        "OSError if it cannot be read, InputError (field: the path, then the member) if it is "
        "not a valid result file.");
  m.def("write_result", &WriteResult, py::arg("result"), py::arg("path"),
        "Writes `result` to `path` (.json or .npz by the extension), as Result.write.");
  m.def("validate_scenario", &ValidateScenario, py::arg("scenario"), py::kw_only(),
        py::arg("directory") = py::none(),
        "The problems of a scenario of any kind, chain, robot, groom or tree (a path to a "
        "scenario file or a dict of its JSON form; its kind told apart as `flexkin validate` "
        "does) as `flexkin "
        "validate` finds them: a list of dicts (field, message, value, expected), empty if the "
        "scenario is valid. directory: where a robot scenario's relative \"urdf\" file is looked "
        "up (default: the file's directory, or the working directory for a dict). Raises OSError "
        "for a file that cannot be read.");
  m.def("estimate_output", &EstimateOutput, py::arg("num_links"), py::arg("dim"),
        py::arg("num_steps"), py::kw_only(), py::arg("record_every") = 1,
        py::arg("link_angles") = true,
        "The size of a run's output before the run: a dict of frames (exact), link_angles, "
        "json_bytes, npz_bytes, csv_bytes and recorder_bytes (estimates).");
  m.def(
      "run",
      [](PointsOrChain points, ArrayLike leader_steps, const std::string& method, int substeps,
         int record_every, double tolerance, int max_substeps, bool link_angles,
         OverallLike overall, CollidersLike colliders, double link_radius,
         ProgressCallback progress) {
        const Chain chain = ChainArg(points);
        const Points steps = ReadPoints(leader_steps, "leader_steps", 1, chain.dim());
        return RunToArrays(chain, steps,
                           MakeRunOptions(method, substeps, record_every, tolerance, max_substeps,
                                          link_angles, overall, colliders, link_radius),
                           std::move(progress), "");
      },
      kRunDoc, py::arg("points"), py::arg("leader_steps"), py::kw_only(),
      py::arg("method") = "tractrix", py::arg("substeps") = 1, py::arg("record_every") = 1,
      py::arg("tolerance") = 0.0, py::arg("max_substeps") = 1 << 16, py::arg("link_angles") = true,
      py::arg("overall") = py::none(), py::arg("colliders") = py::none(),
      py::arg("link_radius") = 0.0, py::arg("progress") = py::none());

  py::class_<Scenario> scenario(m, "Scenario", R"doc(
A scenario (docs/scenario-format.md) read by flexkin.load_scenario: name, description,
chain (Chain), leader_steps ((m, dim) float64), options (RunOptions). Its members may be
changed before flexkin.run_scenario runs it.
)doc");
  Fields<Scenario>(scenario, "Scenario")
      .Member("name", &Scenario::name, "The scenario's \"name\"; '' if absent.", true)
      .Member("description", &Scenario::description,
              "The scenario's \"description\"; '' if absent.", true)
      .Member("chain", &Scenario::chain, "The initial Chain, from \"curve\".", true)
      .Property(
          "leader_steps", [](const Scenario& s) { return ToArray(Points(s.leader_steps)); },
          [](Scenario& s, py::handle steps) {
            s.leader_steps = ReadPoints(steps, "leader_steps", 1, s.chain.dim());
          },
          "(m, dim) float64, a copy: the targets of the leading end from \"leader\", not "
          "including its start (length unit).",
          true)
      .Member("options", &Scenario::options,
              "RunOptions: method, sub-steps, recording and accuracy of the run.", true)
      .Finish(false);
  scenario.def("summary", &ScenarioSummary,
               "One line: dimension, links, total length, leader steps, method, sub-steps.");
  scenario.def(
      "__repr__",
      [](const Scenario& s) {
        return "Scenario(" + (s.name.empty() ? "" : Quoted(s.name) + ": ") + ScenarioSummary(s) +
               ")";
      },
      "The name and the summary.");

  m.def("load_scenario", &ScenarioArg, py::arg("scenario"),
        "Reads a scenario: a path (str or os.PathLike) to a scenario file, or a dict of its JSON "
        "form (docs/scenario-format.md). Raises InputError naming the JSON pointer of the first "
        "problem (field '/leader/steps'), OSError for a file that cannot be read.");
  m.def("run_scenario", &RunAnyScenario, py::arg("scenario"), py::kw_only(),
        py::arg("progress") = py::none(), py::arg("output") = py::none(),
        py::arg("csv") = py::none(),
        "Runs a scenario of any kind (a path or a dict of its JSON form, told apart as `flexkin "
        "validate` does; or a Scenario) as `flexkin run` (or `flexkin robot`) does, with the "
        "same result bit for bit. A chain returns a Result (progress as in run); a robot a "
        "RobotResult, as run_robot; a groom runs into its strand file `output` (required, .npz) "
        "and returns a StrandRunReport, as run_groom; a tree (docs/trees.md) returns a dict of "
        "arrays: frames (F, n+1, dim), parents, and per frame passes, residual, reached, "
        "converged. output, csv: None or the paths of the "
        "files `flexkin run -o --csv` writes (a chain's result file, .json or .npz, and frames "
        "CSV; a robot's trajectory JSON and joint CSV; a groom's strand file; a tree's result, "
        ".npz or .json), written through "
        "the library's one call (RunScenarioToFiles): streamed while the run goes, renamed into "
        "place only when complete.");
}

}  // namespace flexkin::python
