// Fixed-base arms: flexkin.run_robot (the `flexkin robot` of a robot scenario file or dict) and
// its RobotResult: TrackPath with the GIL released, its steps turned into numpy arrays.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cstring>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "convert.h"
#include "flexkin/arm.h"
#include "flexkin/robot_scenario.h"
#include "progress.h"
#ifdef FLEXKIN_PYTHON_URDF
#include "flexkin/urdf.h"
#endif

namespace flexkin::python {
namespace {

// The per-step arrays of a RobotResult, in the order of their docs.
constexpr const char* kFloatSteps[] = {"ee_error", "base_error"};
constexpr const char* kIntSteps[] = {"iterations", "sweeps", "passes", "legs", "restarts"};
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
  StepArrays(int64_t count, int64_t links, int64_t dim, bool azimuths, ProgressHook* hook)
      : count_(count), links_(links), dim_(dim), hook_(hook) {
    angles_ = py::array_t<double>({count, links});
    points_ = py::array_t<double>({count, links + 1, dim});
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
    std::memcpy(point_data_ + t * (links_ + 1) * dim_, s.state.points.data(),
                sizeof(double) * static_cast<size_t>((links_ + 1) * dim_));
    if (azimuth_data_ != nullptr) {
      std::memcpy(azimuth_data_ + t * links_, s.state.angles.azimuth.data(),
                  sizeof(double) * static_cast<size_t>(links_));
    }
    const double f[] = {s.ee_error, s.base_error};
    const int64_t i[] = {s.iterations, s.sweeps, s.passes, s.legs, s.restarts};
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
  int64_t count_, links_, dim_, done_ = 0;
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

RobotScenarioOptions ReaderOptions(const std::string& directory) {
#ifdef FLEXKIN_PYTHON_URDF
  RobotScenarioOptions options = UrdfRobotScenarioOptions();
#else
  RobotScenarioOptions options;
#endif
  options.directory = directory;
  return options;
}

RobotScenario RobotScenarioArg(py::handle scenario, py::handle directory) {
  const std::string dir = directory.is_none() ? "" : PathArg(directory);
  if (!directory.is_none() && dir.empty()) {
    ThrowInput("directory", "is not a path; expected a str or os.PathLike, or None");
  }
  if (py::isinstance<py::dict>(scenario)) {
    return ParseRobotScenarioText(JsonOfDict(scenario, "scenario"), ReaderOptions(dir));
  }
  const std::string path = PathArg(scenario);
  if (path.empty()) {
    ThrowInput("scenario",
               "is a " + std::string(py::str(py::type::of(scenario).attr("__name__"))) +
                   "; expected a path to a robot scenario file or a dict of its JSON form");
  }
  try {
    return LoadRobotScenarioFile(path, ReaderOptions(dir));
  } catch (const InputError& e) {
    Problem p = e.problem();  // the file's name before the JSON pointer, as `flexkin robot`
    p.field = p.field.empty() ? path : path + ": " + p.field;
    throw InputError(p);
  }
}

RobotResult Track(const ArmModel& model, const Points& path, const ArmOptions& options,
                  const std::string& scenario) {
  ThrowIfAny(model.Validate());
  ThrowIfAny(options.Validate());
  const int64_t links = model.num_links(), dim = model.dim;
  const bool spherical = model.joint() == ArmJoint::kSpherical;
  RobotResult r;
  r.scenario = scenario;
  r.method = FixedBaseMethodName(options.method);
  r.joint = NameOf(model.joint());
  r.dim = static_cast<int>(dim);
  r.data["link_lengths"] = ToArray(model.link_lengths);
  r.data["base"] = ToArray(model.base);
  r.data["path"] = ToArray(Points(path));
  const ArmState initial = InitialState(model);
  r.data["initial_angles"] = ToArray(initial.angles.angle);
  r.data["initial_azimuths"] = spherical ? py::object(ToArray(initial.angles.azimuth)) : py::none();
  r.data["initial_points"] = ToArray(Points(initial.points));
  const int64_t count = static_cast<int64_t>(path.rows());
  ProgressHook hook{py::none()};  // Ctrl-C only
  StepArrays sink(count, links, dim, spherical, &hook);
  try {
    py::gil_scoped_release release;
    r.summary = TrackPath(model, path, options, &sink);
  } catch (const StopRun&) {
    hook.Rethrow();
  }
  if (sink.done() != count) {
    throw std::logic_error("flexkin: TrackPath produced " + std::to_string(sink.done()) +
                           " steps for " + std::to_string(count) + " path rows");
  }
  sink.MoveTo(&r);
  r.num_steps = count;
  r.brief = r.summary.BriefReport();
  return r;
}

RobotResult RunRobot(py::handle scenario, py::handle directory, py::object method) {
  RobotScenario s = RobotScenarioArg(scenario, directory);
  if (!method.is_none()) s.options.method = ParseFixedBaseMethod(py::cast<std::string>(method));
  return Track(s.model, s.path, s.options, s.name);
}

std::string RobotRepr(const RobotResult& r) {
  return "RobotResult(" + std::to_string(r.dim) + "D " + r.joint + " arm, " +
         std::to_string(py::len(r.data.at("link_lengths"))) + " links, method " + Quoted(r.method) +
         ", " + std::to_string(r.num_steps) + " steps, " + std::to_string(r.summary.unreached) +
         " not reached, max_ee_error=" + Num(r.summary.max_ee_error) +
         (r.scenario.empty() ? "" : ", scenario=" + Quoted(r.scenario)) + ")";
}

constexpr const char* kArrayNames[] = {
    "link_lengths",   "base",       "path",     "initial_angles", "initial_azimuths",
    "initial_points", "angles",     "azimuths", "points",         "ee_error",
    "base_error",     "iterations", "sweeps",   "passes",         "legs",
    "restarts",       "converged",  "reached",  "stretched",      "limited",
    "joint_space"};

}  // namespace

py::object TrackToResult(const ArmModel& model, const Points& path, const ArmOptions& options,
                         const std::string& scenario) {
  return py::cast(Track(model, path, options, scenario));
}

void BindRobot(py::module_& m) {
  py::class_<RobotResult> c(m, "RobotResult", R"doc(
The trajectory of a fixed-base arm (flexkin.run_robot), as `flexkin robot` writes it
(docs/robot-format.md). Robot order: point 0 the base, point n the end effector. T = the
number of path targets; row t is the state after the step to path[t].
  angles: (T, n) joint angles (radians); azimuths: (T, n) for spherical joints, else None
  points: (T, n+1, dim) link points, base first
  initial_angles (n,), initial_azimuths (n,) or None, initial_points (n+1, dim): before the path
  path: (T, dim) the end effector's targets; link_lengths (n,), base (dim,)
  per step (T,): ee_error, base_error (float64); iterations, sweeps, passes, legs, restarts
    (int64); converged, reached, stretched, limited, joint_space (bool)
  summary: num_steps, unreached, max_ee_error, max_base_error, max_iterations, total_sweeps,
    total_passes, seconds; scenario, method ("newton", "fixed_point"), joint, dim
)doc");
  for (const char* name : kArrayNames) {
    const std::string key = name;
    c.def_property_readonly(name, [key](const RobotResult& r) { return r.data.at(key); });
  }
  c.def_readonly("scenario", &RobotResult::scenario)
      .def_readonly("method", &RobotResult::method)
      .def_readonly("joint", &RobotResult::joint)
      .def_readonly("dim", &RobotResult::dim)
      .def_property_readonly("num_steps", [](const RobotResult& r) { return r.num_steps; })
      .def_property_readonly("unreached", [](const RobotResult& r) { return r.summary.unreached; })
      .def_property_readonly("max_ee_error",
                             [](const RobotResult& r) { return r.summary.max_ee_error; })
      .def_property_readonly("max_base_error",
                             [](const RobotResult& r) { return r.summary.max_base_error; })
      .def_property_readonly("max_iterations",
                             [](const RobotResult& r) { return r.summary.max_iterations; })
      .def_property_readonly("total_sweeps",
                             [](const RobotResult& r) { return r.summary.total_sweeps; })
      .def_property_readonly("total_passes",
                             [](const RobotResult& r) { return r.summary.total_passes; })
      .def_property_readonly("seconds", [](const RobotResult& r) { return r.summary.seconds; })
      .def("brief_report", [](const RobotResult& r) { return r.brief; })
      .def("__repr__", &RobotRepr)
      .def(py::pickle(
          [](const RobotResult& r) {
            py::dict arrays;
            for (const auto& [key, value] : r.data) arrays[key.c_str()] = value;
            const ArmTrajectory& t = r.summary;
            return py::make_tuple(
                r.scenario, r.method, r.joint, r.dim, arrays,
                py::make_tuple(r.num_steps, t.max_ee_error, t.max_base_error, t.unreached,
                               t.max_iterations, t.total_sweeps, t.total_passes, t.seconds),
                r.brief);
          },
          [](const py::tuple& state) {
            StateTuple(state, 7, "RobotResult");
            RobotResult r;
            r.scenario = py::cast<std::string>(state[0]);
            r.method = py::cast<std::string>(state[1]);
            r.joint = py::cast<std::string>(state[2]);
            r.dim = py::cast<int>(state[3]);
            const auto arrays = py::cast<py::dict>(state[4]);
            for (const char* name : kArrayNames) {
              if (!arrays.contains(name)) ThrowInput("state", std::string("lacks ") + name);
              r.data[name] = arrays[name];
            }
            const auto t = StateTuple(py::cast<py::tuple>(state[5]), 8, "RobotResult summary");
            r.num_steps = py::cast<long long>(t[0]);
            r.summary.max_ee_error = py::cast<double>(t[1]);
            r.summary.max_base_error = py::cast<double>(t[2]);
            r.summary.unreached = py::cast<int>(t[3]);
            r.summary.max_iterations = py::cast<int>(t[4]);
            r.summary.total_sweeps = py::cast<long long>(t[5]);
            r.summary.total_passes = py::cast<long long>(t[6]);
            r.summary.seconds = py::cast<double>(t[7]);
            r.brief = py::cast<std::string>(state[6]);
            return r;
          }));

  m.def("run_robot", &RunRobot, py::arg("scenario"), py::kw_only(),
        py::arg("directory") = py::none(), py::arg("method") = py::none(),
        "Tracks a robot scenario's path (a path to a robot scenario file or a dict of its JSON "
        "form, docs/robot-format.md) as `flexkin robot` does, with the same numbers. "
        "directory: where a relative \"urdf\" file is looked up (default: the scenario file's "
        "directory, or the working directory for a dict). method: overrides the solver's "
        "method (\"newton\", \"fixed_point\"), as --method. The GIL is released during the "
        "tracking. Returns a RobotResult.");
}

}  // namespace flexkin::python
