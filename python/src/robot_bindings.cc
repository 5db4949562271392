// Fixed-base arms: flexkin.run_robot (the `flexkin robot` of a robot scenario file or dict),
// RobotScenario, load_robot_scenario and the RobotResult: TrackPath with the GIL released, its
// steps streamed into numpy arrays (and the trajectory files), Ctrl-C and progress checked.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cstring>
#include <iterator>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "convert.h"
#include "fields.h"
#include "flexkin/arm.h"
#include "flexkin/robot_scenario.h"
#include "progress.h"

namespace flexkin::python {
namespace {

// The per-step arrays of a RobotResult, in the order of their docs.
constexpr const char* kFloatSteps[] = {"ee_error", "base_error", "pointing_error",
                                       "velocity_ratio"};
constexpr const char* kIntSteps[] = {"iterations", "sweeps",   "passes",
                                     "legs",       "restarts", "velocity_legs"};
constexpr const char* kBoolSteps[] = {"converged", "reached", "stretched", "limited",
                                      "joint_space"};

struct RobotResult {
  std::string scenario, method, joint, brief;
  int dim = 2;
  ArmTrajectory summary;  // steps empty: they are in `data`
  long long num_steps = 0;
  std::map<std::string, py::object> data;  // arrays (and None for absent azimuths)
};

// The steps of a trajectory streamed into preallocated arrays: (T, n) angles and azimuths,
// (T, n+1, dim) points, and one (T,) array per per-step report member. The arrays are made and
// their pointers taken with the GIL held; Add runs with it released (TrackPath's thread) and
// ticks the progress hook, which checks for Ctrl-C about every 0.1 s and throws StopRun.
class StepArrays : public ArmStepSink {
 public:
  // `model`: the arm; its points are kept one per distinct position (ChainPoints), as the
  // trajectory file has them.
  StepArrays(int64_t count, const ArmModel& model, bool azimuths, ProgressHook* hook)
      : model_(model),
        count_(count),
        links_(model.num_links()),
        dim_(model.dim),
        chain_(model.has_axes() ? ChainPoints(model, InitialState(model).points).rows()
                                : links_ + 1),
        hook_(hook) {
    const int64_t links = links_, dim = dim_;
    angles_ = py::array_t<double>({count, links});
    points_ = py::array_t<double>({count, chain_, dim});
    if (azimuths) azimuths_ = py::array_t<double>({count, links});
    for (size_t k = 0; k < std::size(kFloatSteps); ++k) floats_.emplace_back(count);
    for (size_t k = 0; k < std::size(kIntSteps); ++k) ints_.emplace_back(count);
    for (size_t k = 0; k < std::size(kBoolSteps); ++k) bools_.emplace_back(count);
    angle_data_ = angles_.mutable_data();
    point_data_ = points_.mutable_data();
    azimuth_data_ = azimuths ? azimuths_.mutable_data() : nullptr;
    for (auto& a : floats_) float_data_.push_back(a.mutable_data());
    for (auto& a : ints_) int_data_.push_back(a.mutable_data());
    for (auto& a : bools_) bool_data_.push_back(a.mutable_data());
  }

  void Add(const ArmStepReport& s) override {
    if (done_ >= count_) throw std::logic_error("flexkin: TrackPath produced more steps than rows");
    if (s.state.angles.angle.size() != links_ || s.state.points.size() != (links_ + 1) * dim_ ||
        (azimuth_data_ != nullptr && s.state.angles.azimuth.size() != links_)) {
      throw std::logic_error("flexkin: TrackPath produced a step of another shape");
    }
    const int64_t t = done_;
    std::memcpy(angle_data_ + t * links_, s.state.angles.angle.data(),
                sizeof(double) * static_cast<size_t>(links_));
    if (chain_ == links_ + 1) {
      std::memcpy(point_data_ + t * chain_ * dim_, s.state.points.data(),
                  sizeof(double) * static_cast<size_t>(chain_ * dim_));
    } else {
      const Points chain = ChainPoints(model_, s.state.points);
      std::memcpy(point_data_ + t * chain_ * dim_, chain.data(),
                  sizeof(double) * static_cast<size_t>(chain_ * dim_));
    }
    if (azimuth_data_ != nullptr) {
      std::memcpy(azimuth_data_ + t * links_, s.state.angles.azimuth.data(),
                  sizeof(double) * static_cast<size_t>(links_));
    }
    const double f[] = {s.ee_error, s.base_error, s.pointing_error, s.velocity_ratio};
    const int64_t i[] = {s.iterations, s.sweeps, s.passes, s.legs, s.restarts, s.velocity_legs};
    const bool b[] = {s.converged, s.reached, s.stretched, s.limited, s.joint_space};
    for (size_t k = 0; k < float_data_.size(); ++k) float_data_[k][t] = f[k];
    for (size_t k = 0; k < int_data_.size(); ++k) int_data_[k][t] = i[k];
    for (size_t k = 0; k < bool_data_.size(); ++k) bool_data_[k][t] = b[k];
    ++done_;
    if (hook_ != nullptr) hook_->Tick(done_, count_);
  }

  int64_t done() const { return done_; }

  // Needs the GIL.
  void MoveTo(RobotResult* r) {
    r->data["angles"] = angles_;
    r->data["points"] = points_;
    r->data["azimuths"] = azimuth_data_ != nullptr ? py::object(azimuths_) : py::none();
    for (size_t k = 0; k < floats_.size(); ++k) r->data[kFloatSteps[k]] = floats_[k];
    for (size_t k = 0; k < ints_.size(); ++k) r->data[kIntSteps[k]] = ints_[k];
    for (size_t k = 0; k < bools_.size(); ++k) r->data[kBoolSteps[k]] = bools_[k];
  }

 private:
  const ArmModel& model_;
  int64_t count_, links_, dim_, chain_, done_ = 0;
  ProgressHook* hook_;
  py::array_t<double> angles_, points_, azimuths_;
  std::vector<py::array_t<double>> floats_;  // one array each (not copies of one handle)
  std::vector<py::array_t<int64_t>> ints_;
  std::vector<py::array_t<bool>> bools_;
  double *angle_data_, *point_data_, *azimuth_data_;
  std::vector<double*> float_data_;
  std::vector<int64_t*> int_data_;
  std::vector<bool*> bool_data_;
};

RobotScenario RobotScenarioArg(RobotScenarioSource scenario, OptionalPath directory) {
  if (py::isinstance<RobotScenario>(scenario)) return py::cast<RobotScenario>(scenario);
  if (py::isinstance<py::dict>(scenario)) {
    return ParseRobotScenarioText(JsonOfDict(scenario, "scenario"), RobotReaderOptions(directory));
  }
  const std::string path = PathArg(scenario);
  if (path.empty()) {
    ThrowInput("scenario",
               "is a " + std::string(py::str(py::type::of(scenario).attr("__name__"))) +
                   "; expected a path to a robot scenario file, a dict of its JSON form or a "
                   "RobotScenario");
  }
  const RobotScenarioOptions options = RobotReaderOptions(directory);
  return OnFile(path, [&] { return LoadRobotScenarioFile(path, options); });
}

// A RuntimeWarning where some target was not reached, as `flexkin robot` warns (and exits with 3):
// never silently. With method fixed_point, the vocabulary's words on where it fails. Raises if
// warnings are errors.
void WarnIfUnreached(const RobotResult& r, FixedBaseMethod method) {
  if (r.summary.unreached == 0) return;
  std::string message = "flexkin: " + std::to_string(r.summary.unreached) + " of " +
                        std::to_string(r.num_steps) +
                        " targets were not reached (largest end-effector error " +
                        Num(r.summary.max_ee_error) + "; see RobotResult.reached)";
  if (method == FixedBaseMethod::kFixedPoint) {
    for (const auto& entry : Vocabulary<FixedBaseMethod>::kEntries) {
      if (entry.value == method) message += std::string("; method fixed_point is ") + entry.summary;
    }
    message += "; method newton (the default) is the one to use";
  }
  if (PyErr_WarnEx(PyExc_RuntimeWarning, message.c_str(), 1) != 0) throw py::error_already_set();
}

// TrackPath of the scenario into the arrays of a RobotResult, and into the trajectory JSON at
// `output` and the joint CSV at `csv` where they are not "" (each renamed into place only when
// complete: on Ctrl-C or an error the writers remove their temporary files).
RobotResult Track(const RobotScenario& s, py::object progress, const std::string& output,
                  const std::string& csv) {
  const ArmModel& model = s.model;
  ThrowIfAny(model.Validate());
  ThrowIfAnyArmOptions(s.options);
  ThrowIfAny(s.options.ValidateFor(model));
  const int64_t dim = model.dim;
  const bool spherical = model.joint() == ArmJoint::kSpherical;
  RobotResult r;
  r.scenario = s.name;
  r.method = FixedBaseMethodName(s.options.method);
  r.joint = NameOf(model.joint());
  r.dim = static_cast<int>(dim);
  r.data["link_lengths"] = ToArray(model.link_lengths);
  r.data["base"] = ToArray(model.base);
  r.data["path"] = ToArray(Points(s.path));
  const ArmState initial = InitialState(model);
  r.data["initial_angles"] = ToArray(initial.angles.angle);
  r.data["initial_azimuths"] = spherical ? py::object(ToArray(initial.angles.azimuth)) : py::none();
  r.data["initial_points"] =
      ToArray(model.has_axes() ? ChainPoints(model, initial.points) : Points(initial.points));
  const int64_t count = static_cast<int64_t>(s.path.rows());
  ProgressHook hook(std::move(progress));
  StepArrays arrays(count, model, spherical, &hook);
  try {
    py::gil_scoped_release release;
    r.summary = TrackToFiles(s, output, csv, &arrays);  // the files only if paths were given
  } catch (const StopRun&) {
    hook.Rethrow();
  }
  if (arrays.done() != count) {
    throw std::logic_error("flexkin: TrackPath produced " + std::to_string(arrays.done()) +
                           " steps for " + std::to_string(count) + " path rows");
  }
  arrays.MoveTo(&r);
  r.num_steps = count;
  r.brief = r.summary.BriefReport();
  WarnIfUnreached(r, s.options.method);
  return r;
}

RobotResult RunRobot(RobotScenarioSource scenario, OptionalPath directory, OptionalStr method,
                     ProgressCallback progress, OptionalPath output, OptionalPath csv) {
  RobotScenario s = RobotScenarioArg(scenario, directory);
  if (!method.is_none()) s.options.method = ParseFixedBaseMethod(py::cast<std::string>(method));
  return Track(s, std::move(progress), RequiredPath(output, "output", true),
               RequiredPath(csv, "csv", true));
}

std::string RobotRepr(const RobotResult& r) {
  return "RobotResult(" + std::to_string(r.dim) + "D " + r.joint + " arm, " +
         std::to_string(py::len(r.data.at("link_lengths"))) + " links, method " + Quoted(r.method) +
         ", " + std::to_string(r.num_steps) + " steps, " + std::to_string(r.summary.unreached) +
         " not reached, max_ee_error=" + Num(r.summary.max_ee_error) +
         (r.scenario.empty() ? "" : ", scenario=" + Quoted(r.scenario)) + ")";
}

// The arrays of a RobotResult and their docs.
struct ArrayDoc {
  const char* name;
  const char* doc;
};
constexpr ArrayDoc kArrays[] = {
    {"link_lengths", "(n,) float64: the link lengths, base link first (length unit)."},
    {"base", "(dim,) float64: where the base is bolted (length unit)."},
    {"path", "(T, dim) float64: the end effector's targets, one per step (length unit)."},
    {"initial_angles", "(n,) float64: the joint angles before the path (radians)."},
    {"initial_azimuths", "(n,) float64: spherical joints' azimuths before the path, or None."},
    {"initial_points",
     "(g, dim) float64: the points before the path, base first, one per "
     "distinct position (joint_groups; g = n+1 where each joint has its own)."},
    {"angles", "(T, n) float64: the joint angles after each step (radians)."},
    {"azimuths", "(T, n) float64: spherical joints' azimuths after each step (radians), or None."},
    {"points",
     "(T, g, dim) float64: the points after each step, base first, one per distinct "
     "position (joint_groups; g = n+1 where each joint has its own)."},
    {"ee_error", "(T,) float64: |end effector - target| after each step (length unit)."},
    {"base_error", "(T,) float64: each step's last base residual (length unit)."},
    {"pointing_error",
     "(T,) float64: with pointing, the angle between the tool axis and where it should point "
     "after each step (radians); 0 without."},
    {"velocity_ratio",
     "(T,) float64: with time_step, each step's largest joint speed over its limit (<= 1: "
     "limits kept); 0 without."},
    {"iterations", "(T,) int64: solver iterations of each step."},
    {"sweeps", "(T,) int64: sweeps from the end effector of each step."},
    {"passes", "(T,) int64: passes over the links of each step."},
    {"legs", "(T,) int64: legs a far move was tracked in (0: one sweep)."},
    {"restarts", "(T,) int64: joint-space solves after the first."},
    {"velocity_legs",
     "(T,) int64: with time_step, the legs each step took to keep the velocity limits (1: as "
     "asked); 0 without."},
    {"converged", "(T,) bool: the base residual reached the tolerance."},
    {"reached", "(T,) bool: the target was reached."},
    {"stretched", "(T,) bool: out of reach, the arm stretched toward the target."},
    {"limited", "(T,) bool: a joint limit was active."},
    {"joint_space", "(T,) bool: the step was solved in joint space."},
};

py::dict EstimateRobot(const RobotScenario& s) {
  const RobotOutputEstimate e = EstimateRobotOutput(s);
  py::dict d;
  d["json_bytes"] = e.json_bytes;
  d["csv_bytes"] = e.csv_bytes;
  return d;
}

}  // namespace

std::optional<RobotTrajectoryFile> RobotTrajectoryOfObject(py::handle object) {
  if (!py::isinstance<RobotResult>(object)) return std::nullopt;
  const RobotResult& r = py::cast<const RobotResult&>(object);
  const int dim = r.dim;
  RobotTrajectoryFile t;
  t.scenario_name = r.scenario;
  t.dim = dim;
  t.method = r.method;
  t.link_lengths = ReadVector(r.data.at("link_lengths"), "result.link_lengths", -1);
  t.base = ReadVector(r.data.at("base"), "result.base", dim);
  t.states.push_back(ReadPoints(r.data.at("initial_points"), "result.initial_points", 2, dim));
  const auto points =
      py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(r.data.at("points"));
  if (!points || points.ndim() != 3) {
    PyErr_Clear();
    ThrowInput("result.points", "is not valid; expected a (T, g, dim) array of numbers");
  }
  const int64_t steps = points.shape(0), rows = points.shape(1);
  if (rows != t.states.front().rows() || points.shape(2) != dim) {
    ThrowInput("result.points", "has shape (" + std::to_string(steps) + ", " +
                                    std::to_string(rows) + ", " + std::to_string(points.shape(2)) +
                                    "); expected (T, " + std::to_string(t.states.front().rows()) +
                                    ", " + std::to_string(dim) + "), as initial_points");
  }
  for (int64_t s = 0; s < steps; ++s) {
    Points state(rows, dim);
    std::memcpy(state.data(), points.data() + s * rows * dim,
                sizeof(double) * static_cast<size_t>(rows * dim));
    t.states.push_back(std::move(state));
  }
  t.targets = ReadPoints(r.data.at("path"), "result.path", 1, dim);
  const auto reached =
      py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(r.data.at("reached"));
  if (!reached || reached.ndim() != 1 || reached.shape(0) != steps || t.targets.rows() != steps) {
    PyErr_Clear();
    ThrowInput("result", "its path, points and reached disagree in the number of steps");
  }
  t.reached.assign(reached.data(), reached.data() + steps);
  t.unreached = r.summary.unreached;
  t.max_ee_error = r.summary.max_ee_error;
  t.seconds = r.summary.seconds;
  return t;
}

py::object TrackToResult(const RobotScenario& scenario, py::object progress, py::handle output,
                         py::handle csv) {
  return py::cast(Track(scenario, std::move(progress), RequiredPath(output, "output", true),
                        RequiredPath(csv, "csv", true)));
}

void BindRobot(py::module_& m) {
  py::class_<RobotResult> c(m, "RobotResult", R"doc(
The trajectory of a fixed-base arm (flexkin.run_robot, flexkin.track_path), as `flexkin robot`
writes it (docs/robot-format.md). Robot order: point 0 the base, point n the end effector.
T = the number of path targets; row t is the state after the step to path[t].
  angles: (T, n) joint angles (radians); azimuths: (T, n) for spherical joints, else None
  points: (T, g, dim) points, base first, one per distinct position (g = n+1 unless joints
    share a point: joint_groups)
  initial_angles (n,), initial_azimuths (n,) or None, initial_points (g, dim): before the path
  path: (T, dim) the end effector's targets; link_lengths (n,), base (dim,)
  per step (T,): ee_error, base_error, pointing_error, velocity_ratio (float64); iterations,
    sweeps, passes, legs, restarts, velocity_legs (int64); converged, reached, stretched,
    limited, joint_space (bool)
  summary: num_steps, unreached, max_ee_error, max_base_error, max_pointing_error,
    max_iterations, total_sweeps, total_passes, total_velocity_legs, seconds; scenario, method
    ("newton", "fixed_point"), joint, dim
)doc");
  Fields<RobotResult> fields(c, "RobotResult");
  for (const ArrayDoc& array : kArrays) {
    const std::string key = array.name;
    fields.Property(
        array.name, [key](const RobotResult& r) { return r.data.at(key); },
        [key](RobotResult& r, py::handle value) {
          r.data[key] = py::reinterpret_borrow<py::object>(value);
        },
        array.doc);
  }
  fields.Member("scenario", &RobotResult::scenario, "The scenario's name; '' if none.")
      .Member("method", &RobotResult::method, "The fixed-base method: 'newton' or 'fixed_point'.")
      .Member("joint", &RobotResult::joint, "'revolute' or 'spherical'.")
      .Member("dim", &RobotResult::dim, "2 or 3.")
      .Member("num_steps", &RobotResult::num_steps, "T, the steps tracked (one per target).")
      .Nested("unreached", &RobotResult::summary, &ArmTrajectory::unreached,
              "Steps whose target was not reached.")
      .Nested("max_ee_error", &RobotResult::summary, &ArmTrajectory::max_ee_error,
              "Largest ee_error (length unit).")
      .Nested("max_base_error", &RobotResult::summary, &ArmTrajectory::max_base_error,
              "Largest base_error (length unit).")
      .Nested("max_pointing_error", &RobotResult::summary, &ArmTrajectory::max_pointing_error,
              "Largest pointing_error (radians; 0 without pointing).")
      .Nested("max_iterations", &RobotResult::summary, &ArmTrajectory::max_iterations,
              "Most solver iterations of one step.")
      .Nested("total_sweeps", &RobotResult::summary, &ArmTrajectory::total_sweeps,
              "Sweeps of all steps.")
      .Nested("total_passes", &RobotResult::summary, &ArmTrajectory::total_passes,
              "Passes over the links of all steps.")
      .Nested("total_velocity_legs", &RobotResult::summary, &ArmTrajectory::velocity_legs,
              "Legs of all steps with time_step (0 without).")
      .Nested("seconds", &RobotResult::summary, &ArmTrajectory::seconds,
              "Wall time of the tracking (seconds).")
      .Hidden(
          "brief", [](const RobotResult& r) { return r.brief; },
          [](RobotResult& r, py::handle v) { r.brief = py::cast<std::string>(v); })
      .Finish(false, [](RobotResult& r) { r.summary.num_steps = r.num_steps; });
  c.def(
      "brief_report", [](const RobotResult& r) { return r.brief; },
      "One line: steps, unreached, errors, iterations, sweeps, time.");
  c.def("__repr__", &RobotRepr, "A summary: arm, method, steps, unreached, largest error.");

  py::class_<RobotScenario> scenario(m, "RobotScenario", R"doc(
A robot scenario (docs/robot-format.md) read by flexkin.load_robot_scenario, or made:

RobotScenario(model, path, *, options=None, name="")
  model: ArmModel; path: (T, dim) the end effector's targets; options: ArmOptions, a dict of
  its fields or None. Its members may be changed before flexkin.run_robot runs it.
)doc");
  scenario.def(py::init([](ModelObject model, ArrayLike path, ArmOptionsLike options,
                           const std::string& name) {
                 RobotScenario s;
                 s.model = ModelArg(model);
                 ThrowIfAny(s.model.Validate());
                 s.path = ReadPoints(path, "path", 1, s.model.dim);
                 s.options = OptionsArg<ArmOptions>(options, "options");
                 ThrowIfAnyArmOptions(s.options);
                 s.name = name;
                 return s;
               }),
               py::arg("model"), py::arg("path"), py::kw_only(), py::arg("options") = py::none(),
               py::arg("name") = "");
  Fields<RobotScenario>(scenario, "RobotScenario")
      .Member("name", &RobotScenario::name, "The scenario's \"name\"; '' if absent.", true)
      .Member("model", &RobotScenario::model, "The ArmModel, from \"arm\" or \"urdf\".", true)
      .Property(
          "path", [](const RobotScenario& s) { return ToArray(Points(s.path)); },
          [](RobotScenario& s, py::handle path) {
            s.path = ReadPoints(path, "path", 1, s.model.dim);
          },
          "(T, dim) float64, a copy: the end effector's targets, one per step (length unit).", true)
      .Member("options", &RobotScenario::options, "ArmOptions: the \"solver\".", true)
      .Finish(false);
  scenario.def("summary", &RobotScenarioSummary,
               "One line, as `flexkin validate` prints it: arm, joints, reach, targets, method.");
  scenario.def("estimate_output", &EstimateRobot,
               "The estimated sizes of the outputs: a dict of json_bytes (the trajectory) and "
               "csv_bytes (the joint CSV).");
  scenario.def(
      "__repr__",
      [](const RobotScenario& s) {
        return "RobotScenario(" + (s.name.empty() ? "" : Quoted(s.name) + ": ") +
               RobotScenarioSummary(s) + ")";
      },
      "The name and the summary.");

  m.def("load_robot_scenario", &RobotScenarioArg, py::arg("scenario"), py::kw_only(),
        py::arg("directory") = py::none(),
        "Reads a robot scenario: a path (str or os.PathLike) to a robot scenario file or a dict "
        "of its JSON form (docs/robot-format.md). directory: where a relative \"urdf\" file is "
        "looked up (default: the scenario file's directory, or the working directory for a "
        "dict). Raises InputError naming the JSON pointer of the first problem, OSError for a "
        "file that cannot be read.");
  m.def("run_robot", &RunRobot, py::arg("scenario"), py::kw_only(),
        py::arg("directory") = py::none(), py::arg("method") = py::none(),
        py::arg("progress") = py::none(), py::arg("output") = py::none(),
        py::arg("csv") = py::none(), R"doc(
Tracks a robot scenario's path as `flexkin robot` does, with the same numbers. Returns a
RobotResult.

run_robot(scenario, *, directory=None, method=None, progress=None, output=None, csv=None)
  scenario: a path to a robot scenario file, a dict of its JSON form (docs/robot-format.md)
    or a RobotScenario.
  directory: where a relative "urdf" file is looked up (default: the scenario file's
    directory, or the working directory for a dict).
  method: overrides the solver's method ("newton", "fixed_point"), as --method.
    "fixed_point" is the predecessors' baseline, for comparison: slow, and where it does not
    converge (arms with joint axes such as URDF arms, joint limits) its steps stop unreached.
  progress: callable(done, total) called about every 0.1 s with the targets done.
  output: a path: also write the trajectory JSON there, as `flexkin robot -o`, streamed.
  csv: a path: also write the joint angles as CSV there, as --csv (one column per joint,
    named by the URDF's joint names where the model has them, else joint_0, joint_1, ...).
Where some target is not reached (result.unreached > 0), a RuntimeWarning says how many, as
`flexkin robot` warns and exits with 3.
The GIL is released during the tracking; Ctrl-C raises KeyboardInterrupt within about 0.1 s.
The files are written whole or not at all (Ctrl-C, an error: no file, an existing one left
untouched).
)doc");
}

}  // namespace flexkin::python
