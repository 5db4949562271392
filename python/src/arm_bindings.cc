// Fixed-base arms from Python: flexkin.ArmModel, ArmOptions, ArmStepReport, forward_kinematics,
// joint_angles_from_points, arm_step and track_path (flexkin/arm.h; robot order, base first).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "convert.h"
#include "fields.h"
#include "flexkin/arm.h"
#include "flexkin/curves.h"

namespace flexkin::python {
namespace {

// An optional (n,) or (n, 3) argument: empty when None.
Eigen::VectorXd OptionalVector(py::handle object, const std::string& name, int size) {
  if (object.is_none()) return Eigen::VectorXd();
  return ReadArray(object, name, 1, 1, 0, size).cast<Eigen::VectorXd>();
}
// An optional (n,) argument whose values may be infinite (limits: -inf/inf for none) but not
// NaN; the model's Validate checks the rest.
Eigen::VectorXd OptionalLimits(py::handle object, const std::string& name, int size) {
  if (object.is_none()) return Eigen::VectorXd();
  return ReadArray(object, name, 1, 1, 0, size, true).cast<Eigen::VectorXd>();
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

// Joint types from names ("revolute", "prismatic"), field joint_types[j].
std::vector<JointType> JointTypesArg(const std::vector<std::string>& names) {
  std::vector<JointType> types;
  for (size_t j = 0; j < names.size(); ++j) {
    types.push_back(ParseName<JointType>(names[j], "joint_types[" + std::to_string(j) + "]"));
  }
  return types;
}
// The joint types by name: n names for an arm with joint axes (every joint revolute where the
// model lists none), [] for other arms.
std::vector<std::string> JointTypeNames(const ArmModel& a) {
  std::vector<std::string> names;
  if (!a.has_axes()) return names;
  for (int j = 0; j < a.num_links(); ++j)
    names.emplace_back(NameOf(a.prismatic(j) ? JointType::kPrismatic : JointType::kRevolute));
  return names;
}

// The Python names of ArmOptions' pointing members (flat keywords).
std::string PythonOptionField(const std::string& field) {
  static const std::pair<const char*, const char*> kNames[] = {
      {"pointing.axis", "pointing_axis"},
      {"pointing.direction", "pointing_direction"},
      {"pointing.point", "look_at"},
      {"pointing.weight", "pointing_weight"},
      {"pointing.angle_tolerance", "pointing_tolerance"}};
  for (const auto& [cc, py] : kNames) {
    if (field == cc) return py;
  }
  return field;
}
Problems PythonOptionProblems(Problems problems) {
  for (Problem& p : problems) p.field = PythonOptionField(p.field);
  return problems;
}

// A (3,) vector argument of the pointing options; `name` in errors.
Eigen::Vector3d Vector3Arg(py::handle object, const std::string& name) {
  return ReadVector(object, name, 3);
}

// Sets the pointing direction (None: pointing off unless it looks at a point). Refused while
// look_at is set: the two exclude each other.
void SetPointingDirection(ArmOptions& o, py::handle value) {
  ArmOptions::Pointing& p = o.pointing;
  if (value.is_none()) {
    if (!p.look_at) p.enabled = false;
    return;
  }
  if (p.enabled && p.look_at) {
    ThrowInput("pointing_direction",
               "is given together with look_at; expected one of pointing_direction (a direction "
               "to point along) and look_at (a point to look at)");
  }
  p.direction = Vector3Arg(value, "pointing_direction");
  p.enabled = true;
  p.look_at = false;
}
void SetLookAt(ArmOptions& o, py::handle value) {
  ArmOptions::Pointing& p = o.pointing;
  if (value.is_none()) {
    if (p.look_at) p.enabled = false;
    p.look_at = false;
    return;
  }
  if (p.enabled && !p.look_at) {
    ThrowInput("look_at",
               "is given together with pointing_direction; expected one of pointing_direction (a "
               "direction to point along) and look_at (a point to look at)");
  }
  p.point = Vector3Arg(value, "look_at");
  p.enabled = true;
  p.look_at = true;
}

}  // namespace

void ThrowIfAnyArmOptions(const ArmOptions& options) {
  ThrowIfAny(PythonOptionProblems(options.Validate()));
}

const ArmModel& ModelArg(py::handle model) {
  if (!py::isinstance<ArmModel>(model)) {
    const std::string type = py::str(py::type::of(model).attr("__name__"));
    ThrowInput("model", "is a " + type + "; expected a flexkin.ArmModel", type, "ArmModel");
  }
  return py::cast<const ArmModel&>(model);
}

namespace {

// The (n+1, dim) points of the arm `a` (base first), as forward_kinematics gives them.
Points ArmPointsArg(const ArmModel& a, ArrayLike points) {
  const Points p = ReadPoints(points, "points", a.num_links() + 1, a.dim);
  if (p.rows() != a.num_links() + 1) {
    ThrowInput("points", "has " + std::to_string(p.rows()) + " rows; expected " +
                             std::to_string(a.num_links() + 1) + " (n+1)");
  }
  return p;
}

}  // namespace

void BindArms(py::module_& m) {
  py::class_<ArmModel> model(m, "ArmModel", R"doc(
A fixed-base arm (flexkin::ArmModel, docs/robots.md), robot order: link 1 at the base.

ArmModel(link_lengths, *, dim=2, base=None, base_direction=None, joint_min=None,
         joint_max=None, max_bend=None, joint_axes=None, link_directions=None,
         initial_angles=None, initial_azimuths=None, joint_types=None, max_velocity=None,
         tip_rotation=None, joint_names=None)
  link_lengths: (n,) positive (with joint_axes a link may have length 0: joints at one point,
    as long as the sum is positive); base: (dim,) where the base is bolted (default the origin);
  base_direction: (dim,) the direction of "link 0" (default +x);
  joint_min, joint_max: (n,) joint limits: planar arms in [-pi, pi] (rad); with joint_axes as
    written (rad, or length unit for prismatic joints; -inf/+inf for continuous joints);
  max_bend: (n,) spherical limits;
  joint_axes, link_directions: (n, 3) spatial joints about/along axes (URDF arms);
  initial_angles, initial_azimuths: (n,) the start (default 0);
  joint_types: n of "revolute", "prismatic" (with joint_axes; default every joint revolute);
  max_velocity: (n,) joint speed limits (rad/s or length unit/s; inf: none), used where
    ArmOptions.time_step > 0 (planar arms and arms with joint_axes);
  tip_rotation: (4,) unit quaternion w, x, y, z: the tool frame in the last link's frame
    (with joint_axes; default the identity);
  joint_names: n str, the joints' names in reports (default "joint 0", "joint 1", ...).
Planar arms (dim 2) have revolute joints, arms with joint_axes revolute and prismatic ones,
other spatial arms spherical.
)doc");
  model
      .def(
          py::init([](ArrayLike link_lengths, int dim, OptionalArray base, OptionalArray direction,
                      OptionalArray joint_min, OptionalArray joint_max, OptionalArray max_bend,
                      OptionalArray joint_axes, OptionalArray link_directions, OptionalArray angles,
                      OptionalArray azimuths, std::optional<std::vector<std::string>> joint_types,
                      OptionalArray max_velocity, OptionalArray tip_rotation,
                      std::optional<std::vector<std::string>> joint_names) {
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
            a.joint_min = OptionalLimits(joint_min, "joint_min", n);
            a.joint_max = OptionalLimits(joint_max, "joint_max", n);
            a.max_bend = OptionalVector(max_bend, "max_bend", n);
            a.joint_axes = OptionalRows(joint_axes, "joint_axes", n);
            a.link_directions = OptionalRows(link_directions, "link_directions", n);
            const bool spherical = dim == 3 && a.joint_axes.size() == 0;
            a.initial.angle = angles.is_none() ? Eigen::VectorXd::Zero(n)
                                               : OptionalVector(angles, "initial_angles", n);
            a.initial.azimuth = azimuths.is_none()
                                    ? (spherical ? Eigen::VectorXd::Zero(n) : Eigen::VectorXd())
                                    : OptionalVector(azimuths, "initial_azimuths", n);
            if (joint_types) a.joint_types = JointTypesArg(*joint_types);
            a.max_velocity = OptionalLimits(max_velocity, "max_velocity", n);
            if (!tip_rotation.is_none())
              a.tip_rotation = ReadVector(tip_rotation, "tip_rotation", 4);
            if (joint_names) a.joint_names = *joint_names;
            ThrowIfAny(a.Validate());
            return a;
          }),
          py::arg("link_lengths"), py::kw_only(), py::arg("dim") = 2, py::arg("base") = py::none(),
          py::arg("base_direction") = py::none(), py::arg("joint_min") = py::none(),
          py::arg("joint_max") = py::none(), py::arg("max_bend") = py::none(),
          py::arg("joint_axes") = py::none(), py::arg("link_directions") = py::none(),
          py::arg("initial_angles") = py::none(), py::arg("initial_azimuths") = py::none(),
          py::arg("joint_types") = py::none(), py::arg("max_velocity") = py::none(),
          py::arg("tip_rotation") = py::none(), py::arg("joint_names") = py::none())
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
             "(n,) float64: joint lower limits, or None (no limits): radians, >= -pi on planar "
             "arms; with joint_axes as written (radians, or length unit for prismatic joints; "
             "-inf for a continuous joint).",
             true)
      .Array("joint_max", &ArmModel::joint_max,
             "(n,) float64: joint upper limits (radians, <= pi on planar arms; with joint_axes as "
             "written, +inf for a continuous joint), or None.",
             true)
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
          "joint_types", &JointTypeNames,
          [](ArmModel& a, py::handle v) {
            a.joint_types = JointTypesArg(py::cast<std::vector<std::string>>(v));
          },
          "list of str: each joint's type, 'revolute' or 'prismatic' (arms with joint_axes; "
          "[] for planar and spherical arms).")
      .Array("max_velocity", &ArmModel::max_velocity,
             "(n,) float64: joint speed limits (radians/s, or length unit/s for prismatic "
             "joints; inf: none), used where ArmOptions.time_step > 0; or None (no limits).",
             true)
      .Property(
          "tip_rotation",
          [](const ArmModel& a) { return ToArray(Eigen::VectorXd(a.tip_rotation)); },
          [](ArmModel& a, py::handle v) { a.tip_rotation = ReadVector(v, "tip_rotation", 4); },
          "(4,) float64: the tool frame in the last link's frame, a unit quaternion (w, x, y, "
          "z) (arms with joint_axes; the pointing axis is given in it).")
      .Member("joint_names", &ArmModel::joint_names,
              "list of str: the joints' names (a URDF's), or [] (reports say \"joint 0\", ...).")
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
Options of the fixed-base solver (flexkin::ArmOptions; a robot scenario's "solver", and its
"pointing").
ArmOptions(method="newton", tolerance=1e-10, max_iterations=100,
           max_fixed_point_iterations=100000, restarts=8, substeps=1, edge_margin=1e-9,
           time_step=0.0, pointing_axis=None, pointing_direction=None, look_at=None,
           pointing_weight=1.0, pointing_tolerance=1e-9)
  time_step: the time between two path points (s) for ArmModel.max_velocity; 0: limits ignored.
Pointing (arms with joint_axes, method newton): a tool axis is turned along a direction or
toward a point as the end effector tracks its target. Pointing is on where pointing_direction
or look_at is given (not both: InputError).
  pointing_axis: (3,) the axis in the tool frame (ArmModel.tip_rotation; default +x).
  pointing_direction: (3,) the world direction to point along, non-zero; or
  look_at: (3,) the point to look at.
  pointing_weight: > 0, mean link lengths per radian of angular miss (default 1).
  pointing_tolerance: the angle (rad) within which a step counts as pointed (default 1e-9).
)doc");
  options.def(
      py::init([](const std::string& method, double tolerance, int max_iterations,
                  int max_fixed_point_iterations, int restarts, int substeps, double edge_margin,
                  double time_step, OptionalArray pointing_axis, OptionalArray pointing_direction,
                  OptionalArray look_at, double pointing_weight, double pointing_tolerance) {
        ArmOptions o;
        o.method = ParseFixedBaseMethod(method);
        o.tolerance = tolerance;
        o.max_iterations = max_iterations;
        o.max_fixed_point_iterations = max_fixed_point_iterations;
        o.restarts = restarts;
        o.substeps = substeps;
        o.edge_margin = edge_margin;
        o.time_step = time_step;
        if (!pointing_direction.is_none() && !look_at.is_none()) {
          ThrowInput("pointing_direction",
                     "and look_at are both given; expected one of them (a direction to point "
                     "along, or a point to look at)");
        }
        if (!pointing_axis.is_none()) o.pointing.axis = Vector3Arg(pointing_axis, "pointing_axis");
        SetPointingDirection(o, pointing_direction);
        SetLookAt(o, look_at);
        o.pointing.weight = pointing_weight;
        o.pointing.angle_tolerance = pointing_tolerance;
        ThrowIfAnyArmOptions(o);
        return o;
      }),
      py::kw_only(), py::arg("method") = "newton", py::arg("tolerance") = 1e-10,
      py::arg("max_iterations") = 100, py::arg("max_fixed_point_iterations") = 100000,
      py::arg("restarts") = 8, py::arg("substeps") = 1, py::arg("edge_margin") = 1e-9,
      py::arg("time_step") = 0.0, py::arg("pointing_axis") = py::none(),
      py::arg("pointing_direction") = py::none(), py::arg("look_at") = py::none(),
      py::arg("pointing_weight") = 1.0, py::arg("pointing_tolerance") = 1e-9);
  options.def(
      "validate", [](const ArmOptions& o) { ThrowIfAnyArmOptions(o); },
      "Raises InputError for the first problem, naming the member ('max_iterations', "
      "'pointing_direction'); returns None if there is none.");
  Fields<ArmOptions>(options, "ArmOptions")
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
      .Member("time_step", &ArmOptions::time_step,
              "The time between two path points (float, seconds) for the model's max_velocity: "
              "a step that would exceed a limit is split into legs (default 0: limits ignored).",
              true)
      .Property(
          "pointing_axis",
          [](const ArmOptions& o) { return ToArray(Eigen::VectorXd(o.pointing.axis)); },
          [](ArmOptions& o, py::handle v) { o.pointing.axis = Vector3Arg(v, "pointing_axis"); },
          "(3,) float64: the tool axis that pointing turns, in the tool frame "
          "(ArmModel.tip_rotation; default +x).",
          true)
      .Property(
          "pointing_direction",
          [](const ArmOptions& o) {
            return o.pointing.enabled && !o.pointing.look_at
                       ? py::object(ToArray(Eigen::VectorXd(o.pointing.direction)))
                       : py::object(py::none());
          },
          &SetPointingDirection,
          "(3,) float64: the world direction the tool axis points along, or None (setting it "
          "turns pointing on; refused while look_at is set).",
          true)
      .Property(
          "look_at",
          [](const ArmOptions& o) {
            return o.pointing.enabled && o.pointing.look_at
                       ? py::object(ToArray(Eigen::VectorXd(o.pointing.point)))
                       : py::object(py::none());
          },
          &SetLookAt,
          "(3,) float64: the point the tool axis looks at, or None (setting it turns pointing "
          "on; refused while pointing_direction is set).",
          true)
      .Property(
          "pointing_weight", [](const ArmOptions& o) { return o.pointing.weight; },
          [](ArmOptions& o, py::handle v) { o.pointing.weight = py::cast<double>(v); },
          "float > 0: mean link lengths per radian of angular miss (default 1).", true)
      .Property(
          "pointing_tolerance", [](const ArmOptions& o) { return o.pointing.angle_tolerance; },
          [](ArmOptions& o, py::handle v) { o.pointing.angle_tolerance = py::cast<double>(v); },
          "float: the angle (radians) within which a pointed step counts as reached (default "
          "1e-9).",
          true)
      .Finish();

  py::class_<ArmStepReport> step(m, "ArmStepReport", R"doc(
One step of a fixed-base arm (flexkin.arm_step): points (n+1, dim) base first, angles (n,),
azimuths (n,) or None, ee_error, base_error, iterations, sweeps, passes, converged, reached,
stretched, limited, joint_space, legs, restarts, pointing_error, velocity_legs, velocity_ratio.
Pass it as `state` to the next arm_step to
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
      .Member("pointing_error", &ArmStepReport::pointing_error,
              "float: with pointing, the angle (radians) between the tool axis and where it "
              "should point; 0 without.")
      .Member("velocity_legs", &ArmStepReport::velocity_legs,
              "int: with time_step, the legs the step took to keep every joint within its "
              "velocity limit (1: as asked); 0 without.")
      .Member("velocity_ratio", &ArmStepReport::velocity_ratio,
              "float: with time_step, the largest joint speed over its limit in any leg (<= 1: "
              "limits kept); 0 without.")
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
        const Points p = ArmPointsArg(a, points);
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
      "joint_groups", [](ModelObject model) { return JointGroups(ModelArg(model)); },
      py::arg("model"),
      "The joints of each distinct point of the chain, base first: a list of lists of int "
      "(joint indices). Joints joined by links of length 0 share a point (two revolute joints: "
      "a universal joint, three: a spherical one); a prismatic joint ends its group; the last "
      "group may hold the tip (a tip on its joint).");
  m.def(
      "chain_points",
      [](ModelObject model, ArrayLike points) {
        const ArmModel& a = ModelArg(model);
        const Points p = ArmPointsArg(a, points);
        return ToArray(ChainPoints(a, p));
      },
      py::arg("model"), py::arg("points"),
      "The chain as drawn and written to files: of the arm's (n+1, dim) points (base first, as "
      "forward_kinematics gives them), one per joint group (joint_groups) plus the end effector "
      "where it is a point of its own; a (g, dim) float64 array.");
  m.def(
      "joint_groups_report", [](ModelObject model) { return JointGroupsReport(ModelArg(model)); },
      py::arg("model"),
      "The joint groups of more than one joint in words, one per line (str; 'joints \"m1_pitch\" "
      "and \"m1_yaw\" act at one point (a universal joint)'); '' if every joint has its own "
      "point.");
  m.def(
      "tool_pose",
      [](ModelObject model, ArrayLike angles) {
        const ArmModel& a = ModelArg(model);
        if (!a.has_axes()) {
          ThrowInput("model",
                     "has no joint axes; the tool frame is defined for arms with joint_axes "
                     "(URDF arms)");
        }
        const ToolPose pose = ToolPoseAt(a, AnglesArg(a, angles, py::none()));
        return py::make_tuple(ToArray(Eigen::VectorXd(pose.position)),
                              ToArray(Points(pose.rotation)));
      },
      py::arg("model"), py::arg("angles"),
      "The tool frame of an arm with joint_axes at the joint values angles (n,) (radians, or "
      "length unit for prismatic joints): a tuple (position (3,) float64, the end effector; "
      "rotation (3, 3) float64, the tip link's frame in the world, its columns the tool axes; "
      "ArmModel.tip_rotation in the last link's frame).");
  m.def(
      "arm_step",
      [](ModelObject model, ArrayLike target, StepState state, ArmOptionsLike options) {
        const ArmModel& a = ModelArg(model);
        ThrowIfAny(a.Validate());
        const Eigen::VectorXd t = ReadVector(target, "target", a.dim);
        const ArmOptions o = OptionsArg<ArmOptions>(options, "options");
        ThrowIfAnyArmOptions(o);
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
        ThrowIfAnyArmOptions(s.options);
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
