// Tree scenario files (flexkin/tree_scenario.h, docs/trees.md "Scenario files"): the reader (every
// problem by JSON pointer), the run, and the result writers.
#include "flexkin/tree_scenario.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "io/atomic_file.h"
#include "io/json_file.h"
#include "io/json_values.h"
#include "io/npz.h"
#include "io/scenario_kinds.h"

namespace flexkin {
namespace {

using json = nlohmann::json;

// A library field ("tree.parents[4]", "targets[1]", "weights[0]") as the file's JSON pointer.
std::string TreePointer(const std::string& field) {
  std::string out = "/";
  for (char c : field) {
    if (c == '.' || c == '[') {
      out += '/';
    } else if (c != ']') {
      out += c;
    }
  }
  if (out.rfind("/targets/", 0) == 0 && std::count(out.begin(), out.end(), '/') == 2) {
    out += "/point";  // targets[k] names the target's point
  }
  if (out.rfind("/weights/", 0) == 0) out = "/targets/" + out.substr(9) + "/weight";
  return out;
}

// The solver options of a robot tree scenario.
RobotTreeOptions RobotTreeOptionsOf(const TreeScenario& s) {
  RobotTreeOptions o;
  o.tolerance = s.reach.tolerance;
  o.angle_tolerance = s.reach.tolerance;
  o.max_iterations = s.reach.max_passes;
  o.looks = s.looks;
  o.weights = s.weights;
  return o;
}

class TreeScenarioReader : public json_internal::JsonReader {
 public:
  TreeScenarioReader(const RobotScenarioOptions& options, std::string directory)
      : options_(options), directory_(std::move(directory)) {}

  TreeScenario Read(const json& root) {
    TreeScenario s;
    if (!ExpectObject(root, "", "an object (a tree scenario, docs/trees.md)")) return s;
    CheckKeys(root, "",
              {"format", "name", "tree", "robot", "targets", "fixed", "method", "substeps",
               "branch_rule", "tolerance", "max_passes", "finish", "overall"});
    if (const json* format = Find(root, "format")) {
      if (!(format->is_string() && *format == "flexkin-tree")) {
        ValueProblem(*format, "/format", "\"flexkin-tree\"");
      }
    }
    Optional(
        root, "", "name", [&](const json& v, const std::string& p) { return String(v, p); },
        &s.name);
    if (Find(root, "robot") != nullptr) return ReadRobot(root, std::move(s));
    const bool tree_ok = ReadTree(root, &s.tree);
    const int count = tree_ok ? static_cast<int>(s.tree.points.rows()) : 0;
    const int dim = tree_ok ? static_cast<int>(s.tree.points.cols()) : 0;
    ReadTargets(root, count, dim, &s, nullptr);
    if (const json* fixed = Find(root, "fixed")) {
      if (!fixed->is_array()) {
        TypeProblem(*fixed, "/fixed", "an array of point indices");
      } else {
        for (size_t k = 0; k < fixed->size(); ++k) {
          if (auto i = Integer((*fixed)[k], "/fixed/" + std::to_string(k), 0, 1 << 30)) {
            s.fixed.push_back(static_cast<int>(*i));
          }
        }
      }
    }
    std::string method = "tractrix";
    Optional(
        root, "", "method",
        [&](const json& v, const std::string& p) {
          return Choice(v, p, {"tractrix", "ftl", "min_rotation", "min_joint_angle", "overall"});
        },
        &method);
    s.method = ParseName<Method>(method, "/method");
    int64_t substeps = 1;
    Optional(
        root, "", "substeps",
        [&](const json& v, const std::string& p) { return Integer(v, p, 1, 1 << 20); }, &substeps);
    s.substeps = static_cast<int>(substeps);
    std::string rule = NameOf(s.reach.branch_rule);
    Optional(
        root, "", "branch_rule",
        [&](const json& v, const std::string& p) { return Choice(v, p, NamesOf<BranchRule>()); },
        &rule);
    s.reach.branch_rule = ParseName<BranchRule>(rule, "/branch_rule");
    ReadTolerances(root, &s.reach);
    Optional(
        root, "", "finish",
        [&](const json& v, const std::string& p) -> std::optional<bool> {
          if (v.is_boolean()) return v.get<bool>();
          TypeProblem(v, p, "true or false");
          return std::nullopt;
        },
        &s.finish);
    if (const json* overall = Find(root, "overall")) ReadOverall(*overall, &s);
    if (problems.empty()) CheckTogether(root, &s);
    return s;
  }

 private:
  const RobotScenarioOptions& options_;
  std::string directory_;

  void ReadTolerances(const json& root, ReachOptions* reach) {
    Optional(
        root, "", "tolerance",
        [&](const json& v, const std::string& p) {
          return Number(v, p, json_internal::Range::kPositive);
        },
        &reach->tolerance);
    int64_t max_passes = reach->max_passes;
    Optional(
        root, "", "max_passes",
        [&](const json& v, const std::string& p) { return Integer(v, p, 1, 1 << 24); },
        &max_passes);
    reach->max_passes = static_cast<int>(max_passes);
  }

  // A robot tree: "robot" {"urdf", "base_link"}, targets on links (docs/trees.md, "Robot trees").
  TreeScenario ReadRobot(const json& root, TreeScenario s) {
    for (const char* key :
         {"tree", "fixed", "method", "substeps", "branch_rule", "finish", "overall"}) {
      if (Find(root, key) != nullptr) {
        Add(std::string("/") + key,
            std::string("is not an option of a robot tree (\"robot\"); ") +
                (std::string(key) == "tree"
                     ? "give \"tree\" (points) or \"robot\" (a URDF), not both"
                     : "its base is fixed and its joints solved in joint space; it takes "
                       "\"targets\", \"tolerance\" and \"max_passes\""));
      }
    }
    const json& robot = *Find(root, "robot");
    std::string file, base_link;
    if (ExpectObject(robot, "/robot", "an object with \"urdf\" and optionally \"base_link\"")) {
      CheckKeys(robot, "/robot", {"urdf", "base_link"});
      Require(
          robot, "/robot", "urdf", "a URDF file name",
          [&](const json& v, const std::string& p) { return String(v, p); }, &file);
      if (Find(robot, "urdf") != nullptr && file.empty() && robot["urdf"].is_string()) {
        ValueProblem(robot["urdf"], "/robot/urdf", "a URDF file name");
      }
      Optional(
          robot, "/robot", "base_link",
          [&](const json& v, const std::string& p) { return String(v, p); }, &base_link);
    }
    std::vector<UrdfTool> tools;
    ReadTargets(root, 0, 3, &s, &tools);
    ReadTolerances(root, &s.reach);
    if (!problems.empty()) return s;
    if (!options_.urdf_tree_loader) {
      Add("/robot/urdf",
          "names a URDF file, but this reader has no URDF loader; expected a "
          "reader given RobotScenarioOptions::urdf_tree_loader (the URDF "
          "component's UrdfRobotScenarioOptions(), flexkin/urdf.h)");
      return s;
    }
    std::filesystem::path path(file);
    if (path.is_relative() && !directory_.empty()) path = std::filesystem::path(directory_) / path;
    try {
      auto model =
          std::make_shared<RobotTree>(options_.urdf_tree_loader(path.string(), base_link, tools));
      const RobotTreeLayout layout = MakeRobotTreeLayout(*model);
      s.tree.points = RobotTreePoints(*model, layout, model->initial);
      s.tree.parents = layout.parents;
      for (size_t i = 0; i < layout.sliding.size(); ++i) {
        if (layout.sliding[i]) s.sliding.push_back(static_cast<int>(i));
      }
      s.targets = layout.tool_point;
      s.fixed = {0};
      s.robot = model;
      ThrowIfAny(RobotTreeOptionsOf(s).Validate(*model));
    } catch (const InputError& e) {
      Problem p = e.problem();
      const std::string& f = p.field;
      if (f.rfind("tools[", 0) == 0) {  // tools[k].link -> /targets/k/link
        const size_t close = f.find(']');
        p.field = "/targets/" + f.substr(6, close - 6) + "/" +
                  (close + 2 < f.size() ? f.substr(close + 2) : std::string("link"));
      } else if (f == "base_link") {
        p.field = "/robot/base_link";
      } else {
        p.message = path.string() + ": " + p.Text();
        p.field = "/robot/urdf";
      }
      problems.push_back(std::move(p));
    }
    if (problems.empty()) CheckPathLengths(&s);
    return s;
  }

  void CheckPathLengths(const TreeScenario* s) {
    auto path_of = [&](size_t k) {
      return "/targets/" + std::to_string(k) + (s->looks[k] ? "/look_at" : "/path");
    };
    for (size_t k = 1; k < s->paths.size(); ++k) {
      if (s->paths[k].rows() != s->paths[0].rows()) {
        Add(path_of(k), "has " + std::to_string(s->paths[k].rows()) +
                            " points; every target's path has one point per frame, " +
                            std::to_string(s->paths[0].rows()) + " as " + path_of(0));
      }
    }
  }

  bool ReadTree(const json& root, Tree* tree) {
    const json* t = Required(root, "", "tree", "an object with \"points\" and \"parents\"");
    if (t == nullptr || !ExpectObject(*t, "/tree", "an object with \"points\" and \"parents\"")) {
      return false;
    }
    CheckKeys(*t, "/tree", {"points", "parents"});
    const size_t before = problems.size();
    dimension_of_ = "the tree";
    Require(
        *t, "/tree", "points", "an array of points (2 or 3 numbers each), at least 2",
        [&](const json& v, const std::string& p) { return PointList(v, p, 0, 2, 1 << 24); },
        &tree->points);
    if (const json* parents =
            Required(*t, "/tree", "parents", "an array of parent indices, -1 for the root")) {
      if (!parents->is_array()) {
        TypeProblem(*parents, "/tree/parents", "an array of parent indices, -1 for the root");
      } else {
        for (size_t k = 0; k < parents->size(); ++k) {
          const auto i = Integer((*parents)[k], "/tree/parents/" + std::to_string(k), -1, 1 << 30);
          tree->parents.push_back(i ? static_cast<int>(*i) : 0);
        }
      }
    }
    if (problems.size() != before) return false;
    try {
      ValidateTree(*tree, "tree");
    } catch (const InputError& e) {
      Problem p = e.problem();
      p.field = TreePointer(p.field);
      problems.push_back(p);
      return false;
    }
    return true;
  }

  // With `tools` (a robot tree), each target names a link ("link", "offset", "axis") instead of
  // a point.
  void ReadTargets(const json& root, int count, int dim, TreeScenario* s,
                   std::vector<UrdfTool>* tools) {
    const json* targets =
        Required(root, "", "targets", "an array of {\"point\": i, \"path\": [...]}, at least one");
    if (targets == nullptr) return;
    if (!targets->is_array() || targets->empty()) {
      TypeProblem(*targets, "/targets",
                  "an array of {\"point\": i, \"path\": [...]}, at least one");
      return;
    }
    for (size_t k = 0; k < targets->size(); ++k) {
      const std::string ptr = "/targets/" + std::to_string(k);
      const json& t = (*targets)[k];
      if (!ExpectObject(t, ptr, "an object with \"point\" and \"path\" (or \"look_at\")")) {
        continue;
      }
      int64_t point = -1;
      if (tools != nullptr) {
        CheckKeys(t, ptr, {"link", "offset", "axis", "path", "look_at", "weight"});
        UrdfTool tool;
        Require(
            t, ptr, "link", "the name of a link of the robot",
            [&](const json& v, const std::string& p) { return String(v, p); }, &tool.link);
        std::optional<Eigen::VectorXd> v;
        Optional(
            t, ptr, "offset", [&](const json& x, const std::string& p) { return Vector(x, p, 3); },
            &v);
        if (v) tool.offset = *v;
        v.reset();
        Optional(
            t, ptr, "axis", [&](const json& x, const std::string& p) { return Vector(x, p, 3); },
            &v);
        if (v) {
          if (!(v->norm() > 0.0)) {
            ValueProblem(t["axis"], ptr + "/axis", "a non-zero direction in the link's frame");
          }
          tool.axis = *v;
        }
        tools->push_back(tool);
      } else {
        CheckKeys(t, ptr, {"point", "path", "look_at", "weight"});
        Require(
            t, ptr, "point", "a point index",
            [&](const json& v, const std::string& p) {
              return Integer(v, p, 0, count > 0 ? count - 1 : (1 << 30));
            },
            &point);
      }
      Points path;
      const bool look = t.contains("look_at");
      if (look && t.contains("path")) {
        Add(ptr + "/look_at",
            "is given with \"path\"; a target takes one: \"path\" (where its point goes) or "
            "\"look_at\" (what its link from its parent points at)");
      }
      Require(
          t, ptr, look ? "look_at" : "path",
          look ? "an array of points looked at, one per frame"
               : "an array of points, one per frame",
          [&](const json& v, const std::string& p) { return PointList(v, p, dim, 1, 1 << 24); },
          &path);
      double weight = 1.0;
      Optional(
          t, ptr, "weight",
          [&](const json& v, const std::string& p) {
            return Number(v, p, json_internal::Range::kPositive);
          },
          &weight);
      s->targets.push_back(static_cast<int>(point));
      s->paths.push_back(std::move(path));
      s->looks.push_back(look ? 1 : 0);
      s->weights.push_back(weight);
    }
  }

  void ReadOverall(const json& v, TreeScenario* s) {
    if (!ExpectObject(v, "/overall",
                      "an object of term weights (squared, squared_weighted, "
                      "rotation)")) {
      return;
    }
    ObjectiveWeights w;
    w.squared = 0.0;
    CheckKeys(v, "/overall", {"squared", "squared_weighted", "rotation"});
    for (const char* term : {"squared", "squared_weighted", "rotation"}) {
      Optional(
          v, "/overall", term,
          [&](const json& x, const std::string& p) {
            return Number(x, p, json_internal::Range::kNonNegative);
          },
          &w[ParseName<ObjectiveTerm>(term, "/overall")]);
    }
    if (!(w.squared > 0.0 || w.squared_weighted > 0.0 || w.rotation > 0.0)) {
      Add("/overall", "has no positive weight", "",
          "at least one of squared, squared_weighted "
          "and rotation > 0");
    }
    s->overall.weights = w;
  }

  // What only the whole scenario can tell: the paths' lengths, the method against the targets,
  // and the library's own checks (a point driven twice, fixed and driven, ...).
  void CheckTogether(const json& root, TreeScenario* s) {
    auto path_of = [&](size_t k) {
      return "/targets/" + std::to_string(k) + (s->looks[k] ? "/look_at" : "/path");
    };
    CheckPathLengths(s);
    for (size_t k = 0; k < s->looks.size(); ++k) {
      if (s->looks[k] && s->method == Method::kOverall) {
        Add(path_of(k),
            "is a pointing goal; method \"overall\" takes position targets only (the passes, "
            "\"tractrix\" or \"ftl\", take pointing goals)");
      }
    }
    const bool one = s->driven_at_one_point();
    if (!one && s->method != Method::kTractrix && s->method != Method::kFollowTheLeader &&
        s->method != Method::kOverall) {
      problems.push_back(Problem::Invalid(
          "/method", std::string("\"") + NameOf(s->method) + "\"",
          "\"tractrix\", \"ftl\" or \"overall\" (with several targets or fixed points)"));
    }
    if (!one && root.contains("substeps")) {
      Add("/substeps",
          "is an option of a tree driven at one point (one target, nothing fixed); "
          "several targets or fixed points take \"max_passes\" and \"tolerance\"");
    }
    if (!problems.empty()) return;
    try {
      ReachOptions reach = s->reach;
      if (s->method == Method::kFollowTheLeader) reach.method = s->method;
      MakeTreeReacher(s->tree, s->targets, s->fixed, s->weights, reach, s->looks);
    } catch (const InputError& e) {
      Problem p = e.problem();
      p.field = TreePointer(p.field);
      problems.push_back(p);
    }
  }
};

// The JSON of a result (and of an .npz's tree.json, without the arrays).
// Whether the scenario's paths give every frame's goals (a scenario read from a file always does).
bool HasGoals(const TreeScenario& s, const TreeRunResult& r) {
  if (s.paths.size() != s.targets.size() || r.frames.empty()) return false;
  for (const Points& path : s.paths) {
    if (path.rows() + 1 != static_cast<Eigen::Index>(r.frames.size())) return false;
  }
  return true;
}

nlohmann::ordered_json TreeResultHeader(const TreeScenario& s, const TreeRunResult& r) {
  nlohmann::ordered_json j;
  j["format"] = "flexkin-tree-result";
  j["name"] = s.name;
  j["method"] = s.robot ? "newton" : NameOf(s.method);
  if (s.robot) j["joints"] = s.robot->joint_names;
  if (!s.sliding.empty()) {
    j["sliding"] = s.sliding;
    std::vector<bool> prismatic;
    for (const char c : s.robot->prismatic) prismatic.push_back(c != 0);
    j["prismatic"] = prismatic;
  }
  j["dim"] = s.tree.points.cols();
  j["parents"] = s.tree.parents;
  j["targets"] = s.targets;
  std::vector<bool> looks(s.targets.size(), false);  // a scenario built in C++ may leave it empty
  for (size_t k = 0; k < s.looks.size() && k < looks.size(); ++k) looks[k] = s.looks[k] != 0;
  j["looks"] = looks;
  j["fixed"] = s.fixed;
  j["max_length_error"] = r.max_length_error;
  j["failures"] = r.failures();
  return j;
}

}  // namespace

namespace internal {
TreeScenario ReadTreeScenario(const json& root, const RobotScenarioOptions& options,
                              const std::string& directory, Problems* problems) {
  TreeScenarioReader reader(options, directory);
  TreeScenario s = reader.Read(root);
  for (Problem& p : reader.problems) problems->push_back(std::move(p));
  return s;
}
}  // namespace internal

int TreeRunResult::failures() const {
  int n = 0;
  for (size_t i = 0; i < reached.size(); ++i) n += !reached[i] || !converged[i];
  return n;
}

std::string TreeRunResult::BriefReport() const {
  std::ostringstream out;
  const int worst_passes = passes.empty() ? 0 : *std::max_element(passes.begin(), passes.end());
  const double worst = residual.empty() ? 0.0 : *std::max_element(residual.begin(), residual.end());
  out << frames.size() << " frames; " << failures() << " not reached or not converged; passes at "
      << "most " << worst_passes << "; residual at most " << worst << " of the longest link; "
      << "link lengths within " << max_length_error;
  const auto completed = std::count(finished.begin(), finished.end(), char(1));
  if (completed > 0) {
    out << "; " << completed << (completed == 1 ? " frame" : " frames")
        << " of stalled passes finished by the least correction";
  }
  return out.str();
}

std::string TreeSummary(const TreeScenario& s) {
  std::ostringstream out;
  const Eigen::Index n = s.tree.points.rows();
  if (s.robot) {
    const auto pointing = std::count(s.looks.begin(), s.looks.end(), char(1));
    out << "robot tree" << (s.name.empty() ? "" : " \"" + s.name + "\"") << ": "
        << s.robot->joints() << " joints, " << n << " points, " << s.targets.size()
        << (s.targets.size() == 1 ? " tool" : " tools");
    if (pointing > 0) out << " (" << pointing << " pointing)";
    out << ", joint-space Gauss-Newton (newton), " << s.frames() << " frames";
    return out.str();
  }
  out << "tree" << (s.name.empty() ? "" : " \"" + s.name + "\"") << ": " << n << " points ("
      << n - 1 << " links, " << s.tree.points.cols() << "D), " << s.targets.size()
      << (s.targets.size() == 1 ? " target" : " targets");
  const auto pointing = std::count(s.looks.begin(), s.looks.end(), char(1));
  if (pointing > 0) out << " (" << pointing << " pointing)";
  out << ", " << s.fixed.size() << " fixed, ";
  if (s.driven_at_one_point() && s.method != Method::kOverall) {
    out << NameOf(s.method) << " driven at point " << s.targets[0] << " (" << s.substeps
        << (s.substeps == 1 ? " sub-step" : " sub-steps") << " a frame)";
  } else if (s.method == Method::kOverall) {
    out << "overall (exact least motion)";
  } else {
    out << NameOf(s.method) << " passes (" << NameOf(s.reach.branch_rule) << ")";
  }
  out << ", " << s.frames() << " frames";
  return out.str();
}

namespace {

// A robot tree: every frame's joints solved from the last frame's.
TreeRunResult RunRobotTree(const TreeScenario& s,
                           const std::function<void(int64_t, int64_t)>& progress) {
  const RobotTree& robot = *s.robot;
  const RobotTreeSolver solver(robot, RobotTreeOptionsOf(s));
  const std::vector<int>& parents = solver.layout().parents;
  const std::vector<char>& sliding = solver.layout().sliding;
  const int frames = s.frames();
  TreeRunResult r;
  Eigen::VectorXd q = robot.initial;
  r.frames.push_back(RobotTreePoints(robot, solver.layout(), q));
  r.angles.push_back(q);
  // The links' lengths at the start, against which each frame's are measured (a sliding joint's
  // link is not: its length is the joint's).
  const Points& start = r.frames.front();
  std::vector<double> lengths(parents.size(), 0.0);
  for (size_t i = 1; i < parents.size(); ++i) {
    lengths[i] = (start.row(i) - start.row(parents[i])).norm();
  }
  Points goals(s.targets.size(), 3);
  const double longest = solver.layout().longest_link;
  for (int f = 0; f < frames; ++f) {
    for (size_t k = 0; k < s.targets.size(); ++k) goals.row(k) = s.paths[k].row(f);
    const RobotTreeSolve solve = solver.Solve(q, goals);
    q = solve.angles;
    r.frames.push_back(RobotTreePoints(robot, solver.layout(), q));
    r.angles.push_back(q);
    r.passes.push_back(solve.iterations);
    r.residual.push_back(std::max(solve.residual / longest, solve.angle_residual));
    r.reached.push_back(solve.converged);
    r.converged.push_back(1);
    r.finished.push_back(0);
    const Points& p = r.frames.back();
    for (size_t i = 1; i < parents.size(); ++i) {
      if (sliding[i]) continue;
      const double length = (p.row(i) - p.row(parents[i])).norm();
      r.max_length_error = std::max(r.max_length_error, std::abs(length - lengths[i]) / lengths[i]);
    }
    if (progress) progress(f + 1, frames);
  }
  return r;
}

}  // namespace

TreeRunResult RunTree(const TreeScenario& s,
                      const std::function<void(int64_t, int64_t)>& progress) {
  if (s.robot) return RunRobotTree(s, progress);
  TreeRunResult r;
  const TreeStepper links = MakeTreeStepper(Method::kTractrix, s.tree, 0);  // the start's lengths
  const int frames = s.frames();
  const int dim = static_cast<int>(s.tree.points.cols());
  Points points = s.tree.points;
  r.frames.reserve(frames + 1);
  r.frames.push_back(points);
  const bool one = s.driven_at_one_point() && s.method != Method::kOverall;
  TreeStepper stepper;
  TreeReacher reacher;
  ReachOptions reach = s.reach;
  reach.method = s.method == Method::kFollowTheLeader ? s.method : Method::kTractrix;
  if (one) {
    stepper = MakeTreeStepper(s.method, s.tree, s.targets[0]);
  } else {
    reacher = MakeTreeReacher(s.tree, s.targets, s.fixed, s.weights, reach, s.looks);
  }
  Points goal(s.targets.size(), dim);
  for (int f = 0; f < frames; ++f) {
    for (size_t k = 0; k < s.targets.size(); ++k) goal.row(k) = s.paths[k].row(f);
    int passes = 0;
    double residual = 0.0;
    char reached = 1, converged = 1, finished = 0;
    if (one) {
      MoveTreePoint(stepper, goal.row(0).transpose(), s.substeps, &points);
    } else if (s.method == Method::kOverall) {
      const TreeOverallReport report = StepTreeOverall(reacher, goal, s.overall, &points);
      passes = report.start.passes;
      residual = report.converged ? 0.0 : report.start.residual;
      reached = report.start.reached;
      converged = report.converged;
    } else {
      ReachReport report = ReachTargets(reacher, goal, &points);
      if (s.finish) report = FinishTreeReach(reacher, goal, report, &points);
      passes = report.passes;
      residual = report.residual;
      reached = report.reached;
      finished = report.finished;
    }
    r.passes.push_back(passes);
    r.residual.push_back(residual);
    r.reached.push_back(reached);
    r.converged.push_back(converged);
    r.finished.push_back(finished);
    r.frames.push_back(points);
    r.max_length_error = std::max(r.max_length_error, MaxTreeLengthError(links, points));
    if (progress) progress(f + 1, frames);
  }
  return r;
}

bool CheckTreeResultPath(const std::string& path) {
  auto ends_with = [&path](const std::string& end) {
    return path.size() >= end.size() &&
           path.compare(path.size() - end.size(), end.size(), end) == 0;
  };
  if (ends_with(".npz")) return true;
  if (ends_with(".json")) return false;
  throw InputError(
      Problem::Invalid("output", "\"" + path + "\"",
                       "a path ending in .npz or .json (a tree result, docs/trees.md)"));
}

bool IsTreeResultFile(const std::string& path) {
  if (JsonFileFormat(path) == "flexkin-tree-result") return true;
  try {
    ZipReader zip(path);
    return zip.Has("tree.json") && zip.Has("frames.npy");
  } catch (...) {
    return false;
  }
}

void WriteTreeResult(const std::string& path, const TreeScenario& s, const TreeRunResult& r) {
  const bool npz = CheckTreeResultPath(path);
  const bool goals = HasGoals(s, r);
  nlohmann::ordered_json header = TreeResultHeader(s, r);
  AtomicFile file(path);
  if (npz) {
    ZipWriter zip(&file);
    const uint64_t frames = r.frames.size(), rows = s.tree.points.rows(),
                   dim = s.tree.points.cols();
    std::string data = NpyHeader("<f8", {frames, rows, dim});
    for (const Points& p : r.frames) {
      data.append(reinterpret_cast<const char*>(p.data()), sizeof(double) * rows * dim);
    }
    zip.AddMember("frames.npy", data);
    auto ints = [&](const char* name, const std::vector<int>& v) {
      std::string d = NpyHeader("<i8", {v.size()});
      for (const int x : v) {
        const int64_t y = x;
        d.append(reinterpret_cast<const char*>(&y), sizeof(y));
      }
      zip.AddMember(name, d);
    };
    ints("parents.npy", s.tree.parents);
    // The goals: frame f's target k (f from 1), where it was driven or what it looked at.
    if (goals) {
      std::string goal_data = NpyHeader("<f8", {frames - 1, s.targets.size(), dim});
      for (uint64_t f = 1; f < frames; ++f) {
        for (const Points& path : s.paths) {
          goal_data.append(reinterpret_cast<const char*>(path.row(f - 1).data()),
                           sizeof(double) * dim);
        }
      }
      zip.AddMember("goals.npy", goal_data);
    }
    if (s.robot && r.angles.size() == r.frames.size()) {  // a robot's joints, every frame
      const uint64_t n = s.robot->joints();
      std::string angles = NpyHeader("<f8", {frames, n});
      for (const Eigen::VectorXd& q : r.angles) {
        angles.append(reinterpret_cast<const char*>(q.data()), sizeof(double) * n);
      }
      zip.AddMember("angles.npy", angles);
    }
    ints("passes.npy", r.passes);
    std::string res = NpyHeader("<f8", {r.residual.size()});
    res.append(reinterpret_cast<const char*>(r.residual.data()),
               sizeof(double) * r.residual.size());
    zip.AddMember("residual.npy", res);
    for (const auto& [name, v] :
         {std::pair<const char*, const std::vector<char>*>{"reached.npy", &r.reached},
          {"converged.npy", &r.converged},
          {"finished.npy", &r.finished}}) {
      std::string d = NpyHeader("|b1", {v->size()});
      for (const char c : *v) d.push_back(c ? 1 : 0);
      zip.AddMember(name, d);
    }
    zip.AddMember("tree.json", header.dump(2) + "\n");
    zip.Finish();
  } else {
    nlohmann::ordered_json frames = nlohmann::ordered_json::array();
    for (const Points& p : r.frames) {
      nlohmann::ordered_json rows = nlohmann::ordered_json::array();
      for (Eigen::Index i = 0; i < p.rows(); ++i) {
        rows.push_back(std::vector<double>(p.row(i).data(), p.row(i).data() + p.cols()));
      }
      frames.push_back(std::move(rows));
    }
    header["frames"] = std::move(frames);
    nlohmann::ordered_json goal_frames = nlohmann::ordered_json::array();
    for (size_t f = 1; goals && f < r.frames.size(); ++f) {
      nlohmann::ordered_json rows = nlohmann::ordered_json::array();
      for (const Points& path : s.paths) {
        rows.push_back(
            std::vector<double>(path.row(f - 1).data(), path.row(f - 1).data() + path.cols()));
      }
      goal_frames.push_back(std::move(rows));
    }
    if (goals) header["goals"] = std::move(goal_frames);
    if (s.robot && r.angles.size() == r.frames.size()) {
      nlohmann::ordered_json angles = nlohmann::ordered_json::array();
      for (const Eigen::VectorXd& q : r.angles) {
        angles.push_back(std::vector<double>(q.data(), q.data() + q.size()));
      }
      header["angles"] = std::move(angles);
    }
    header["passes"] = r.passes;
    header["residual"] = r.residual;
    header["reached"] = std::vector<bool>(r.reached.begin(), r.reached.end());
    header["converged"] = std::vector<bool>(r.converged.begin(), r.converged.end());
    header["finished"] = std::vector<bool>(r.finished.begin(), r.finished.end());
    file.stream() << header.dump() << "\n";
  }
  file.Check();
  file.Commit();
}

}  // namespace flexkin
