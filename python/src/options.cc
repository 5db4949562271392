// Option and report classes: flexkin.ObjectiveWeights, OverallOptions, RunOptions (inputs, with
// the C++ field names), Metrics, AccuracyReport, OverallRunReport, OverallReport (outputs, read
// only). Every one prints readably and pickles.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <string>

#include "convert.h"
#include "flexkin/overall.h"
#include "flexkin/run.h"

namespace flexkin::python {
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

std::string OverallOptionsRepr(const OverallOptions& o) {
  return "OverallOptions(weights=" + WeightsRepr(o.weights) +
         ", constraint_tolerance=" + Num(o.constraint_tolerance) +
         ", optimality_tolerance=" + Num(o.optimality_tolerance) +
         ", max_iterations=" + std::to_string(o.max_iterations) + ")";
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

std::string RunOptionsRepr(const RunOptions& o) {
  return "RunOptions(method=" + Quoted(MethodName(o.method)) +
         ", substeps=" + std::to_string(o.substeps) +
         ", record_every=" + std::to_string(o.record_every) + ", tolerance=" + Num(o.tolerance) +
         ", max_substeps=" + std::to_string(o.max_substeps) +
         ", link_angles=" + (o.link_angles ? "True" : "False") +
         ", overall=" + OverallOptionsRepr(o.overall) + ")";
}

void BindOptions(py::module_& m) {
  py::class_<ObjectiveWeights> weights(m, "ObjectiveWeights", R"doc(
The metric of one overall step: a weighted sum of the objective terms (docs/scenario-format.md).

ObjectiveWeights(**terms): keywords named as the terms, each weight finite and >= 0:
  squared, squared_weighted, rotation, joint_angle, l2, l2_weighted
As in a scenario file's "objective", only the terms given count: ObjectiveWeights(rotation=1)
is the rotation metric alone. With no keyword: the C++ default, squared=1.
)doc");
  weights.def(py::init([](const py::kwargs& terms) { return WeightsFromKwargs(terms); }));
  for (const auto& entry : Vocabulary<ObjectiveTerm>::kEntries) {
    const ObjectiveTerm term = entry.value;
    weights.def_property(
        entry.name, [term](const ObjectiveWeights& w) { return w[term]; },
        [term](ObjectiveWeights& w, double value) { w[term] = value; }, entry.summary);
  }
  weights.def(
      "validate", [](const ObjectiveWeights& w) { ThrowIfAny(w.Validate()); },
      "Raises InputError for the first problem (a weight < 0 or not finite, all zero, L2 "
      "with joint_angle).");
  weights.def("as_dict", [](const ObjectiveWeights& w) {
    py::dict d;
    for (const auto& entry : Vocabulary<ObjectiveTerm>::kEntries) d[entry.name] = w[entry.value];
    return d;
  });
  weights.def("__repr__", &WeightsRepr);
  weights.def("__eq__", [](const ObjectiveWeights& a, const ObjectiveWeights& b) {
    for (const auto& entry : Vocabulary<ObjectiveTerm>::kEntries) {
      if (a[entry.value] != b[entry.value]) return false;
    }
    return true;
  });
  weights.def(py::pickle(
      [](const ObjectiveWeights& w) {
        py::tuple state(std::size(Vocabulary<ObjectiveTerm>::kEntries));
        size_t i = 0;
        for (const auto& entry : Vocabulary<ObjectiveTerm>::kEntries) state[i++] = w[entry.value];
        return state;
      },
      [](const py::tuple& state) {
        StateTuple(state, std::size(Vocabulary<ObjectiveTerm>::kEntries), "ObjectiveWeights");
        ObjectiveWeights w;
        size_t i = 0;
        for (const auto& entry : Vocabulary<ObjectiveTerm>::kEntries) {
          w[entry.value] = py::cast<double>(state[i++]);
        }
        return w;
      }));

  py::class_<OverallOptions>(m, "OverallOptions", R"doc(
Options of the overall solver (method "overall"; docs/scenario-format.md, "solver").

OverallOptions(weights=None, constraint_tolerance=1e-12, optimality_tolerance=1e-12,
               max_iterations=50)
  weights: ObjectiveWeights or a dict of term weights ({"squared": 1, "rotation": 0.5});
           None: squared=1.
  constraint_tolerance: stop when every relative link-length residual is below it.
  optimality_tolerance: ... and the relative first-order optimality is below it.
  max_iterations: Newton iterations at most per step.
)doc")
      .def(py::init([](py::object weights, double constraint_tolerance, double optimality_tolerance,
                       int max_iterations) {
             OverallOptions o = weights.is_none() ? OverallOptions() : OverallArg(weights);
             if (py::isinstance<OverallOptions>(weights)) {
               ThrowInput("weights", "is an OverallOptions; expected ObjectiveWeights or a dict");
             }
             o.constraint_tolerance = constraint_tolerance;
             o.optimality_tolerance = optimality_tolerance;
             o.max_iterations = max_iterations;
             return o;
           }),
           py::kw_only(), py::arg("weights") = py::none(), py::arg("constraint_tolerance") = 1e-12,
           py::arg("optimality_tolerance") = 1e-12, py::arg("max_iterations") = 50)
      .def_readwrite("weights", &OverallOptions::weights)
      .def_readwrite("constraint_tolerance", &OverallOptions::constraint_tolerance)
      .def_readwrite("optimality_tolerance", &OverallOptions::optimality_tolerance)
      .def_readwrite("max_iterations", &OverallOptions::max_iterations)
      .def(
          "validate", [](const OverallOptions& o) { ThrowIfAny(o.Validate()); },
          "Raises InputError for the first problem.")
      .def("__repr__", &OverallOptionsRepr)
      .def(py::pickle(
          [](const OverallOptions& o) {
            return py::make_tuple(o.weights, o.constraint_tolerance, o.optimality_tolerance,
                                  o.max_iterations);
          },
          [](const py::tuple& state) {
            StateTuple(state, 4, "OverallOptions");
            OverallOptions o;
            o.weights = py::cast<ObjectiveWeights>(state[0]);
            o.constraint_tolerance = py::cast<double>(state[1]);
            o.optimality_tolerance = py::cast<double>(state[2]);
            o.max_iterations = py::cast<int>(state[3]);
            return o;
          }));

  py::class_<RunOptions>(m, "RunOptions", R"doc(
Options of a whole run (flexkin::RunOptions), the keyword arguments of flexkin.run.

RunOptions(method="tractrix", substeps=1, record_every=1, tolerance=0.0, max_substeps=65536,
           link_angles=True, overall=None)
  method: "tractrix", "ftl", "min_rotation", "min_joint_angle" or "overall".
  substeps: equal sub-steps per leader step (>= 1; the start of the automatic choice).
  record_every: keep frame 0, every record_every-th leader step and the last.
  tolerance: if > 0, sub-steps are doubled until the estimated largest distance to the
             continuous motion is at most this (length unit); tractrix and ftl only.
  max_substeps: upper bound of the automatic sub-steps.
  link_angles: compute each frame's link angles to the pull.
  overall: OverallOptions, ObjectiveWeights or a dict of term weights (method "overall").
)doc")
      .def(py::init([](const std::string& method, int substeps, int record_every, double tolerance,
                       int max_substeps, bool link_angles, py::object overall) {
             RunOptions o;
             o.method = MethodArg(method);
             o.substeps = substeps;
             o.record_every = record_every;
             o.tolerance = tolerance;
             o.max_substeps = max_substeps;
             o.link_angles = link_angles;
             o.overall = OverallArg(overall);
             return o;
           }),
           py::kw_only(), py::arg("method") = "tractrix", py::arg("substeps") = 1,
           py::arg("record_every") = 1, py::arg("tolerance") = 0.0,
           py::arg("max_substeps") = 1 << 16, py::arg("link_angles") = true,
           py::arg("overall") = py::none())
      .def_property(
          "method", [](const RunOptions& o) { return std::string(MethodName(o.method)); },
          [](RunOptions& o, const std::string& name) { o.method = MethodArg(name); })
      .def_readwrite("substeps", &RunOptions::substeps)
      .def_readwrite("record_every", &RunOptions::record_every)
      .def_readwrite("tolerance", &RunOptions::tolerance)
      .def_readwrite("max_substeps", &RunOptions::max_substeps)
      .def_readwrite("link_angles", &RunOptions::link_angles)
      .def_property(
          "overall", [](const RunOptions& o) { return o.overall; },
          [](RunOptions& o, py::object overall) { o.overall = OverallArg(overall); })
      .def(
          "validate", [](const RunOptions& o) { ThrowIfAny(o.Validate()); },
          "Raises InputError for the first problem, naming the member ('substeps').")
      .def("__repr__", &RunOptionsRepr)
      .def(py::pickle(
          [](const RunOptions& o) {
            return py::make_tuple(std::string(MethodName(o.method)), o.substeps, o.record_every,
                                  o.tolerance, o.max_substeps, o.link_angles, o.overall);
          },
          [](const py::tuple& state) {
            StateTuple(state, 7, "RunOptions");
            RunOptions o;
            o.method = MethodArg(py::cast<std::string>(state[0]));
            o.substeps = py::cast<int>(state[1]);
            o.record_every = py::cast<int>(state[2]);
            o.tolerance = py::cast<double>(state[3]);
            o.max_substeps = py::cast<int>(state[4]);
            o.link_angles = py::cast<bool>(state[5]);
            o.overall = py::cast<OverallOptions>(state[6]);
            return o;
          }));

  py::class_<Metrics>(m, "Metrics", R"doc(
Measures of a run's motion (paper eq. 6, Sec. 3.2); read only.
  l2_per_step: (num_steps,) sum over the points of the distance each travels in the step.
  l2_weighted_per_step: (num_steps,) the same weighted by arc length (eq. 6).
  l2_total, l2_weighted_total: their sums.
  max_relative_length_error: largest |(|x_i - x_{i-1}| - L_i)| / L_i after any leader step.
  path_length: (n+1,) distance travelled by each point over the run, leading end first.
)doc")
      .def_readonly("l2_per_step", &Metrics::l2_per_step)
      .def_readonly("l2_weighted_per_step", &Metrics::l2_weighted_per_step)
      .def_readonly("l2_total", &Metrics::l2_total)
      .def_readonly("l2_weighted_total", &Metrics::l2_weighted_total)
      .def_readonly("max_relative_length_error", &Metrics::max_relative_length_error)
      .def_readonly("path_length", &Metrics::path_length)
      .def("__repr__",
           [](const Metrics& x) {
             return "Metrics(l2_total=" + Num(x.l2_total) +
                    ", l2_weighted_total=" + Num(x.l2_weighted_total) +
                    ", max_relative_length_error=" + Num(x.max_relative_length_error) +
                    ", l2_per_step=" + VectorText(x.l2_per_step) +
                    ", path_length=" + VectorText(x.path_length) + ")";
           })
      .def(py::pickle(
          [](const Metrics& x) {
            return py::make_tuple(x.l2_per_step, x.l2_weighted_per_step, x.l2_total,
                                  x.l2_weighted_total, x.max_relative_length_error, x.path_length);
          },
          [](const py::tuple& state) {
            StateTuple(state, 6, "Metrics");
            Metrics x;
            x.l2_per_step = py::cast<Eigen::VectorXd>(state[0]);
            x.l2_weighted_per_step = py::cast<Eigen::VectorXd>(state[1]);
            x.l2_total = py::cast<double>(state[2]);
            x.l2_weighted_total = py::cast<double>(state[3]);
            x.max_relative_length_error = py::cast<double>(state[4]);
            x.path_length = py::cast<Eigen::VectorXd>(state[5]);
            return x;
          }));

  py::class_<AccuracyReport>(m, "AccuracyReport", R"doc(
What the accuracy control did (RunOptions.tolerance > 0); read only.
  enabled, tolerance, max_substeps, substeps (used), order (2 tractrix, 1 ftl),
  estimated_error (Richardson estimate of the largest distance to the continuous motion),
  met (estimated_error <= tolerance; True when not enabled).
)doc")
      .def_readonly("enabled", &AccuracyReport::enabled)
      .def_readonly("tolerance", &AccuracyReport::tolerance)
      .def_readonly("max_substeps", &AccuracyReport::max_substeps)
      .def_readonly("substeps", &AccuracyReport::substeps)
      .def_readonly("order", &AccuracyReport::order)
      .def_readonly("estimated_error", &AccuracyReport::estimated_error)
      .def_readonly("met", &AccuracyReport::met)
      .def("__repr__",
           [](const AccuracyReport& a) {
             return std::string("AccuracyReport(enabled=") + (a.enabled ? "True" : "False") +
                    ", tolerance=" + Num(a.tolerance) +
                    ", max_substeps=" + std::to_string(a.max_substeps) +
                    ", substeps=" + std::to_string(a.substeps) +
                    ", order=" + std::to_string(a.order) +
                    ", estimated_error=" + Num(a.estimated_error) +
                    ", met=" + (a.met ? "True" : "False") + ")";
           })
      .def(py::pickle(
          [](const AccuracyReport& a) {
            return py::make_tuple(a.enabled, a.tolerance, a.max_substeps, a.substeps, a.order,
                                  a.estimated_error, a.met);
          },
          [](const py::tuple& state) {
            StateTuple(state, 7, "AccuracyReport");
            AccuracyReport a;
            a.enabled = py::cast<bool>(state[0]);
            a.tolerance = py::cast<double>(state[1]);
            a.max_substeps = py::cast<int>(state[2]);
            a.substeps = py::cast<int>(state[3]);
            a.order = py::cast<int>(state[4]);
            a.estimated_error = py::cast<double>(state[5]);
            a.met = py::cast<bool>(state[6]);
            return a;
          }));

  py::class_<OverallRunReport>(m, "OverallRunReport", R"doc(
What the overall solver did over a run (method "overall"); read only.
  solves, failures (sub-steps whose solve did not converge), iterations, max_iterations,
  constraint_violation and optimality (worst over the run), first_failure ('' if none).
)doc")
      .def_readonly("solves", &OverallRunReport::solves)
      .def_readonly("failures", &OverallRunReport::failures)
      .def_readonly("iterations", &OverallRunReport::iterations)
      .def_readonly("max_iterations", &OverallRunReport::max_iterations)
      .def_readonly("constraint_violation", &OverallRunReport::constraint_violation)
      .def_readonly("optimality", &OverallRunReport::optimality)
      .def_readonly("first_failure", &OverallRunReport::first_failure)
      .def("__repr__",
           [](const OverallRunReport& r) {
             return "OverallRunReport(solves=" + std::to_string(r.solves) +
                    ", failures=" + std::to_string(r.failures) +
                    ", iterations=" + std::to_string(r.iterations) +
                    ", max_iterations=" + std::to_string(r.max_iterations) +
                    ", constraint_violation=" + Num(r.constraint_violation) +
                    ", optimality=" + Num(r.optimality) +
                    ", first_failure=" + Quoted(r.first_failure) + ")";
           })
      .def(py::pickle(
          [](const OverallRunReport& r) {
            return py::make_tuple(r.solves, r.failures, r.iterations, r.max_iterations,
                                  r.constraint_violation, r.optimality, r.first_failure);
          },
          [](const py::tuple& state) {
            StateTuple(state, 7, "OverallRunReport");
            OverallRunReport r;
            r.solves = py::cast<int64_t>(state[0]);
            r.failures = py::cast<int64_t>(state[1]);
            r.iterations = py::cast<int64_t>(state[2]);
            r.max_iterations = py::cast<int>(state[3]);
            r.constraint_violation = py::cast<double>(state[4]);
            r.optimality = py::cast<double>(state[5]);
            r.first_failure = py::cast<std::string>(state[6]);
            return r;
          }));

  py::class_<OverallReport>(m, "OverallReport", R"doc(
What the overall solver did in one step (flexkin.overall_step); read only.
  status ("converged", "max_iterations", "stalled", "failed"), converged, iterations,
  objective, constraint_violation, optimality, start (how the minimizer was reached),
  moving_points (points 1..moving_points moved).
)doc")
      .def_property_readonly("status",
                             [](const OverallReport& r) { return OverallStatusName(r.status); })
      .def_property_readonly("converged", &OverallReport::converged)
      .def_readonly("iterations", &OverallReport::iterations)
      .def_readonly("objective", &OverallReport::objective)
      .def_readonly("constraint_violation", &OverallReport::constraint_violation)
      .def_readonly("optimality", &OverallReport::optimality)
      .def_readonly("start", &OverallReport::start)
      .def_readonly("moving_points", &OverallReport::moving_points)
      .def("brief_report", &OverallReport::BriefReport)
      .def("__repr__", [](const OverallReport& r) {
        return std::string("OverallReport(status=") + Quoted(OverallStatusName(r.status)) +
               ", iterations=" + std::to_string(r.iterations) + ", objective=" + Num(r.objective) +
               ", constraint_violation=" + Num(r.constraint_violation) +
               ", optimality=" + Num(r.optimality) +
               ", moving_points=" + std::to_string(r.moving_points) + ")";
      });
}

}  // namespace flexkin::python
