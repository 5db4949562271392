// Fixed-base arms from Python: flexkin.ArmModel, ArmOptions, ArmStepReport, forward_kinematics,
// joint_angles_from_points, arm_step and track_path (flexkin/arm.h; robot order, base first).
#include "flexkin/arm.h"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <string>

#include "convert.h"
#include "fields.h"
#include "flexkin/curves.h"

namespace flexkin::python {
namespace {

// An optional (n,) or (n, 3) argument: empty when None.
Eigen::VectorXd OptionalVector(py::handle object, const std::string& name, int size) {
  if (object.is_none()) return Eigen::VectorXd();
  return ReadArray(object, name, 1, 1, 0, size).cast<Eigen::VectorXd>();
}
Eigen::MatrixXd OptionalRows(py::handle object, const std::string& name, int rows) {
  if (object.is_none()) return Eigen::MatrixXd();
  const Points p = ReadPoints(object, name, rows, 3);
  if (p.rows() != rows) {
    ThrowInput(name, "has " + std::to_string(p.rows()) + " rows; expected " + std::to_string(rows) +
                         ", one per link");
  }
  return Eigen::MatrixXd(p);
}

// Joint angles (n,) and azimuths (n,): given for spherical joints (unless `need_azimuths` is
// false), None for revolute joints.
JointAngles AnglesArg(const ArmModel& model, py::handle angles, py::handle azimuths,
                      bool need_azimuths = true) {
  JointAngles a;
  a.angle = ReadArray(angles, "angles", 1, 1, 0, model.num_links()).cast<Eigen::VectorXd>();
  const bool spherical = model.joint() == ArmJoint::kSpherical;
  if (!spherical && !azimuths.is_none()) {
    ThrowInput("azimuths", "given for an arm with revolute joints; expected None", "", "None");
  }
  if (spherical && need_azimuths && azimuths.is_none()) {
    ThrowInput("azimuths",
               "is None; expected " + std::to_string(model.num_links()) +
                   " values, the azimuths of the spherical joints (radians)",
               "None", std::to_string(model.num_links()) + " values");
  }
  a.azimuth = OptionalVector(azimuths, "azimuths", model.num_links());
  return a;
}

// The getter and setter of a member of an ArmStepReport's solver memory (pickled, not shown).
template <typename E>
auto MemoryGet(E ArmSolverMemory::*member) {
  return [member](const ArmStepReport& r) { return r.state.memory.*member; };
}
template <typename E>
auto MemorySet(E ArmSolverMemory::*member) {
  return [member](ArmStepReport& r, py::handle v) { r.state.memory.*member = EigenIn<E>(v); };
}

py::object AzimuthsOrNone(const Eigen::VectorXd& azimuth) {
  return azimuth.size() > 0 ? py::object(ToArray(azimuth)) : py::none();
}

}  // namespace

const ArmModel& ModelArg(py::handle model) {
  if (!py::isinstance<ArmModel>(model)) {
    const std::string type = py::str(py::type::of(model).attr("__name__"));
    ThrowInput("model", "is a " + type + "; expected a flexkin.ArmModel", type, "ArmModel");
  }
  return py::cast<const ArmModel&>(model);
}

namespace {}  // namespace

void BindArms(py::module_& m) {
  py::class_<ArmModel> model(m, "ArmModel", R"doc(
A fixed-base arm (flexkin::ArmModel, docs/robots.md), robot order: link 1 at the base.

ArmModel(link_lengths, *, dim=2, base=None, base_direction=None, joint_min=None,
         joint_max=None, max_bend=None, joint_axes=None, link_directions=None,
         initial_angles=None, initial_azimuths=None)
  link_lengths: (n,) positive; base: (dim,) where the base is bolted (default the origin);
  base_direction: (dim,) the direction of "link 0" (default +x);
  joint_min, joint_max: (n,) revolute limits (rad) in [-pi, pi]; max_bend: (n,) spherical limits;
  joint_axes, link_directions: (n, 3) spatial revolute joints (URDF arms);
  initial_angles, initial_azimuths: (n,) the start (default 0).
Planar arms (dim 2) and arms with joint_axes have revolute joints, other spatial arms spherical.
)doc");
  model
      .def(py::init([](ArrayLike link_lengths, int dim, OptionalArray base, OptionalArray direction,
                       OptionalArray joint_min, OptionalArray joint_max, OptionalArray max_bend,
                       OptionalArray joint_axes, OptionalArray link_directions,
                       OptionalArray angles, OptionalArray azimuths) {
             ArmModel a;
             a.dim = dim;
             if (dim != 2 && dim != 3) {
               throw InputError(Problem::Invalid("dim", std::to_string(dim), "2 or 3"));
             }
             a.link_lengths =
                 ReadArray(link_lengths, "link_lengths", 1, 1, 0, -1).cast<Eigen::VectorXd>();
             const int n = a.num_links();
             a.base = base.is_none() ? Eigen::VectorXd::Zero(dim) : ReadVector(base, "base", dim);
             a.base_direction = direction.is_none() ? Eigen::VectorXd::Unit(dim, 0)
                                                    : ReadVector(direction, "base_direction", dim);
             a.joint_min = OptionalVector(joint_min, "joint_min", n);
             a.joint_max = OptionalVector(joint_max, "joint_max", n);
             a.max_bend = OptionalVector(max_bend, "max_bend", n);
             a.joint_axes = OptionalRows(joint_axes, "joint_axes", n);
             a.link_directions = OptionalRows(link_directions, "link_directions", n);
             const bool spherical = dim == 3 && a.joint_axes.size() == 0;
             a.initial.angle = angles.is_none() ? Eigen::VectorXd::Zero(n)
                                                : OptionalVector(angles, "initial_angles", n);
             a.initial.azimuth = azimuths.is_none()
                                     ? (spherical ? Eigen::VectorXd::Zero(n) : Eigen::VectorXd())
                                     : OptionalVector(azimuths, "initial_azimuths", n);
             ThrowIfAny(a.Validate());
             return a;
           }),
           py::arg("link_lengths"), py::kw_only(), py::arg("dim") = 2, py::arg("base") = py::none(),
           py::arg("base_direction") = py::none(), py::arg("joint_min") = py::none(),
           py::arg("joint_max") = py::none(), py::arg("max_bend") = py::none(),
           py::arg("joint_axes") = py::none(), py::arg("link_directions") = py::none(),
           py::arg("initial_angles") = py::none(), py::arg("initial_azimuths") = py::none())
      .def_static(
          "straight",
          [](int dim, int links, double link_length) {
            if (dim != 2 && dim != 3) {
              throw InputError(Problem::Invalid("dim", std::to_string(dim), "2 or 3"));
            }
            if (links < 1 || links > kMaxGeneratedLinks) {
              throw InputError(
                  Problem::Invalid("links", std::to_string(links),
                                   "an integer from 1 to " + std::to_string(kMaxGeneratedLinks)));
            }
            ArmModel a = StraightArm(dim, links, link_length);
            ThrowIfAny(a.Validate());
            return a;
          },
          py::arg("dim"), py::arg("links"), py::arg("link_length"),
          "A straight arm of `links` links of `link_length` from the origin along +x, all "
          "joint angles 0, no limits.")
      .def_property_readonly(
          "joint", [](const ArmModel& a) { return std::string(NameOf(a.joint())); },
          "'revolute' (planar arms, or spatial arms with joint_axes) or 'spherical'.")
      .def_property_readonly("num_links", &ArmModel::num_links, "n, the number of links.")
      .def_property_readonly("reach", &ArmModel::reach,
                             "The sum of the link lengths (length unit).")
      .def_property_readonly("has_limits", &ArmModel::has_limits,
                             "Whether the joints have limits (joint_min/joint_max or max_bend).")
      .def(
          "__repr__",
          [](const ArmModel& a) {
            return "ArmModel(" + std::to_string(a.dim) + "D " + NameOf(a.joint()) + ", " +
                   std::to_string(a.num_links()) + " links, reach " + Num(a.reach()) +
                   (a.has_limits() ? ", with limits" : "") + ")";
          },
          "A summary: dimension, joint kind, links, reach, limits.");
  Fields<ArmModel>(model, "ArmModel")
      .Validate("joint_min[2]")
      .Member("dim", &ArmModel::dim, "2 (planar) or 3 (spatial).")
      .Array("link_lengths", &ArmModel::link_lengths,
             "(n,) float64: the link lengths, base link first (length unit).")
      .Array("base", &ArmModel::base, "(dim,) float64: where the base is bolted (length unit).")
      .Array("base_direction", &ArmModel::base_direction,
             "(dim,) float64: the direction of \"link 0\", which joint 0 turns link 1 from.")
      .Array("joint_min", &ArmModel::joint_min,
             "(n,) float64: revolute lower limits (radians, >= -pi), or None (no limits).", true)
      .Array("joint_max", &ArmModel::joint_max,
             "(n,) float64: revolute upper limits (radians, <= pi), or None.", true)
      .Array("max_bend", &ArmModel::max_bend,
             "(n,) float64: spherical limits, the largest bend angle of each joint (radians, "
             "(0, pi]), or None.",
             true)
      .Array("joint_axes", &ArmModel::joint_axes,
             "(n, 3) float64: spatial revolute joints' unit axes, row j in link j's frame (as "
             "from a URDF), or None (spherical joints).",
             true)
      .Array("link_directions", &ArmModel::link_directions,
             "(n, 3) float64: with joint_axes, each link's unit direction in its own frame, or "
             "None (every link along base_direction).",
             true)
      .Property(
          "initial_angles", [](const ArmModel& a) { return ToArray(a.initial.angle); },
          [](ArmModel& a, py::handle v) { a.initial.angle = EigenIn<Eigen::VectorXd>(v); },
          "(n,) float64: the joint angles at the start (radians).")
      .Property(
          "initial_azimuths", [](const ArmModel& a) { return EigenOut(a.initial.azimuth, true); },
          [](ArmModel& a, py::handle v) { a.initial.azimuth = EigenIn<Eigen::VectorXd>(v); },
          "(n,) float64: spherical joints' bend directions at the start (radians), or None.")
      .Finish(false, [](ArmModel& a) { ThrowIfAny(a.Validate()); });

  py::class_<ArmOptions> options(m, "ArmOptions", R"doc(
Options of the fixed-base solver (flexkin::ArmOptions; a robot scenario's "solver").
ArmOptions(method="newton", tolerance=1e-10, max_iterations=100,
           max_fixed_point_iterations=100000, restarts=8, substeps=1, edge_margin=1e-9)
)doc");
  options.def(
      py::init([](const std::string& method, double tolerance, int max_iterations,
                  int max_fixed_point_iterations, int restarts, int substeps, double edge_margin) {
        ArmOptions o;
        o.method = ParseFixedBaseMethod(method);
        o.tolerance = tolerance;
        o.max_iterations = max_iterations;
        o.max_fixed_point_iterations = max_fixed_point_iterations;
        o.restarts = restarts;
        o.substeps = substeps;
        o.edge_margin = edge_margin;
        ThrowIfAny(o.Validate());
        return o;
      }),
      py::kw_only(), py::arg("method") = "newton", py::arg("tolerance") = 1e-10,
      py::arg("max_iterations") = 100, py::arg("max_fixed_point_iterations") = 100000,
      py::arg("restarts") = 8, py::arg("substeps") = 1, py::arg("edge_margin") = 1e-9);
  Fields<ArmOptions>(options, "ArmOptions")
      .Validate("max_iterations")
      .Property(
          "method", [](const ArmOptions& o) { return std::string(FixedBaseMethodName(o.method)); },
          [](ArmOptions& o, py::handle name) {
            o.method = ParseFixedBaseMethod(py::cast<std::string>(name));
          },
          "How the base is brought back after each sweep: 'newton' (default) or 'fixed_point'.",
          true)
      .Member("tolerance", &ArmOptions::tolerance,
              "Base residual at which the solver stops, relative to the mean link length "
              "(default 1e-10).",
              true)
      .Member("max_iterations", &ArmOptions::max_iterations,
              "Newton iterations at most per step (default 100).", true)
      .Member("max_fixed_point_iterations", &ArmOptions::max_fixed_point_iterations,
              "Fixed-point sweeps at most per step (default 100000).", true)
      .Member("restarts", &ArmOptions::restarts,
              "Restarts of a joint-space solve that stalls short of the target (default 8; 0 "
              "none).",
              true)
      .Member("substeps", &ArmOptions::substeps,
              "Straight pieces the end effector's move is split into (default 1).", true)
      .Member("edge_margin", &ArmOptions::edge_margin,
              "Targets beyond (1 - edge_margin) times the reach are out of reach: the arm is "
              "stretched toward them (dimensionless; default 1e-9).",
              true)
      .Finish();

  py::class_<ArmStepReport> step(m, "ArmStepReport", R"doc(
One step of a fixed-base arm (flexkin.arm_step): points (n+1, dim) base first, angles (n,),
azimuths (n,) or None, ee_error, base_error, iterations, sweeps, passes, converged, reached,
stretched, limited, joint_space, legs, restarts. Pass it as `state` to the next arm_step to
continue from it (with the solver's memory, which pickles with it).
)doc");
  Fields<ArmStepReport>(step, "ArmStepReport")
      .Property(
          "points", [](const ArmStepReport& r) { return ToArray(Points(r.state.points)); },
          [](ArmStepReport& r, py::handle v) { r.state.points = py::cast<Points>(v); },
          "(n+1, dim) float64: the link points after the step, base first (length unit).")
      .Property(
          "angles", [](const ArmStepReport& r) { return ToArray(r.state.angles.angle); },
          [](ArmStepReport& r, py::handle v) {
            r.state.angles.angle = EigenIn<Eigen::VectorXd>(v);
          },
          "(n,) float64: the joint angles after the step (radians).")
      .Property(
          "azimuths", [](const ArmStepReport& r) { return EigenOut(r.state.angles.azimuth, true); },
          [](ArmStepReport& r, py::handle v) {
            r.state.angles.azimuth = EigenIn<Eigen::VectorXd>(v);
          },
          "(n,) float64: spherical joints' bend directions (radians), or None.")
      .Member("ee_error", &ArmStepReport::ee_error,
              "|end effector - target| after the step (length unit).")
      .Member("base_error", &ArmStepReport::base_error,
              "The solver's last base residual before the base was re-anchored (length unit).")
      .Member("iterations", &ArmStepReport::iterations,
              "Solver iterations (Newton steps or fixed-point sweeps).")
      .Member("sweeps", &ArmStepReport::sweeps, "Sweeps from the end effector, all included.")
      .Member("passes", &ArmStepReport::passes,
              "Passes over the links (cost ~ passes * n): sweeps done together count once.")
      .Member("converged", &ArmStepReport::converged, "The base residual reached the tolerance.")
      .Member("reached", &ArmStepReport::reached,
              "Converged and ee_error within the tolerance: the target was reached.")
      .Member("stretched", &ArmStepReport::stretched,
              "Out of reach: the arm was stretched straight toward the target.")
      .Member("limited", &ArmStepReport::limited, "A joint limit was active.")
      .Member("joint_space", &ArmStepReport::joint_space,
              "The step was solved in joint space (docs/robots.md).")
      .Member("legs", &ArmStepReport::legs,
              "Legs a far move was tracked in (0: one sweep; docs/robots.md).")
      .Member("restarts", &ArmStepReport::restarts, "Joint-space solves after the first.")
      .Hidden("memory_translation", MemoryGet(&ArmSolverMemory::translation),
              MemorySet(&ArmSolverMemory::translation))
      .Hidden("memory_earlier_translations", MemoryGet(&ArmSolverMemory::earlier_translations),
              MemorySet(&ArmSolverMemory::earlier_translations))
      .Hidden("memory_move_lengths", MemoryGet(&ArmSolverMemory::move_lengths),
              MemorySet(&ArmSolverMemory::move_lengths))
      .Hidden("memory_prediction_error", MemoryGet(&ArmSolverMemory::prediction_error),
              MemorySet(&ArmSolverMemory::prediction_error))
      .Finish(false);
  step.def("brief_report", &ArmStepReport::BriefReport,
           "One line: reached or not, errors, iterations, sweeps, flags.");
  step.def(
      "__repr__", [](const ArmStepReport& r) { return "ArmStepReport(" + r.BriefReport() + ")"; },
      "ArmStepReport(<brief report>).");

  m.def(
      "forward_kinematics",
      [](ModelObject model, ArrayLike angles, OptionalArray azimuths) {
        const ArmModel& a = ModelArg(model);
        return ToArray(ForwardKinematics(a, AnglesArg(a, angles, azimuths)));
      },
      py::arg("model"), py::arg("angles"), py::arg("azimuths") = py::none(),
      "The (n+1, dim) float64 points (base first, length unit) of the arm at the joint angles "
      "(n,) (radians; and azimuths (n,) for spherical joints).");
  m.def(
      "joint_angles_from_points",
      [](ModelObject model, ArrayLike points) {
        const ArmModel& a = ModelArg(model);
        const Points p = ReadPoints(points, "points", a.num_links() + 1, a.dim);
        if (p.rows() != a.num_links() + 1) {
          ThrowInput("points", "has " + std::to_string(p.rows()) + " rows; expected " +
                                   std::to_string(a.num_links() + 1) + " (n+1)");
        }
        const JointAngles angles = JointAnglesFromPoints(a, p);
        return py::make_tuple(ToArray(angles.angle), AzimuthsOrNone(angles.azimuth));
      },
      py::arg("model"), py::arg("points"),
      "The joint angles (angles (n,), azimuths (n,) or None; radians) of the arm whose points "
      "(n+1, dim) (base first) are given.");
  m.def(
      "joint_quaternions",
      [](ModelObject model, ArrayLike angles, OptionalArray azimuths) {
        const ArmModel& a = ModelArg(model);
        return ToArray(Points(JointQuaternions(a, AnglesArg(a, angles, azimuths))));
      },
      py::arg("model"), py::arg("angles"), py::arg("azimuths") = py::none(),
      "Each joint's rotation as a unit quaternion in the frame of the link before it: an (n, 4) "
      "float64 array of rows (w, x, y, z), scalar first, at the joint angles (n,) (radians; and "
      "azimuths (n,) for spherical joints). Planar arms: rotations about z.");
  m.def(
      "within_limits",
      [](ModelObject model, ArrayLike angles, OptionalArray azimuths, double slack) {
        const ArmModel& a = ModelArg(model);
        const JointAngles joint = AnglesArg(a, angles, azimuths, false);
        return WithinLimits(a, joint, CheckFinite(slack, "slack"));
      },
      py::arg("model"), py::arg("angles"), py::arg("azimuths") = py::none(), py::kw_only(),
      py::arg("slack") = 0.0,
      "Whether every joint angle (n,) (radians) is within the model's limits, with `slack` "
      "radians of tolerance (default 0). True for a model without limits.");
  m.def(
      "arm_step",
      [](ModelObject model, ArrayLike target, StepState state, ArmOptionsLike options) {
        const ArmModel& a = ModelArg(model);
        ThrowIfAny(a.Validate());
        const Eigen::VectorXd t = ReadVector(target, "target", a.dim);
        const ArmOptions o = OptionsArg<ArmOptions>(options, "options");
        if (!state.is_none() && !py::isinstance<ArmStepReport>(state)) {
          const std::string type = py::str(py::type::of(state).attr("__name__"));
          ThrowInput("state",
                     "is a " + type + "; expected None or the ArmStepReport of the last step", type,
                     "ArmStepReport");
        }
        ArmState s =
            state.is_none() ? InitialState(a) : py::cast<const ArmStepReport&>(state).state;
        py::gil_scoped_release release;
        return ArmStep(a, s, t, o);
      },
      py::arg("model"), py::arg("target"), py::kw_only(), py::arg("state") = py::none(),
      py::arg("options") = py::none(),
      "Moves the end effector to target (dim,) with the base held, from `state` (the "
      "ArmStepReport of the previous step; None: the model's initial angles). options: "
      "ArmOptions, a dict of its fields or None. Returns an ArmStepReport.");
  m.def(
      "track_path",
      [](ModelObject model, ArrayLike path, ArmOptionsLike options, ProgressCallback progress,
         OptionalPath output, OptionalPath csv) {
        RobotScenario s;
        s.model = ModelArg(model);
        ThrowIfAny(s.model.Validate());
        s.path = ReadPoints(path, "path", 1, s.model.dim);
        s.options = OptionsArg<ArmOptions>(options, "options");
        return TrackToResult(s, std::move(progress), output, csv);
      },
      py::arg("model"), py::arg("path"), py::kw_only(), py::arg("options") = py::none(),
      py::arg("progress") = py::none(), py::arg("output") = py::none(), py::arg("csv") = py::none(),
      R"doc(
Tracks a path of end-effector targets from the model's initial state, one arm_step per row,
with the GIL released. Returns a RobotResult.

track_path(model, path, *, options=None, progress=None, output=None, csv=None)
  model: ArmModel.  path: (T, dim) targets (length unit), T >= 1.
  options: ArmOptions, a dict of its fields or None (the defaults).
  progress: callable(done, total) called about every 0.1 s with the targets done.
  output: a path: also write the trajectory JSON there (docs/robot-format.md), streamed.
  csv: a path: also write the joint angles as CSV there.
The files are written whole or not at all (Ctrl-C, an error: no file, an existing one left
untouched). Ctrl-C raises KeyboardInterrupt within about 0.1 s.
)doc");
}

}  // namespace flexkin::python
