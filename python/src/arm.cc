// Fixed-base arms from Python: flexkin.ArmModel, ArmOptions, ArmStepReport, forward_kinematics,
// joint_angles_from_points, arm_step and track_path (flexkin/arm.h; robot order, base first).
#include "flexkin/arm.h"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <string>

#include "convert.h"

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

JointAngles AnglesArg(const ArmModel& model, py::handle angles, py::handle azimuths) {
  JointAngles a;
  a.angle = ReadArray(angles, "angles", 1, 1, 0, model.num_links()).cast<Eigen::VectorXd>();
  a.azimuth = OptionalVector(azimuths, "azimuths", model.num_links());
  return a;
}

py::object AzimuthsOrNone(const Eigen::VectorXd& azimuth) {
  return azimuth.size() > 0 ? py::object(ToArray(azimuth)) : py::none();
}

std::string ArmOptionsRepr(const ArmOptions& o) {
  return "ArmOptions(method=" + Quoted(FixedBaseMethodName(o.method)) +
         ", tolerance=" + Num(o.tolerance) +
         ", max_iterations=" + std::to_string(o.max_iterations) +
         ", max_fixed_point_iterations=" + std::to_string(o.max_fixed_point_iterations) +
         ", restarts=" + std::to_string(o.restarts) + ", substeps=" + std::to_string(o.substeps) +
         ", edge_margin=" + Num(o.edge_margin) + ")";
}

ArmOptions OptionsArg(py::handle options) {
  if (options.is_none()) return ArmOptions();
  if (!py::isinstance<ArmOptions>(options)) {
    ThrowInput("options", "is not an ArmOptions; expected flexkin.ArmOptions or None");
  }
  return py::cast<ArmOptions>(options);
}

}  // namespace

void BindArms(py::module_& m) {
  py::class_<ArmModel>(m, "ArmModel", R"doc(
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
)doc")
      .def(py::init([](py::handle link_lengths, int dim, py::handle base, py::handle direction,
                       py::handle joint_min, py::handle joint_max, py::handle max_bend,
                       py::handle joint_axes, py::handle link_directions, py::handle angles,
                       py::handle azimuths) {
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
      .def_static("straight", &StraightArm, py::arg("dim"), py::arg("links"),
                  py::arg("link_length"),
                  "A straight arm of `links` links from the origin along +x, no limits.")
      .def_readonly("dim", &ArmModel::dim)
      .def_property_readonly("link_lengths",
                             [](const ArmModel& a) { return ToArray(a.link_lengths); })
      .def_property_readonly("base", [](const ArmModel& a) { return ToArray(a.base); })
      .def_property_readonly("base_direction",
                             [](const ArmModel& a) { return ToArray(a.base_direction); })
      .def_property_readonly("initial_angles",
                             [](const ArmModel& a) { return ToArray(a.initial.angle); })
      .def_property_readonly("initial_azimuths",
                             [](const ArmModel& a) { return AzimuthsOrNone(a.initial.azimuth); })
      .def_property_readonly("joint", [](const ArmModel& a) { return NameOf(a.joint()); })
      .def_property_readonly("num_links", &ArmModel::num_links)
      .def_property_readonly("reach", &ArmModel::reach)
      .def_property_readonly("has_limits", &ArmModel::has_limits)
      .def("__repr__",
           [](const ArmModel& a) {
             return "ArmModel(" + std::to_string(a.dim) + "D " + NameOf(a.joint()) + ", " +
                    std::to_string(a.num_links()) + " links, reach " + Num(a.reach()) +
                    (a.has_limits() ? ", with limits" : "") + ")";
           })
      .def(py::pickle(
          [](const ArmModel& a) {
            return py::make_tuple(a.dim, a.link_lengths, a.base, a.base_direction, a.joint_min,
                                  a.joint_max, a.max_bend, a.joint_axes, a.link_directions,
                                  a.initial.angle, a.initial.azimuth);
          },
          [](const py::tuple& state) {
            StateTuple(state, 11, "ArmModel");
            ArmModel a;
            a.dim = py::cast<int>(state[0]);
            a.link_lengths = py::cast<Eigen::VectorXd>(state[1]);
            a.base = py::cast<Eigen::VectorXd>(state[2]);
            a.base_direction = py::cast<Eigen::VectorXd>(state[3]);
            a.joint_min = py::cast<Eigen::VectorXd>(state[4]);
            a.joint_max = py::cast<Eigen::VectorXd>(state[5]);
            a.max_bend = py::cast<Eigen::VectorXd>(state[6]);
            a.joint_axes = py::cast<Eigen::MatrixXd>(state[7]);
            a.link_directions = py::cast<Eigen::MatrixXd>(state[8]);
            a.initial.angle = py::cast<Eigen::VectorXd>(state[9]);
            a.initial.azimuth = py::cast<Eigen::VectorXd>(state[10]);
            ThrowIfAny(a.Validate());
            return a;
          }));

  py::class_<ArmOptions>(m, "ArmOptions", R"doc(
Options of the fixed-base solver (flexkin::ArmOptions; a robot scenario's "solver").
ArmOptions(method="newton", tolerance=1e-10, max_iterations=100,
           max_fixed_point_iterations=100000, restarts=8, substeps=1, edge_margin=1e-9)
)doc")
      .def(py::init([](const std::string& method, double tolerance, int max_iterations,
                       int max_fixed_point_iterations, int restarts, int substeps,
                       double edge_margin) {
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
           py::arg("restarts") = 8, py::arg("substeps") = 1, py::arg("edge_margin") = 1e-9)
      .def_property(
          "method", [](const ArmOptions& o) { return FixedBaseMethodName(o.method); },
          [](ArmOptions& o, const std::string& name) { o.method = ParseFixedBaseMethod(name); })
      .def_readwrite("tolerance", &ArmOptions::tolerance)
      .def_readwrite("max_iterations", &ArmOptions::max_iterations)
      .def_readwrite("max_fixed_point_iterations", &ArmOptions::max_fixed_point_iterations)
      .def_readwrite("restarts", &ArmOptions::restarts)
      .def_readwrite("substeps", &ArmOptions::substeps)
      .def_readwrite("edge_margin", &ArmOptions::edge_margin)
      .def("__repr__", &ArmOptionsRepr)
      .def(py::pickle(
          [](const ArmOptions& o) {
            return py::make_tuple(std::string(FixedBaseMethodName(o.method)), o.tolerance,
                                  o.max_iterations, o.max_fixed_point_iterations, o.restarts,
                                  o.substeps, o.edge_margin);
          },
          [](const py::tuple& state) {
            StateTuple(state, 7, "ArmOptions");
            ArmOptions o;
            o.method = ParseFixedBaseMethod(py::cast<std::string>(state[0]));
            o.tolerance = py::cast<double>(state[1]);
            o.max_iterations = py::cast<int>(state[2]);
            o.max_fixed_point_iterations = py::cast<int>(state[3]);
            o.restarts = py::cast<int>(state[4]);
            o.substeps = py::cast<int>(state[5]);
            o.edge_margin = py::cast<double>(state[6]);
            return o;
          }));

  py::class_<ArmStepReport>(m, "ArmStepReport", R"doc(
One step of a fixed-base arm (flexkin.arm_step): points (n+1, dim) base first, angles (n,),
azimuths (n,) or None, ee_error, base_error, iterations, sweeps, passes, converged, reached,
stretched, limited, joint_space, legs, restarts. Pass it as `state` to the next arm_step to
continue from it (with the solver's memory).
)doc")
      .def_property_readonly("points",
                             [](const ArmStepReport& r) { return ToArray(Points(r.state.points)); })
      .def_property_readonly("angles",
                             [](const ArmStepReport& r) { return ToArray(r.state.angles.angle); })
      .def_property_readonly(
          "azimuths", [](const ArmStepReport& r) { return AzimuthsOrNone(r.state.angles.azimuth); })
      .def_readonly("ee_error", &ArmStepReport::ee_error)
      .def_readonly("base_error", &ArmStepReport::base_error)
      .def_readonly("iterations", &ArmStepReport::iterations)
      .def_readonly("sweeps", &ArmStepReport::sweeps)
      .def_readonly("passes", &ArmStepReport::passes)
      .def_readonly("converged", &ArmStepReport::converged)
      .def_readonly("reached", &ArmStepReport::reached)
      .def_readonly("stretched", &ArmStepReport::stretched)
      .def_readonly("limited", &ArmStepReport::limited)
      .def_readonly("joint_space", &ArmStepReport::joint_space)
      .def_readonly("legs", &ArmStepReport::legs)
      .def_readonly("restarts", &ArmStepReport::restarts)
      .def("brief_report", &ArmStepReport::BriefReport)
      .def("__repr__",
           [](const ArmStepReport& r) { return "ArmStepReport(" + r.BriefReport() + ")"; });

  m.def(
      "forward_kinematics",
      [](const ArmModel& model, py::handle angles, py::handle azimuths) {
        return ToArray(ForwardKinematics(model, AnglesArg(model, angles, azimuths)));
      },
      py::arg("model"), py::arg("angles"), py::arg("azimuths") = py::none(),
      "The (n+1, dim) points (base first) of the arm at the joint angles (n,) (and azimuths "
      "(n,) for spherical joints).");
  m.def(
      "joint_angles_from_points",
      [](const ArmModel& model, py::handle points) {
        const Points p = ReadPoints(points, "points", model.num_links() + 1, model.dim);
        if (p.rows() != model.num_links() + 1) {
          ThrowInput("points", "has " + std::to_string(p.rows()) + " rows; expected " +
                                   std::to_string(model.num_links() + 1) + " (n+1)");
        }
        const JointAngles a = JointAnglesFromPoints(model, p);
        return py::make_tuple(ToArray(a.angle), AzimuthsOrNone(a.azimuth));
      },
      py::arg("model"), py::arg("points"),
      "The joint angles (angles, azimuths or None) of the arm whose points (base first) are "
      "given.");
  m.def(
      "arm_step",
      [](const ArmModel& model, py::handle target, py::object state, py::handle options) {
        ThrowIfAny(model.Validate());
        const Eigen::VectorXd t = ReadVector(target, "target", model.dim);
        const ArmOptions o = OptionsArg(options);
        ArmState s =
            state.is_none() ? InitialState(model) : py::cast<const ArmStepReport&>(state).state;
        py::gil_scoped_release release;
        return ArmStep(model, s, t, o);
      },
      py::arg("model"), py::arg("target"), py::kw_only(), py::arg("state") = py::none(),
      py::arg("options") = py::none(),
      "Moves the end effector to target (dim,) with the base held, from `state` (the "
      "ArmStepReport of the previous step; None: the model's initial angles). Returns an "
      "ArmStepReport.");
  m.def(
      "track_path",
      [](const ArmModel& model, py::handle path, py::handle options) {
        ThrowIfAny(model.Validate());
        const Points p = ReadPoints(path, "path", 1, model.dim);
        return TrackToResult(model, p, OptionsArg(options), "");
      },
      py::arg("model"), py::arg("path"), py::kw_only(), py::arg("options") = py::none(),
      "Tracks the path (T, dim) of end-effector targets from the model's initial state, one "
      "arm_step per row, with the GIL released. Returns a RobotResult.");
}

}  // namespace flexkin::python
