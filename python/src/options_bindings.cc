// Option and report classes: flexkin.ObjectiveWeights, OverallOptions, RunOptions (inputs, with
// the C++ field names), Metrics, AccuracyReport, OverallRunReport, OverallReport (outputs, read
// only), and flexkin.overall_objective. Every class prints readably, compares and pickles
// (fields.h).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <string>

#include "convert.h"
#include "fields.h"
#include "flexkin/overall.h"
#include "flexkin/run.h"
#include "flexkin/scenario.h"

namespace flexkin::python {

RunOptions MakeRunOptions(const std::string& method, int substeps, int record_every,
                          double tolerance, int max_substeps, bool link_angles, OverallLike overall,
                          CollidersLike colliders, double link_radius) {
  RunOptions o;
  o.colliders = CollidersArg(colliders);
  o.link_radius = link_radius;
  o.method = MethodArg(method);
  o.substeps = substeps;
  o.record_every = record_every;
  o.tolerance = tolerance;
  o.max_substeps = max_substeps;
  o.link_angles = link_angles;
  o.overall = OverallArg(overall);
  return o;
}

std::vector<Collider> CollidersArg(py::handle colliders) {
  if (colliders.is_none()) return {};
  if (!py::isinstance<py::list>(colliders) && !py::isinstance<py::tuple>(colliders)) {
    ThrowInput("colliders",
               "is not a list; expected a list of dicts in the form of a scenario's "
               "\"colliders\" (docs/scenario-format.md), or None");
  }
  return ParseCollidersText(JsonOfDict(colliders, "colliders"));
}

py::object CollidersValue(const std::vector<Collider>& colliders) {
  return py::module_::import("json").attr("loads")(CollidersText(colliders, 3));
}

namespace {

std::string WeightsRepr(const ObjectiveWeights& w) {
  std::string text = "ObjectiveWeights(";
  bool first = true;
  for (const auto& entry : Vocabulary<ObjectiveTerm>::kEntries) {
    if (w[entry.value] == 0.0) continue;
    text += (first ? "" : ", ") + std::string(entry.name) + "=" + Num(w[entry.value]);
    first = false;
  }
  return text + ")";
}

// Weights from keyword arguments named as the objective terms (scenario files' "objective"):
// with any given, the terms not given are 0; with none, the C++ default (squared = 1).
ObjectiveWeights WeightsFromKwargs(const py::kwargs& terms) {
  ObjectiveWeights w;
  if (terms.empty()) return w;
  for (const auto& entry : Vocabulary<ObjectiveTerm>::kEntries) w[entry.value] = 0.0;
  for (const auto& [key, value] : terms) {
    const std::string name = py::str(key);
    const auto* entry = FindName<ObjectiveTerm>(name);
    if (entry == nullptr) {
      throw InputError(
          UnknownName(name, Vocabulary<ObjectiveTerm>::kKind, name, NamesOf<ObjectiveTerm>()));
    }
    w[entry->value] = CheckFinite(py::cast<double>(value), name);
  }
  return w;
}

}  // namespace

// The overall options from an `overall` argument: None (the defaults), OverallOptions,
// ObjectiveWeights or a dict of term weights.
OverallOptions OverallArg(py::handle object) {
  if (object.is_none()) return OverallOptions();
  if (py::isinstance<OverallOptions>(object)) return py::cast<OverallOptions>(object);
  OverallOptions options;
  if (py::isinstance<ObjectiveWeights>(object)) {
    options.weights = py::cast<ObjectiveWeights>(object);
  } else if (py::isinstance<py::dict>(object)) {
    options.weights = WeightsFromKwargs(py::reinterpret_borrow<py::kwargs>(object));
  } else {
    ThrowInput("overall", "is a " + std::string(py::str(py::type::of(object).attr("__name__"))) +
                              "; expected None, OverallOptions, ObjectiveWeights or a dict of "
                              "objective term weights");
  }
  return options;
}

ObjectiveWeights WeightsArg(py::handle object) {
  ObjectiveWeights w;
  if (py::isinstance<ObjectiveWeights>(object)) {
    w = py::cast<ObjectiveWeights>(object);
  } else if (py::isinstance<py::dict>(object)) {
    w = WeightsFromKwargs(py::reinterpret_borrow<py::kwargs>(object));
  } else {
    ThrowInput("weights", "is a " + std::string(py::str(py::type::of(object).attr("__name__"))) +
                              "; expected ObjectiveWeights or a dict of objective term weights");
  }
  for (const auto& entry : Vocabulary<ObjectiveTerm>::kEntries) {
    CheckFinite(w[entry.value], std::string("weights.") + entry.name);
  }
  return w;
}

namespace {

// OverallObjective of checked arguments: the value, and with `gradient` or `hessian` a tuple of
// it and the gradient (n dim,) (and the Hessian (n dim, n dim)).
py::object Objective(WeightsLike weights, ArrayLike lengths, ArrayLike old_points,
                     ArrayLike new_points, bool gradient, bool hessian) {
  const ObjectiveWeights w = WeightsArg(weights);
  const Points old_p = ReadPoints(old_points, "old_points", 2);
  const Points new_p = ReadPoints(new_points, "new_points", 2, static_cast<int>(old_p.cols()));
  if (new_p.rows() != old_p.rows()) {
    ThrowInput("new_points",
               "has " + std::to_string(new_p.rows()) + " points; expected " +
                   std::to_string(old_p.rows()) + ", as old_points",
               std::to_string(new_p.rows()), std::to_string(old_p.rows()));
  }
  const Eigen::VectorXd l =
      ReadArray(lengths, "lengths", 1, 1, 0, static_cast<int>(old_p.rows() - 1))
          .cast<Eigen::VectorXd>();
  for (Eigen::Index i = 0; i < l.size(); ++i) {
    CheckPositive(l[i], "lengths[" + std::to_string(i) + "]");
  }
  Eigen::VectorXd g;
  Eigen::MatrixXd h;
  double value = 0.0;
  {
    py::gil_scoped_release release;
    value = OverallObjective(w, l, old_p, new_p, gradient || hessian ? &g : nullptr,
                             hessian ? &h : nullptr);
  }
  if (hessian) return py::make_tuple(value, ToArray(g), py::cast(h));
  if (gradient) return py::make_tuple(value, ToArray(g));
  return py::float_(value);
}

OverallStatus StatusArg(const std::string& name) {
  for (OverallStatus s : {OverallStatus::kConverged, OverallStatus::kMaxIterations,
                          OverallStatus::kStalled, OverallStatus::kFailed}) {
    if (name == OverallStatusName(s)) return s;
  }
  ThrowInput("status", "is not an overall status", Quoted(name),
             "converged, max_iterations, stalled or failed");
}

}  // namespace

void BindOptions(py::module_& m) {
  py::class_<ObjectiveWeights> weights(m, "ObjectiveWeights", R"doc(
The metric of one overall step: a weighted sum of the objective terms (docs/scenario-format.md).

ObjectiveWeights(**terms): keywords named as the terms, each weight finite and >= 0:
  squared, squared_weighted, rotation, joint_angle, l2, l2_weighted
As in a scenario file's "objective", only the terms given count: ObjectiveWeights(rotation=1)
is the rotation metric alone. With no keyword: the C++ default, squared=1.
)doc");
  weights.def(py::init([](const py::kwargs& terms) { return WeightsFromKwargs(terms); }));
  Fields<ObjectiveWeights> weight_fields(weights, "ObjectiveWeights");
  for (const auto& entry : Vocabulary<ObjectiveTerm>::kEntries) {
    const ObjectiveTerm term = entry.value;
    weight_fields.Property(
        entry.name, [term](const ObjectiveWeights& w) { return w[term]; },
        [term](ObjectiveWeights& w, py::handle value) { w[term] = py::cast<double>(value); },
        entry.summary, true);
  }
  weight_fields.Validate("l2").Finish(false);
  weights.def(
      "as_dict",
      [](const ObjectiveWeights& w) {
        py::dict d;
        for (const auto& entry : Vocabulary<ObjectiveTerm>::kEntries) {
          d[entry.name] = w[entry.value];
        }
        return d;
      },
      "Every term's weight, zero or not: {'l2': 0.0, ..., 'squared': 1.0, ...}.");
  weights.def("__repr__", &WeightsRepr,
              "The terms with a non-zero weight: ObjectiveWeights(squared=1).");

  py::class_<OverallOptions> overall(m, "OverallOptions", R"doc(
Options of the overall solver (method "overall"; docs/scenario-format.md, "solver").

OverallOptions(weights=None, constraint_tolerance=1e-12, optimality_tolerance=1e-12,
               max_iterations=50)
  weights: ObjectiveWeights or a dict of term weights ({"squared": 1, "rotation": 0.5});
           None: squared=1.
  constraint_tolerance: stop when every relative link-length residual is below it.
  optimality_tolerance: ... and the relative first-order optimality is below it.
  max_iterations: Newton iterations at most per step.
)doc");
  overall.def(
      py::init([](OptionalWeights weights, double constraint_tolerance, double optimality_tolerance,
                  int max_iterations) {
        if (py::isinstance<OverallOptions>(weights)) {
          ThrowInput("weights", "is an OverallOptions; expected ObjectiveWeights or a dict");
        }
        OverallOptions o = weights.is_none() ? OverallOptions() : OverallArg(weights);
        o.constraint_tolerance = constraint_tolerance;
        o.optimality_tolerance = optimality_tolerance;
        o.max_iterations = max_iterations;
        return o;
      }),
      py::kw_only(), py::arg("weights") = py::none(), py::arg("constraint_tolerance") = 1e-12,
      py::arg("optimality_tolerance") = 1e-12, py::arg("max_iterations") = 50);
  Fields<OverallOptions>(overall, "OverallOptions")
      .Validate("weights.l2")
      .Member("weights", &OverallOptions::weights,
              "ObjectiveWeights: the metric each step minimizes (default squared=1).", true)
      .Member("constraint_tolerance", &OverallOptions::constraint_tolerance,
              "Stop when every |(|x_i - x_{i-1}|^2 - L_i^2)| / (2 L_i^2) is below this "
              "(dimensionless; default 1e-12).",
              true)
      .Member("optimality_tolerance", &OverallOptions::optimality_tolerance,
              "... and the relative first-order optimality is below this (dimensionless; "
              "default 1e-12).",
              true)
      .Member("max_iterations", &OverallOptions::max_iterations,
              "Newton iterations at most per step (default 50).", true)
      .Finish();

  py::class_<RunOptions> run(m, "RunOptions", R"doc(
Options of a whole run (flexkin::RunOptions), the keyword arguments of flexkin.run.

RunOptions(method="tractrix", substeps=1, record_every=1, tolerance=0.0, max_substeps=65536,
           link_angles=True, overall=None, colliders=None, link_radius=0.0)
  method: "tractrix", "ftl", "min_rotation", "min_joint_angle", "overall" or "follow_path".
  substeps: equal sub-steps per leader step (>= 1; the start of the automatic choice).
  record_every: keep frame 0, every record_every-th leader step and the last.
  tolerance: if > 0, sub-steps are doubled until the estimated largest distance to the
             continuous motion is at most this (length unit); tractrix and ftl only.
  max_substeps: upper bound of the automatic sub-steps.
  link_angles: compute each frame's link angles to the pull.
  overall: OverallOptions, ObjectiveWeights or a dict of term weights (method "overall").
  colliders: a list of dicts in the form of a scenario's "colliders" (docs/scenario-format.md).
  link_radius: each link a capsule of this radius kept outside the colliders.
)doc");
  run.def(py::init(&MakeRunOptions), py::kw_only(), py::arg("method") = "tractrix",
          py::arg("substeps") = 1, py::arg("record_every") = 1, py::arg("tolerance") = 0.0,
          py::arg("max_substeps") = 1 << 16, py::arg("link_angles") = true,
          py::arg("overall") = py::none(), py::arg("colliders") = py::none(),
          py::arg("link_radius") = 0.0);
  Fields<RunOptions>(run, "RunOptions")
      .Validate("substeps")
      .Property(
          "method", [](const RunOptions& o) { return std::string(MethodName(o.method)); },
          [](RunOptions& o, py::handle name) { o.method = MethodArg(py::cast<std::string>(name)); },
          "How the chain follows its leading end: 'tractrix' (default), 'ftl', 'min_rotation', "
          "'min_joint_angle', 'overall' or 'follow_path'.",
          true)
      .Member("substeps", &RunOptions::substeps,
              "Equal sub-steps per leader step, >= 1 (default 1; with tolerance > 0 the start of "
              "the automatic choice).",
              true)
      .Member("record_every", &RunOptions::record_every,
              "Keep frame 0, every record_every-th leader step and the last, >= 1 (default 1).",
              true)
      .Member("tolerance", &RunOptions::tolerance,
              "Accuracy control: if > 0, sub-steps are doubled until the estimated largest "
              "distance to the continuous motion is at most this (length unit; default 0 = off).",
              true)
      .Member("max_substeps", &RunOptions::max_substeps,
              "Upper bound of the automatic sub-steps (default 65536).", true)
      .Member("link_angles", &RunOptions::link_angles,
              "Compute each frame's link angles to the pull (default True).", true)
      .Member("link_radius", &RunOptions::link_radius,
              "The links' radius (length unit, >= 0, default 0): each link a capsule kept "
              "outside the colliders (a scenario's \"link_radius\"; docs/colliders.md).",
              true)
      .Property(
          "colliders", [](const RunOptions& o) { return CollidersValue(o.colliders); },
          [](RunOptions& o, py::handle colliders) { o.colliders = CollidersArg(colliders); },
          "Things the chain stays outside of: a list of dicts in the form of a scenario's "
          "\"colliders\" (docs/scenario-format.md; keyframed ones with \"motion\"), read back in "
          "that form with 3 coordinates (default []).",
          true)
      .Property(
          "overall", [](const RunOptions& o) { return o.overall; },
          [](RunOptions& o, py::handle overall) { o.overall = OverallArg(overall); },
          "OverallOptions of method 'overall' (set from OverallOptions, ObjectiveWeights, a dict "
          "of term weights or None).",
          true)
      .Finish();

  py::class_<Metrics> metrics(m, "Metrics", R"doc(
Measures of a run's motion (paper eq. 6, Sec. 3.2); read only.
  l2_per_step: (num_steps,) sum over the points of the distance each travels in the step.
  l2_weighted_per_step: (num_steps,) the same weighted by arc length (eq. 6).
  l2_total, l2_weighted_total: their sums.
  max_relative_length_error: largest |(|x_i - x_{i-1}| - L_i)| / L_i after any leader step.
  path_length: (n+1,) distance travelled by each point over the run, leading end first.
)doc");
  Fields<Metrics>(metrics, "Metrics")
      .Member("l2_per_step", &Metrics::l2_per_step,
              "(num_steps,) float64: per leader step, the sum over the points of the distance "
              "each travels (length unit), sub-steps included.")
      .Member("l2_weighted_per_step", &Metrics::l2_weighted_per_step,
              "(num_steps,) float64: the same weighted by arc length (eq. 6; length unit^2).")
      .Member("l2_total", &Metrics::l2_total, "Sum of l2_per_step (length unit).")
      .Member("l2_weighted_total", &Metrics::l2_weighted_total,
              "Sum of l2_weighted_per_step (length unit^2).")
      .Member("max_relative_length_error", &Metrics::max_relative_length_error,
              "Largest |(|x_i - x_{i-1}| - L_i)| / L_i over every link after every leader step "
              "(dimensionless).")
      .Member("path_length", &Metrics::path_length,
              "(n+1,) float64: the distance each point travelled over the run (length unit), "
              "leading end first.")
      .Finish();

  py::class_<AccuracyReport> accuracy(m, "AccuracyReport", R"doc(
What the accuracy control did (RunOptions.tolerance > 0); read only.
  enabled, tolerance, max_substeps, substeps (used), order (2 tractrix, 1 ftl),
  estimated_error (Richardson estimate of the largest distance to the continuous motion),
  met (estimated_error <= tolerance; True when not enabled).
)doc");
  Fields<AccuracyReport>(accuracy, "AccuracyReport")
      .Member("enabled", &AccuracyReport::enabled, "Whether tolerance > 0 was asked for.")
      .Member("tolerance", &AccuracyReport::tolerance,
              "The tolerance asked for (length unit; RunOptions.tolerance).")
      .Member("max_substeps", &AccuracyReport::max_substeps,
              "The bound on the sub-steps (RunOptions.max_substeps).")
      .Member("substeps", &AccuracyReport::substeps, "Sub-steps per leader step actually used.")
      .Member("order", &AccuracyReport::order,
              "Convergence order assumed in the estimate (2 tractrix, 1 ftl).")
      .Member("estimated_error", &AccuracyReport::estimated_error,
              "Richardson estimate of the largest distance to the continuous motion (length "
              "unit); meaningful only if enabled.")
      .Member("met", &AccuracyReport::met, "estimated_error <= tolerance (True when not enabled).")
      .Finish();

  py::class_<OverallRunReport> run_report(m, "OverallRunReport", R"doc(
What the overall solver did over a run (method "overall"); read only.
  solves, failures (sub-steps whose solve did not converge), iterations, max_iterations,
  constraint_violation and optimality (worst over the run), first_failure ('' if none).
)doc");
  Fields<OverallRunReport>(run_report, "OverallRunReport")
      .Member("solves", &OverallRunReport::solves, "Sub-steps solved.")
      .Member("failures", &OverallRunReport::failures,
              "Sub-steps whose solve did not converge (0 for a good run).")
      .Member("iterations", &OverallRunReport::iterations, "Newton iterations in all.")
      .Member("max_iterations", &OverallRunReport::max_iterations,
              "Most Newton iterations of one sub-step.")
      .Member("constraint_violation", &OverallRunReport::constraint_violation,
              "Worst relative link-length residual over the run (dimensionless).")
      .Member("optimality", &OverallRunReport::optimality,
              "Worst relative first-order optimality over the run (dimensionless).")
      .Member("first_failure", &OverallRunReport::first_failure,
              "'leader step s, sub-step j: <report>' of the first failure; '' if none.")
      .Finish();

  py::class_<ContactReport> contacts(m, "ContactReport", R"doc(
What the colliders did to a run (a scenario's "colliders"; docs/colliders.md); read only.
  num_colliders, contact_link_steps (link steps that slid along a collider), least_clearance
  (of any link after any sub-step, relative to its length; inf without colliders).
)doc");
  Fields<ContactReport>(contacts, "ContactReport")
      .Member("num_colliders", &ContactReport::num_colliders, "Colliders of the run.")
      .Member("contact_link_steps", &ContactReport::contact_link_steps,
              "Link steps (a link's move in one sub-step) that would have entered a collider and "
              "slid along it instead.")
      .Member("least_clearance", &ContactReport::least_clearance,
              "Least clearance of any link from any collider after any sub-step, relative to the "
              "link's length (inf without colliders; never below -1e-12, the rounding).")
      .Finish();

  py::class_<PathReport> path(m, "PathReport", R"doc(
What a follow_path run did (method "follow_path"; docs/colliders.md "Follow the path"); read
only. Per leader step, (m,) float64: clearance (least clearance of any link from any collider,
length unit; inf without colliders; < 0 where the body passes through a collider), tip_error
(distance of the last point from the head's path at arc length s_head - body length) and
deviation (largest distance of any point from the head's path). Over the run: least_clearance,
least_clearance_step, max_tip_error, max_deviation. enabled is False for the other methods.
)doc");
  Fields<PathReport>(path, "PathReport")
      .Member("enabled", &PathReport::enabled, "Whether the run's method is follow_path.")
      .Member("clearance", &PathReport::clearance,
              "(m,) float64: per leader step, the least clearance of any link from any collider "
              "over its sub-steps (length unit; inf without colliders; negative: the body passes "
              "through a collider, as the head's path does).")
      .Member("tip_error", &PathReport::tip_error,
              "(m,) float64: per leader step, the distance of the last point from the point of "
              "the head's path at arc length s_head - (L_1 + ... + L_n) (length unit).")
      .Member("deviation", &PathReport::deviation,
              "(m,) float64: per leader step, the largest distance of any point from the head's "
              "path travelled so far (length unit; ~1e-16 by construction).")
      .Member("least_clearance", &PathReport::least_clearance,
              "The least of clearance (length unit; inf without colliders).")
      .Member("least_clearance_step", &PathReport::least_clearance_step,
              "The leader step (1-based) of least_clearance; 0 without colliders.")
      .Member("max_tip_error", &PathReport::max_tip_error, "The largest tip error (length unit).")
      .Member("max_deviation", &PathReport::max_deviation,
              "The largest deviation from the head's path (length unit).")
      .Finish();

  py::class_<OverallReport> report(m, "OverallReport", R"doc(
What the overall solver did in one step (flexkin.overall_step); read only.
  status ("converged", "max_iterations", "stalled", "failed"), converged, iterations,
  objective, constraint_violation, optimality, start (how the minimizer was reached),
  moving_points (points 1..moving_points moved).
)doc");
  Fields<OverallReport>(report, "OverallReport")
      .Property(
          "status", [](const OverallReport& r) { return std::string(OverallStatusName(r.status)); },
          [](OverallReport& r, py::handle name) {
            r.status = StatusArg(py::cast<std::string>(name));
          },
          "'converged' (both tolerances met), 'max_iterations', 'stalled' (the line search made "
          "no progress) or 'failed' (a singular system or a value not finite).")
      .Member("iterations", &OverallReport::iterations, "Newton iterations.")
      .Member("objective", &OverallReport::objective,
              "The step's metric at the returned configuration.")
      .Member("constraint_violation", &OverallReport::constraint_violation,
              "Largest |(|D_i|^2 - L_i^2)| / (2 L_i^2) (dimensionless).")
      .Member("optimality", &OverallReport::optimality,
              "Relative first-order optimality (dimensionless; OverallOptions."
              "optimality_tolerance).")
      .Member("start", &OverallReport::start,
              "How the returned local minimizer was reached (continuation in head sub-steps, or "
              "the sequential tractrix step).")
      .Member("moving_points", &OverallReport::moving_points,
              "Points 1..moving_points moved, the others stayed exactly still (n for the smooth "
              "metrics; often fewer with an L2 term).")
      .Finish();
  report.def_property_readonly("converged", &OverallReport::converged, "status == 'converged'.");
  report.def("brief_report", &OverallReport::BriefReport,
             "One line: status, iterations, objective, residuals.");

  m.def("overall_objective", &Objective, py::arg("weights"), py::arg("lengths"),
        py::arg("old_points"), py::arg("new_points"), py::kw_only(), py::arg("gradient") = false,
        py::arg("hessian") = false, R"doc(
The metric of one overall step (flexkin::OverallObjective), as the overall solver evaluates it.

overall_objective(weights, lengths, old_points, new_points, *, gradient=False, hessian=False)
  weights: ObjectiveWeights or a dict of term weights ({"squared": 1, "rotation": 0.5}).
  lengths: (n,) the link lengths L_i (> 0; the joint-angle and weighted terms use them).
  old_points: (n+1, dim) the configuration before the step a_0..a_n, dim 2 or 3.
  new_points: (n+1, dim) the configuration after it x_0..x_n (x_0 is held fixed).
  gradient, hessian: also return the gradient and the (dense) Hessian with respect to
    x_1..x_n, flattened point by point: component (j-1)*dim + k is coordinate k of x_j.
Returns the value (float); with gradient=True a tuple (value, gradient (n*dim,)); with
hessian=True (value, gradient (n*dim,), hessian (n*dim, n*dim)). The joint-angle term is
ignored for 3D chains; at a point that has not moved the L2 terms add the subgradient 0 and no
Hessian. Raises InputError naming the argument for shapes that do not match, values that are
not finite, or lengths <= 0.
)doc");
}

}  // namespace flexkin::python
