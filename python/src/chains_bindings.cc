// Chains, generated curves, leader paths, the single link step and multi-step propagation:
// flexkin.Chain, line, parabola, arc, helix, split_pull, resample_path, tractrix_step,
// follow_the_leader_step, move_leader, overall_step.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "convert.h"
#include "fields.h"
#include "flexkin/curves.h"
#include "flexkin/leader.h"
#include "flexkin/link_step.h"
#include "flexkin/overall.h"
#include "flexkin/propagate.h"
#include "flexkin/tree.h"
#include "flexkin/tree_overall.h"
#include "flexkin/vocabulary.h"

namespace flexkin::python {
namespace {

// A DeprecationWarning attributed to the caller of the module's function (stack level 2: the
// function is called through its wrapper in flexkin/__init__.py).
void Deprecated(const char* message) {
  if (PyErr_WarnEx(PyExc_DeprecationWarning, message, 2) != 0) throw py::error_already_set();
}

// The enumerator named by a str argument `name` ("turn", "side"); InputError naming the keyword,
// the value and the valid names otherwise.
template <typename Enum>
Enum NameArg(py::handle value, const std::string& name) {
  if (!py::isinstance<py::str>(value)) {
    throw InputError(Problem::Invalid(name, std::string(py::repr(value)), QuotedNames<Enum>()));
  }
  return ParseName<Enum>(py::cast<std::string>(value), name);
}

// turn="ccw" or "cw"; the deprecated clockwise=True/False, where given, agreeing with it.
bool TurnArg(py::handle turn, py::handle clockwise) {
  const bool cw = NameArg<CurveTurn>(turn, "turn") == CurveTurn::kCw;
  if (clockwise.is_none()) return cw;
  if (!py::isinstance<py::bool_>(clockwise)) {
    throw InputError(
        Problem::Invalid("clockwise", std::string(py::repr(clockwise)), "True or False"));
  }
  Deprecated(
      "flexkin: clockwise= is deprecated; use turn=\"cw\" or turn=\"ccw\", as in scenario "
      "files");
  if (cw && !clockwise.cast<bool>()) {
    ThrowInput("clockwise", "False contradicts turn=\"cw\"; give turn alone", "False",
               "turn alone");
  }
  return cw || clockwise.cast<bool>();
}

// side="+x" or "-x" as +1 or -1; the deprecated 1 and -1 too.
int SideArg(py::handle side) {
  if (py::isinstance<py::int_>(side) && !py::isinstance<py::bool_>(side) &&
      (side.equal(py::int_(1)) || side.equal(py::int_(-1)))) {
    Deprecated(
        "flexkin: side=1 and side=-1 are deprecated; use side=\"+x\" or side=\"-x\", as "
        "in scenario files");
    return side.cast<int>();
  }
  return NameArg<CurveSide>(side, "side") == CurveSide::kPlusX ? 1 : -1;
}

// A line as a scenario file defines it: a start sets the dimension (and the default direction
// [1, 0] or [1, 0, 0]); without one the direction does (2 or 3 values), from the origin; without
// either the line is 2D.
LineDef LineArgs(py::handle start, py::handle direction, int links, double link_length) {
  LineDef d;
  const bool has_start = !start.is_none();
  if (has_start) d.start = ReadVector(start, "start");
  const int dim = has_start ? static_cast<int>(d.start.size()) : 0;
  d.direction = direction.is_none() ? Eigen::VectorXd::Unit(has_start ? dim : 2, 0)
                                    : ReadVector(direction, "direction", dim);
  if (!has_start) d.start = Eigen::VectorXd::Zero(d.direction.size());
  d.links = links;
  d.link_length = link_length;
  return d;
}

// The single link step, 2D or 3D by the size of the points.
template <typename Step2, typename Step3>
py::array_t<double> LinkStep(py::handle head_old, py::handle head_new, py::handle tail,
                             double length, Step2 step2, Step3 step3) {
  const Eigen::VectorXd a = ReadVector(head_old, "head_old");
  const Eigen::VectorXd b = ReadVector(head_new, "head_new", static_cast<int>(a.size()));
  const Eigen::VectorXd t = ReadVector(tail, "tail", static_cast<int>(a.size()));
  CheckPositive(length, "length");
  if (a.size() == 2) {
    return ToArray(
        Eigen::VectorXd(step2(Eigen::Vector2d(a), Eigen::Vector2d(b), Eigen::Vector2d(t), length)));
  }
  return ToArray(
      Eigen::VectorXd(step3(Eigen::Vector3d(a), Eigen::Vector3d(b), Eigen::Vector3d(t), length)));
}

std::string ChainRepr(const Chain& c) {
  return "Chain(" + std::to_string(c.dim()) + "D, " + std::to_string(c.num_links()) +
         " links, total length " + Num(c.lengths.sum()) + ", leading end " +
         VectorText(c.points.row(0).transpose()) + ")";
}

void MoveChain(Chain* chain, py::handle target, const std::string& method, int substeps) {
  const Method m = MethodArg(method);
  const Eigen::VectorXd head = ReadVector(target, "target", chain->dim());
  if (m == Method::kOverall) {
    ThrowInput("method",
               "\"overall\" is not a link rule; use overall_step (or run with method "
               "\"overall\")",
               "\"overall\"", "\"tractrix\", \"ftl\", \"min_rotation\" or \"min_joint_angle\"");
  }
  const Stepper stepper = MakeStepper(m, *chain);
  py::gil_scoped_release release;
  MoveLeader(stepper, head, substeps, &chain->points);
}

OverallReport StepChainOverall(Chain* chain, py::handle head, py::handle options) {
  const Eigen::VectorXd h = ReadVector(head, "head", chain->dim());
  const OverallOptions o = OverallArg(options);
  py::gil_scoped_release release;
  return OverallStep(h, o, chain);
}

// A sequence of integers (Python ints or numpy integers, not bools or floats), each named
// "name[i]" in errors.
std::vector<int> IndexList(py::handle object, const std::string& name) {
  if (!py::isinstance<py::sequence>(object) && !py::isinstance<py::array>(object)) {
    ThrowInput(name, "is not a sequence of point indices", std::string(py::repr(object)),
               "a list of ints, -1 for the root");
  }
  std::vector<int> out;
  Py_ssize_t i = 0;
  for (py::handle item : object) {
    const std::string field = name + "[" + std::to_string(i++) + "]";
    if (py::isinstance<py::bool_>(item) || !PyIndex_Check(item.ptr())) {
      ThrowInput(field, "is not an integer", std::string(py::repr(item)),
                 "a point index, -1 for the root");
    }
    const Py_ssize_t value = PyNumber_AsSsize_t(item.ptr(), nullptr);
    if (value == -1 && PyErr_Occurred()) throw py::error_already_set();
    if (value < -1 || value > std::numeric_limits<int>::max()) {
      ThrowInput(field, "is not a point index", std::to_string(value),
                 "-1 (the root) or a point index");
    }
    out.push_back(static_cast<int>(value));
  }
  return out;
}

// The tree's frames: the start, then the configuration after each target of `path`.
py::array_t<double> MoveTree(ArrayLike points, IndexSequence parents, ArrayLike path, int driven,
                             const std::string& method, int substeps) {
  Tree tree;
  tree.points = ReadPoints(points, "points", 2);
  tree.parents = IndexList(parents, "parents");
  ValidateTree(tree, "");
  const TreeStepper stepper = MakeTreeStepper(MethodArg(method), tree, driven);
  const int dim = stepper.dim;
  const auto targets = ReadArray(path, "path", 2, 1, dim);
  if (substeps < 1) {
    ThrowInput("substeps", "must be at least 1", std::to_string(substeps), "1 or more");
  }
  const py::ssize_t count = targets.shape(0), rows = tree.points.rows();
  py::array_t<double> frames({count + 1, rows, static_cast<py::ssize_t>(dim)});
  double* out = frames.mutable_data();
  const double* target = targets.data();
  Points pts = tree.points;
  const size_t frame = static_cast<size_t>(rows) * dim;
  py::gil_scoped_release release;
  std::copy(pts.data(), pts.data() + frame, out);
  for (py::ssize_t i = 0; i < count; ++i) {
    MoveTreePoint(stepper, Eigen::Map<const Eigen::VectorXd>(target + i * dim, dim), substeps,
                  &pts);
    std::copy(pts.data(), pts.data() + frame, out + (i + 1) * frame);
  }
  return frames;
}

// The frames of a tree whose points `targets` reach the rows of each frame of `paths` ((m, k,
// dim)), with a report per frame.
py::tuple ReachTree(ArrayLike points, IndexSequence parents, IndexSequence targets, ArrayLike paths,
                    IndexSequence fixed, OptionalArray weights, const std::string& method,
                    NameText branch_rule, double tolerance, int max_passes, OptionalWeights overall,
                    const std::vector<bool>& looks, bool finish) {
  Tree tree;
  tree.points = ReadPoints(points, "points", 2);
  tree.parents = IndexList(parents, "parents");
  ValidateTree(tree, "");
  ReachOptions options;
  options.method = MethodArg(method);
  options.branch_rule = NameArg<BranchRule>(branch_rule, "branch_rule");
  options.tolerance = tolerance;
  options.max_passes = max_passes;
  std::vector<double> w;
  if (!weights.is_none()) {
    const auto array = ReadArray(weights, "weights", 1, 1, 0, -1);
    w.assign(array.data(), array.data() + array.size());
  }
  const TreeReacher reacher =
      MakeTreeReacher(tree, IndexList(targets, "targets"), IndexList(fixed, "fixed"), w, options,
                      std::vector<char>(looks.begin(), looks.end()));
  const bool exact = !overall.is_none();
  TreeOverallOptions overall_options;
  if (exact) overall_options.weights = WeightsArg(overall);
  const py::ssize_t dim = reacher.dim, k = static_cast<py::ssize_t>(reacher.target_points.size());
  const auto frames_in =
      py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(paths);
  if (!frames_in || frames_in.ndim() != 3 || frames_in.shape(1) != k || frames_in.shape(2) != dim) {
    std::string given = "not an array";
    if (frames_in) {
      given = "shape (";
      for (py::ssize_t d = 0; d < frames_in.ndim(); ++d) {
        given += (d > 0 ? ", " : "") + std::to_string(frames_in.shape(d));
      }
      given += ")";
    }
    ThrowInput("paths", "is " + given + "; expected (m, " + std::to_string(k) + ", " +
                            std::to_string(dim) + "): each frame's position of every target");
  }
  const py::ssize_t count = frames_in.shape(0), rows = tree.points.rows();
  for (py::ssize_t i = 0; i < frames_in.size(); ++i) {
    if (!std::isfinite(frames_in.data()[i])) {
      const py::ssize_t f = i / (k * dim), t = i / dim % k;
      ThrowInput("paths[" + std::to_string(f) + "][" + std::to_string(t) + "]",
                 "has a non-finite coordinate", FormatNumber(frames_in.data()[i]), "finite values");
    }
  }
  py::array_t<double> frames({count + 1, rows, dim});
  py::array_t<int> passes(count);
  py::array_t<double> residual(count);
  py::array_t<bool> reached(count), converged(count), finished(count);
  double* out = frames.mutable_data();
  Points pts = tree.points, goal(k, dim);
  const size_t frame = static_cast<size_t>(rows) * dim;
  {
    py::gil_scoped_release release;
    std::copy(pts.data(), pts.data() + frame, out);
    for (py::ssize_t i = 0; i < count; ++i) {
      std::copy(frames_in.data() + i * k * dim, frames_in.data() + (i + 1) * k * dim, goal.data());
      ReachReport report;
      if (exact) {
        const TreeOverallReport step = StepTreeOverall(reacher, goal, overall_options, &pts);
        report = step.start;
        converged.mutable_data()[i] = step.converged;
      } else {
        report = ReachTargets(reacher, goal, &pts);
        if (finish) report = FinishTreeReach(reacher, goal, report, &pts);
      }
      finished.mutable_data()[i] = report.finished;
      std::copy(pts.data(), pts.data() + frame, out + (i + 1) * frame);
      passes.mutable_data()[i] = report.passes;
      residual.mutable_data()[i] = report.residual;
      reached.mutable_data()[i] = report.reached;
    }
  }
  py::dict report;
  report["passes"] = passes;
  report["residual"] = residual;
  report["reached"] = reached;
  report["root"] = reacher.root;
  if (exact) report["converged"] = converged;
  if (!exact) report["finished"] = finished;
  return py::make_tuple(frames, report);
}

}  // namespace

Chain ChainArg(py::handle object, const std::string& name) {
  if (py::isinstance<Chain>(object)) return py::cast<Chain>(object);
  return MakeChain(ReadPoints(object, name, 2));
}

void BindChains(py::module_& m) {
  py::class_<Chain> chain(m, "Chain", R"doc(
A chain of rigid links: points (n+1, dim) float64, row 0 the leading end; link i joins points
i-1 and i and keeps its length lengths[i-1], fixed when the chain is made.

Chain(points, *, link_length=None, lengths=None)
  points: (n+1, 2) or (n+1, 3) array-like, n >= 1.
  link_length: every link exactly this long (points from the curve generators, whose chords
               equal it to rounding); else
  lengths: the n link lengths; else the distances between consecutive points.
)doc");
  chain
      .def(py::init([](ArrayLike points, OptionalFloat link_length, OptionalArray lengths) {
             Points p = ReadPoints(points, "points", 2);
             if (!link_length.is_none() && !lengths.is_none()) {
               ThrowInput("lengths", "given with link_length; give one of them");
             }
             if (!link_length.is_none()) {
               return MakeEqualLinkChain(
                   p, CheckPositive(py::cast<double>(link_length), "link_length"));
             }
             if (!lengths.is_none()) {
               Chain c;
               c.lengths = ReadArray(lengths, "lengths", 1, 1, 0, static_cast<int>(p.rows() - 1))
                               .cast<Eigen::VectorXd>();
               c.points = std::move(p);
               ValidateChain(c, "lengths");
               return c;
             }
             return MakeChain(p);
           }),
           py::arg("points"), py::kw_only(), py::arg("link_length") = py::none(),
           py::arg("lengths") = py::none())
      .def_property_readonly("dim", &Chain::dim, "2 or 3: the columns of points.")
      .def_property_readonly("num_links", &Chain::num_links, "n, the number of links.")
      .def("max_relative_length_error", &MaxRelativeLengthError,
           "Largest |(|p_i - p_{i-1}| - L_i)| / L_i over the links (dimensionless).")
      .def(
          "move_leader",
          [](Chain& c, ArrayLike target, const std::string& method, int substeps) {
            MoveChain(&c, target, method, substeps);
          },
          py::arg("target"), py::kw_only(), py::arg("method") = "tractrix", py::arg("substeps") = 1,
          "Moves the leading end in a straight line to target (dim values) in `substeps` equal "
          "sub-steps, every link following by `method`; in place.")
      .def(
          "overall_step",
          [](Chain& c, ArrayLike head, OverallLike options) {
            return StepChainOverall(&c, head, options);
          },
          py::arg("head"), py::kw_only(), py::arg("options") = py::none(),
          "One overall step in place: the leading end to head, the other points to the "
          "minimizer of the objective under the length constraints. options: OverallOptions, "
          "ObjectiveWeights or a dict of term weights. Returns an OverallReport.")
      .def("__repr__", &ChainRepr, "A summary: dimension, links, total length, leading end.");
  Fields<Chain>(chain, "Chain")
      .Property(
          "points", [](const Chain& c) { return ToArray(Points(c.points)); },
          [](Chain& c, py::handle points) { c.points = ReadPoints(points, "points", 2); },
          "(n+1, dim) float64, a copy; row 0 the leading end (length unit).")
      .Property(
          "lengths", [](const Chain& c) { return ToArray(c.lengths); },
          [](Chain& c, py::handle lengths) {
            c.lengths =
                ReadArray(lengths, "lengths", 1, 1, 0, static_cast<int>(c.points.rows() - 1))
                    .cast<Eigen::VectorXd>();
          },
          "(n,) float64, a copy: the link lengths, fixed when the chain was made (length unit).")
      .Finish(false, [](Chain& c) { ValidateChain(c, "lengths"); });

  m.def(
      "line",
      [](OptionalArray start, OptionalArray direction, int links, double link_length) {
        return ToArray(MakeLine(LineArgs(start, direction, links, link_length)));
      },
      py::kw_only(), py::arg("start") = py::none(), py::arg("direction") = py::none(),
      py::arg("links") = 10, py::arg("link_length") = 0.1,
      "A straight line of `links` links of `link_length` from start (the leading end, default "
      "the origin) along direction (toward the trailing end, any nonzero length; default "
      "[1, 0], or [1, 0, 0] with a 3D start), as a scenario file's {\"shape\": \"line\"}: "
      "(links+1, dim) float64.");
  m.def(
      "parabola",
      [](double a, int links, double link_length, NameText side) {
        ParabolaDef d;
        d.a = a;
        d.links = links;
        d.link_length = link_length;
        d.side = SideArg(side);
        return ToArray(MakeParabola(d));
      },
      py::kw_only(), py::arg("a") = 1.0, py::arg("links") = 20, py::arg("link_length") = 0.25,
      py::arg("side") = NameOf(CurveSide::kPlusX),
      "The parabola y = a x^2 from the vertex (the leading end) toward +x (side=\"+x\") or -x "
      "(side=\"-x\"), every chord link_length, as a scenario file's {\"shape\": \"parabola\"}: "
      "(links+1, 2) float64 (paper Sec. 5.1: a=1, 20 links of 0.25). side=1 and side=-1 are "
      "the deprecated forms of \"+x\" and \"-x\".");
  m.def(
      "arc",
      [](double radius, ArrayLike center, double start_angle, NameText turn, int links,
         double link_length, OptionalBool clockwise) {
        ArcDef d;
        d.radius = radius;
        d.center = ReadVector(center, "center", 2);
        d.start_angle = start_angle;
        d.clockwise = TurnArg(turn, clockwise);
        d.links = links;
        d.link_length = link_length;
        return ToArray(MakeArc(d));
      },
      py::kw_only(), py::arg("radius") = 1.0, py::arg("center") = std::vector<double>{0.0, 0.0},
      py::arg("start_angle") = 0.0, py::arg("turn") = NameOf(CurveTurn::kCcw),
      py::arg("links") = 10, py::arg("link_length") = 0.1, py::arg("clockwise") = py::none(),
      "A circular arc about center, point 0 at start_angle (radians), the angle moving along "
      "the chain counterclockwise (turn=\"ccw\") or clockwise (turn=\"cw\"), every chord "
      "link_length, as a scenario file's {\"shape\": \"arc\"}: (links+1, 2) float64. "
      "clockwise=True/False is the deprecated form of turn.");
  m.def(
      "helix",
      [](double radius, double pitch, ArrayLike center, double start_angle, NameText turn,
         int links, double link_length, OptionalBool clockwise) {
        HelixDef d;
        d.radius = radius;
        d.pitch = pitch;
        d.center = ReadVector(center, "center", 3);
        d.start_angle = start_angle;
        d.clockwise = TurnArg(turn, clockwise);
        d.links = links;
        d.link_length = link_length;
        return ToArray(MakeHelix(d));
      },
      py::kw_only(), py::arg("radius") = 1.0, py::arg("pitch") = 1.0,
      py::arg("center") = std::vector<double>{0.0, 0.0, 0.0}, py::arg("start_angle") = 0.0,
      py::arg("turn") = NameOf(CurveTurn::kCcw), py::arg("links") = 20,
      py::arg("link_length") = 1.5, py::arg("clockwise") = py::none(),
      "A circular helix about an axis parallel to z (rise `pitch` per turn), turning "
      "counterclockwise (turn=\"ccw\") or clockwise (turn=\"cw\") seen from +z, every chord "
      "link_length, as a scenario file's {\"shape\": \"helix\"}: (links+1, 3) float64. "
      "clockwise=True/False is the deprecated form of turn.");

  m.def(
      "split_pull",
      [](ArrayLike start, ArrayLike pull, int64_t steps) {
        const Eigen::VectorXd s = ReadVector(start, "start");
        return ToArray(SplitPull(s, ReadVector(pull, "pull", static_cast<int>(s.size())), steps));
      },
      py::arg("start"), py::arg("pull"), py::arg("steps"),
      "Leader steps of one straight pull: (steps, dim), row k-1 = start + k/steps pull, the "
      "last exactly start + pull.");
  m.def(
      "resample_path",
      [](ArrayLike start, ArrayLike path, double max_step) {
        const Eigen::VectorXd s = ReadVector(start, "start");
        return ToArray(
            ResamplePath(s, ReadPoints(path, "path", 1, static_cast<int>(s.size())), max_step));
      },
      py::arg("start"), py::arg("path"), py::arg("max_step"),
      "Leader steps along the polyline start -> path[0] -> ..., each segment split into equal "
      "steps of at most max_step: (total steps, dim).");

  m.def(
      "tractrix_step",
      [](ArrayLike head_old, ArrayLike head_new, ArrayLike tail, double length) {
        return LinkStep(
            head_old, head_new, tail, length,
            [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& t,
               double l) { return TractrixStep(a, b, t, l); },
            [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& t,
               double l) { return TractrixStep(a, b, t, l); });
      },
      py::arg("head_old"), py::arg("head_new"), py::arg("tail"), py::arg("length"),
      "One link's tractrix step: the new trailing end when the leading end moves in a straight "
      "line from head_old to head_new (2 or 3 values each), the trailing end's velocity along "
      "the link (closed form). Returns (dim,) float64.");
  m.def(
      "follow_the_leader_step",
      [](ArrayLike head_old, ArrayLike head_new, ArrayLike tail, double length) {
        return LinkStep(
            head_old, head_new, tail, length,
            [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& t,
               double l) { return FollowTheLeaderStep(a, b, t, l); },
            [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& t,
               double l) { return FollowTheLeaderStep(a, b, t, l); });
      },
      py::arg("head_old"), py::arg("head_new"), py::arg("tail"), py::arg("length"),
      "One link's follow-the-leader step (FABRIK): the point at distance length from head_new "
      "nearest the old trailing end. Returns (dim,) float64.");

  m.def(
      "move_leader",
      [](PointsOrChain points, ArrayLike target, const std::string& method, int substeps) {
        Chain chain = ChainArg(points);
        MoveChain(&chain, target, method, substeps);
        return ToArray(std::move(chain.points));
      },
      py::arg("points"), py::arg("target"), py::kw_only(), py::arg("method") = "tractrix",
      py::arg("substeps") = 1,
      "Multi-step propagation: the leading end of points (an (n+1, dim) array-like or a Chain) "
      "moves in a straight line to target in `substeps` equal sub-steps, each link following by "
      "`method` (\"tractrix\", \"ftl\", \"min_rotation\", \"min_joint_angle\"). Returns the new "
      "(n+1, dim) points; the input is not changed (Chain.move_leader moves a chain in place).");
  m.def("move_tree", &MoveTree, py::arg("points"), py::arg("parents"), py::arg("path"),
        py::kw_only(), py::arg("driven") = 0, py::arg("method") = "tractrix",
        py::arg("substeps") = 1,
        "A tree driven at one point (docs/trees.md): points is (n+1, dim), parents the point "
        "each point hangs from (n+1 ints, -1 for the one root; a path is [-1, 0, 1, ...]). The "
        "point `driven` moves through the targets of path ((m, dim)), each in `substeps` straight "
        "sub-steps, and every link, outward from it along every branch, follows by `method` "
        "(\"tractrix\", \"ftl\", \"min_rotation\", \"min_joint_angle\"). Returns the frames, (m+1, "
        "n+1, dim): the start, then the "
        "tree after each target.");
  m.def(
      "reach_tree", &ReachTree, py::arg("points"), py::arg("parents"), py::arg("targets"),
      py::arg("paths"), py::kw_only(), py::arg("fixed") = std::vector<int>(),
      py::arg("weights") = py::none(), py::arg("method") = "tractrix",
      py::arg("branch_rule") = "centroid", py::arg("tolerance") = 1e-10,
      py::arg("max_passes") = 1000, py::arg("overall") = py::none(),
      py::arg("looks") = std::vector<bool>(), py::arg("finish") = true,
      "Several targets on a tree (docs/trees.md): the points `targets` (k point indices) reach, "
      "frame by frame, the positions of paths ((m, k, dim)) while the points `fixed` stay where "
      "they are, by passes of `method` (\"tractrix\" or \"ftl\") between them, with "
      "`branch_rule` (\"centroid\", FABRIK's, or \"keep_links\") where pulled branches meet; "
      "each frame starts where the last ended. weights: one per target (default 1). tolerance: "
      "of the longest link. Returns (frames, report): frames (m+1, n+1, dim), the start then "
      "each frame; report a dict of per-frame arrays passes, residual (of the longest link) and "
      "reached, and root (the point the passes hang the tree from). overall: objective weights "
      "(ObjectiveWeights or a dict: squared, squared_weighted, rotation): each frame is then the "
      "exact least-motion step, from the passes by Newton's method (docs/trees.md), and the "
      "report adds converged; the passes' points where it does not converge. looks: one bool "
      "per target (default none): a True target is a pointing goal, its paths' rows the point "
      "its link from its parent points at (docs/trees.md, \"Pointing goals\"; the passes "
      "only, not overall). finish: passes that stall within 0.05 of the longest link are completed "
      "by the least correction to the targets (docs/trees.md, \"Finishing stalled passes\"); "
      "the report's finished says which frames.");
  m.def(
      "overall_step",
      [](PointsOrChain points, ArrayLike head, OverallLike options) {
        Chain chain = ChainArg(points);
        OverallReport report = StepChainOverall(&chain, head, options);
        return py::make_tuple(ToArray(std::move(chain.points)), report);
      },
      py::arg("points"), py::arg("head"), py::kw_only(), py::arg("options") = py::none(),
      "One overall step: the leading end to head, every other point to the minimizer of the "
      "objective (options: OverallOptions, ObjectiveWeights or a dict of term weights) under "
      "the length constraints. Returns (new points, OverallReport).");
}

}  // namespace flexkin::python
