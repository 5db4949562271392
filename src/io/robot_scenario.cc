// Robot scenario files in (docs/robot-format.md): a RobotParser on the value readers every file
// reader shares (src/io/json_values.h), so numbers, messages and suggestions are those of
// scenario files, and every problem is listed before the first one is thrown.
#include "flexkin/robot_scenario.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "arm/colliders.h"
#include "flexkin/arm.h"
#include "flexkin/error.h"
#include "flexkin/leader.h"
#include "flexkin/scenario_kind.h"
#include "flexkin/vocabulary.h"
#include "io/colliders_json.h"
#include "io/json_file.h"
#include "io/json_values.h"
#include "io/scenario_kinds.h"

namespace flexkin {
namespace {

using json_internal::json;
using json_internal::Range;
using json_internal::ShowJson;

constexpr double kPi = 3.14159265358979323846;
constexpr int64_t kMaxLinks = int64_t{1} << 20;
constexpr int64_t kMaxSteps = kMaxLeaderSteps;

const char* const kPathExpected =
    "an object {\"type\": \"points\", \"points\": [...]}, {\"type\": \"line\", \"to\": p, "
    "\"steps\": m} or {\"type\": \"circle\", \"center\": c, \"steps\": m}";

// An ArmModel member path ("initial.angle[0]", "max_bend[2]") as the robot file's JSON pointer
// below "/arm" ("/initial_angles/0", "/joint_limits/max_bend/2").
std::string ArmFieldToPointer(std::string field) {
  const std::pair<const char*, const char*> keys[] = {{"initial.angle", "initial_angles"},
                                                      {"initial.azimuth", "initial_azimuths"},
                                                      {"max_bend", "joint_limits.max_bend"},
                                                      {"joint_min", "joint_limits.min"},
                                                      {"joint_max", "joint_limits.max"}};
  for (const auto& [member, key] : keys) {
    const std::string m = member;
    if (field.compare(0, m.size(), m) == 0 &&
        (field.size() == m.size() || field[m.size()] == '[' || field[m.size()] == '.')) {
      field = key + field.substr(m.size());
      break;
    }
  }
  return MemberPathToPointer(field);
}

class RobotParser : public json_internal::JsonReader {
 public:
  RobotParser(const RobotScenarioOptions& options, std::string directory)
      : options_(options), directory_(std::move(directory)) {
    dimension_of_ = "the arm";
  }

  // The scenario; valid if and only if no problem was added.
  RobotScenario Parse(const json& root) {
    RobotScenario s;
    if (!ExpectObject(root, "", "an object with \"arm\" (or \"urdf\") and \"path\"")) return s;
    CheckKeys(root, "",
              {"format", "name", "arm", "urdf", "base_link", "tip_link", "tip_offset", "pointing",
               "path", "solver", "colliders", "link_radius"});
    if (const json* f = Find(root, "format")) {
      if (!f->is_string()) {
        TypeProblem(*f, "/format", "\"flexkin-robot\"");
      } else if (*f != "flexkin-robot") {
        ValueProblem(*f, "/format", "\"flexkin-robot\"");
      }
    }
    Optional(
        root, "", "name", [this](const json& v, const std::string& p) { return String(v, p); },
        &s.name);
    std::optional<ArmModel> model;
    int dim = 0;  // unknown
    if (Find(root, "urdf")) {
      model = ParseUrdfArm(root);
    } else {
      for (const char* key : {"base_link", "tip_link", "tip_offset"}) {
        if (Find(root, key)) {
          Add(std::string("/") + key, "belongs to a URDF arm; expected \"urdf\" too");
        }
      }
      if (const json* arm = Required(root, "", "arm",
                                     "an object {\"links\": n, \"link_length\": l, ...}, or "
                                     "\"urdf\": a URDF file")) {
        model = ParseArm(*arm, "/arm", &dim);
      }
    }
    if (model) dim = model->dim;
    std::optional<Points> path;
    if (const json* p = Required(root, "", "path", kPathExpected)) {
      path = ParsePath(*p, "/path", model ? &*model : nullptr, dim);
    }
    if (const json* solver = Find(root, "solver")) ParseSolver(*solver, "/solver", &s.options);
    if (const json* pointing = Find(root, "pointing")) {
      ParsePointing(*pointing, "/pointing", &s.options.pointing);
    }
    if (const json* c = Find(root, "colliders"); c != nullptr && dim != 0) {
      s.options.colliders = ReadCollidersJson(*c, "/colliders", dim, &problems, directory_);
    }
    if (model) ParseLinkRadius(root, &*model);
    if (model) {
      for (const Problem& p : s.options.ValidateFor(*model)) {
        Add(p.field == "method" ? "/solver/method" : "/" + p.field, p.message);
      }
    }
    if (model && path && problems.empty()) CheckOutside(*model, *path, s.options);
    if (!problems.empty()) return s;
    s.model = std::move(*model);
    s.path = std::move(*path);
    return s;
  }

 private:
  std::optional<int> Int(const json& v, const std::string& ptr, int64_t min, int64_t max) {
    const auto n = Integer(v, ptr, min, max);
    return n ? std::optional<int>(static_cast<int>(*n)) : std::nullopt;
  }

  // "arm": sets *dim to the arm's dimension when it could be read.
  std::optional<ArmModel> ParseArm(const json& arm, const std::string& ptr, int* dim) {
    if (!ExpectObject(arm, ptr, "an object {\"links\": n, \"link_length\": l, ...}")) {
      return std::nullopt;
    }
    CheckKeys(arm, ptr,
              {"dim", "links", "link_length", "link_lengths", "base", "base_direction",
               "joint_limits", "initial_angles", "initial_azimuths"});
    const size_t before = problems.size();
    ArmModel m;
    Optional(
        arm, ptr, "dim", [this](const json& v, const std::string& p) { return Int(v, p, 2, 3); },
        &m.dim);
    const bool dim_known = problems.size() == before;
    *dim = dim_known ? m.dim : 0;

    // The links: their number n is known when it could be read (0 otherwise).
    int n = 0;
    if (const json* lengths = Find(arm, "link_lengths")) {
      if (Find(arm, "link_length")) {
        Add(ptr + "/link_length",
            "is not valid with \"link_lengths\"; give link_lengths, or links "
            "and link_length");
      }
      if (const auto l = NumberList(*lengths, ptr + "/link_lengths", 1, Range::kPositive)) {
        m.link_lengths = *l;
        n = m.num_links();
      }
      if (const json* links = Find(arm, "links")) {
        const auto count = Int(*links, ptr + "/links", 1, kMaxLinks);
        if (count && n > 0 && *count != n) {
          Add(ptr + "/links", "value " + ShowJson(*links) + " differs from the " +
                                  std::to_string(n) + " link_lengths");
        }
      }
    } else {
      std::optional<int> count;
      std::optional<double> length;
      if (const json* v = Required(arm, ptr, "links",
                                   "an integer >= 1 (the number of links), or \"link_lengths\"")) {
        count = Int(*v, ptr + "/links", 1, kMaxLinks);
      }
      if (const json* v = Required(arm, ptr, "link_length",
                                   "a finite number > 0 (the length of every link), or "
                                   "\"link_lengths\"")) {
        length = Number(*v, ptr + "/link_length", Range::kPositive);
      }
      if (count) n = *count;
      if (count && length) m.link_lengths = Eigen::VectorXd::Constant(n, *length);
    }

    const auto vector = [this, dim = *dim](const json& v, const std::string& p) {
      return Vector(v, p, dim);
    };
    m.base = Eigen::VectorXd::Zero(std::max(*dim, 2));
    Optional(arm, ptr, "base", vector, &m.base);
    m.base_direction = Eigen::VectorXd::Unit(std::max(*dim, 2), 0);
    const size_t before_direction = problems.size();
    Optional(arm, ptr, "base_direction", vector, &m.base_direction);
    if (problems.size() == before_direction && !(m.base_direction.squaredNorm() > 0.0)) {
      Add(ptr + "/base_direction", "is zero; expected a non-zero vector");
    }

    const auto per_joint = [this, n](Range range) {
      return [this, n, range](const json& v, const std::string& p) {
        return NumberPerItem(v, p, n, range, "joint");
      };
    };
    if (const json* limits = Find(arm, "joint_limits")) {
      const std::string lp = ptr + "/joint_limits";
      const char* expected = !dim_known   ? "an object"
                             : m.dim == 2 ? "an object {\"min\": m, \"max\": M}"
                                          : "an object {\"max_bend\": b}";
      if (ExpectObject(*limits, lp, expected) && dim_known) {
        if (m.dim == 2) {
          CheckKeys(*limits, lp, {"min", "max"});
          const size_t before_limits = problems.size();
          Require(*limits, lp, "min", "a number or an array of one number per joint (rad)",
                  per_joint(Range::kAny), &m.joint_min);
          Require(*limits, lp, "max", "a number or an array of one number per joint (rad)",
                  per_joint(Range::kAny), &m.joint_max);
          for (int j = 0; problems.size() == before_limits && j < n; ++j) {
            if (!(-kPi <= m.joint_min[j] && m.joint_min[j] <= m.joint_max[j] &&
                  m.joint_max[j] <= kPi)) {
              Add(lp, "joint " + std::to_string(j) + ": limits [" + FormatNumber(m.joint_min[j]) +
                          ", " + FormatNumber(m.joint_max[j]) +
                          "] rad are not valid; expected -pi <= min <= max <= pi");
              break;
            }
          }
        } else {
          CheckKeys(*limits, lp, {"max_bend"});
          Require(*limits, lp, "max_bend", "a number > 0 or an array of one per joint (rad)",
                  per_joint(Range::kPositive), &m.max_bend);
        }
      }
    }
    m.initial.angle = Eigen::VectorXd::Zero(n);
    Optional(arm, ptr, "initial_angles", per_joint(Range::kAny), &m.initial.angle);
    if (dim_known && m.dim == 3) {
      m.initial.azimuth = Eigen::VectorXd::Zero(n);
      Optional(arm, ptr, "initial_azimuths", per_joint(Range::kAny), &m.initial.azimuth);
    } else if (dim_known && Find(arm, "initial_azimuths")) {
      Add(ptr + "/initial_azimuths",
          "is only valid for spatial arms (dim 3); planar arms (dim 2) "
          "have no azimuths");
    }
    if (problems.size() != before || n == 0) return std::nullopt;
    // What is left (the ranges of the limits and of the initial angles) is the model's own check.
    for (Problem p : m.Validate()) {
      p.field = ptr + ArmFieldToPointer(p.field);
      problems.push_back(std::move(p));
    }
    if (problems.size() != before) return std::nullopt;
    return m;
  }

  // "link_radius": a radius >= 0 for every link, or one per link. A URDF arm's links keep the
  // radius of their collision geometry; links without one (radius 0) take this value.
  void ParseLinkRadius(const json& root, ArmModel* model) {
    const json* v = Find(root, "link_radius");
    if (v == nullptr) return;
    const int n = model->num_links();
    const auto radii = NumberPerItem(*v, "/link_radius", n, Range::kNonNegative, "link");
    if (!radii) return;
    if (model->link_radii.size() != n) model->link_radii = Eigen::VectorXd::Zero(n);
    for (int k = 0; k < n; ++k) {
      if (model->link_radii[k] == 0.0) model->link_radii[k] = (*radii)[k];
    }
  }

  // Neither the start nor a target inside a collider (the checks TrackPath makes, here with the
  // scenario's pointers).
  void CheckOutside(const ArmModel& model, const Points& path, const ArmOptions& options) {
    if (options.colliders.empty() || model.has_axes()) return;
    try {
      arm_internal::CheckArmOutside(model, ForwardKinematics(model, model.initial),
                                    options.colliders, "/colliders");
      for (int i = 0; i < path.rows(); ++i) {
        arm_internal::CheckTargetOutside(model, options, path.row(i).transpose(),
                                         "/path (target " + std::to_string(i) + ")");
      }
    } catch (const InputError& e) {
      problems.push_back(e.problem());
    }
  }

  // "urdf", "base_link", "tip_link": the arm read by the URDF loader.
  std::optional<ArmModel> ParseUrdfArm(const json& root) {
    const size_t before = problems.size();
    const json& urdf = *Find(root, "urdf");
    std::string file;
    if (const auto name = String(urdf, "/urdf")) {
      if (name->empty()) {
        ValueProblem(urdf, "/urdf", "a URDF file name");
      } else {
        file = *name;
      }
    }
    if (Find(root, "arm")) Add("/arm", "is not valid with \"urdf\"; give arm or urdf, not both");
    UrdfChain chain;
    Optional(
        root, "", "base_link", [this](const json& v, const std::string& p) { return String(v, p); },
        &chain.base_link);
    Optional(
        root, "", "tip_link", [this](const json& v, const std::string& p) { return String(v, p); },
        &chain.tip_link);
    std::optional<Eigen::VectorXd> offset;
    Optional(
        root, "", "tip_offset",
        [this](const json& v, const std::string& p) { return Vector(v, p, 3); }, &offset);
    if (offset) chain.tip_offset = *offset;
    if (problems.size() != before) return std::nullopt;
    if (!options_.urdf_loader) {
      Add("/urdf", "value " + ShowJson(urdf) +
                       " names a URDF file, but this reader has no URDF loader; expected an "
                       "\"arm\", or a reader given RobotScenarioOptions::urdf_loader (the URDF "
                       "component's UrdfRobotScenarioOptions(), flexkin/urdf.h)");
      return std::nullopt;
    }
    std::filesystem::path path(file);
    if (path.is_relative() && !directory_.empty()) path = std::filesystem::path(directory_) / path;
    try {
      return options_.urdf_loader(path.string(), chain);
    } catch (const InputError& e) {
      Problem p = e.problem();
      if (p.field == "base_link" || p.field == "tip_link" || p.field == "tip_offset") {
        p.field = "/" + p.field;
      } else {
        p.message = path.string() + ": " + p.Text();
        p.field = "/urdf";
      }
      problems.push_back(std::move(p));
      return std::nullopt;
    }
  }

  // "path": the targets, one per row. Without a model only the values are checked (dim 0:
  // points of 2 or 3 coordinates).
  std::optional<Points> ParsePath(const json& path, const std::string& ptr, const ArmModel* model,
                                  int dim) {
    if (!ExpectObject(path, ptr, kPathExpected)) return std::nullopt;
    const size_t before = problems.size();
    std::optional<std::string> type;
    if (const json* t = Required(path, ptr, "type", "one of \"points\", \"line\" or \"circle\"")) {
      type = Choice(*t, ptr + "/type", {"points", "line", "circle"});
    }
    if (!type) return std::nullopt;
    const auto vector = [this, dim](const json& v, const std::string& p) {
      return Vector(v, p, dim);
    };
    const auto steps_of = [this](const json& v, const std::string& p) {
      return Integer(v, p, 1, kMaxSteps);
    };
    if (*type == "points") {
      CheckKeys(path, ptr, {"type", "points"});
      std::optional<Points> points;
      if (const json* list = Required(path, ptr, "points", "an array of at least 1 point")) {
        points = PointList(*list, ptr + "/points", dim, 1, kMaxSteps);
      }
      if (problems.size() != before || model == nullptr) return std::nullopt;
      return points;
    }
    if (*type == "line") {
      CheckKeys(path, ptr, {"type", "to", "steps"});
      Eigen::VectorXd to;
      int64_t steps = 1;
      Require(path, ptr, "to", "a point (the end of the line)", vector, &to);
      Require(path, ptr, "steps", "an integer >= 1", steps_of, &steps);
      if (problems.size() != before || model == nullptr) return std::nullopt;
      const Eigen::VectorXd ee =
          ForwardKinematics(*model, model->initial).row(model->num_links()).transpose();
      Points out(steps, dim);
      for (int i = 0; i < steps; ++i) {
        out.row(i) = (ee + (to - ee) * (double(i + 1) / steps)).transpose();
      }
      return out;
    }
    CheckKeys(path, ptr, {"type", "center", "steps", "turns", "normal"});
    Eigen::VectorXd c;
    int64_t steps = 1;
    double turns = 1.0;
    Eigen::VectorXd normal = Eigen::Vector3d::UnitZ();
    Require(path, ptr, "center", "a point (the circle's center)", vector, &c);
    Require(path, ptr, "steps", "an integer >= 1", steps_of, &steps);
    Optional(
        path, ptr, "turns",
        [this](const json& v, const std::string& p) { return Number(v, p, Range::kPositive); },
        &turns);
    if (dim == 2 && Find(path, "normal")) {
      Add(ptr + "/normal",
          "is only valid for spatial arms (dim 3); a planar circle lies in the "
          "plane");
    } else {
      Optional(
          path, ptr, "normal",
          [this](const json& v, const std::string& p) { return Vector(v, p, 3); }, &normal);
    }
    if (problems.size() != before || model == nullptr) return std::nullopt;
    const Eigen::VectorXd ee =
        ForwardKinematics(*model, model->initial).row(model->num_links()).transpose();
    const Eigen::VectorXd r = ee - c;
    if (!(r.norm() > 0.0)) {
      Add(ptr + "/center", "is the end effector's initial position; the circle needs a radius");
      return std::nullopt;
    }
    Eigen::VectorXd side(dim);
    if (dim == 2) {
      side << -r[1], r[0];
    } else {
      const Eigen::Vector3d s = Eigen::Vector3d(normal).normalized().cross(Eigen::Vector3d(r));
      if (!(s.norm() > 1e-12 * r.norm())) {
        Add(ptr + "/normal", "is zero or along the radius; expected a vector across it");
        return std::nullopt;
      }
      side = s.normalized() * r.norm();
    }
    Points out(steps, dim);
    for (int i = 0; i < steps; ++i) {
      const double a = 2.0 * kPi * turns * (i + 1) / steps;
      out.row(i) = (c + std::cos(a) * r + std::sin(a) * side).transpose();
    }
    return out;
  }

  void ParseSolver(const json& solver, const std::string& ptr, ArmOptions* o) {
    if (!ExpectObject(solver, ptr, "an object {\"method\": \"newton\", \"tolerance\": t, ...}")) {
      return;
    }
    CheckKeys(solver, ptr,
              {"method", "tolerance", "max_iterations", "max_fixed_point_iterations", "substeps",
               "edge_margin", "restarts", "time_step"});
    const size_t before = problems.size();
    if (const json* v = Find(solver, "method")) {
      if (const auto name = String(*v, ptr + "/method")) {
        if (const NamedValue<FixedBaseMethod>* entry = FindName<FixedBaseMethod>(*name)) {
          o->method = entry->value;
        } else {
          problems.push_back(UnknownName(ptr + "/method", Vocabulary<FixedBaseMethod>::kKind, *name,
                                         NamesOf<FixedBaseMethod>()));
        }
      }
    }
    const auto number = [this](Range range) {
      return [this, range](const json& v, const std::string& p) { return Number(v, p, range); };
    };
    const auto integer = [this](int64_t min, int64_t max) {
      return [this, min, max](const json& v, const std::string& p) { return Int(v, p, min, max); };
    };
    Optional(solver, ptr, "tolerance", number(Range::kPositive), &o->tolerance);
    Optional(solver, ptr, "max_iterations", integer(1, 1000000), &o->max_iterations);
    Optional(solver, ptr, "max_fixed_point_iterations", integer(1, 100000000),
             &o->max_fixed_point_iterations);
    Optional(solver, ptr, "substeps", integer(1, 1000000), &o->substeps);
    Optional(solver, ptr, "edge_margin", number(Range::kAny), &o->edge_margin);
    Optional(solver, ptr, "restarts", integer(0, 1000), &o->restarts);
    Optional(solver, ptr, "time_step", number(Range::kNonNegative), &o->time_step);
    if (problems.size() != before) return;
    // What is left (tolerance < 1, the edge margin's range) is the options' own check; their
    // members are the keys.
    for (Problem p : o->Validate()) {
      p.field = ptr + MemberPathToPointer(p.field);
      problems.push_back(std::move(p));
    }
  }

  // "pointing": {"axis": a, "direction": d} or {"axis": a, "look_at": p}, "weight", "tolerance".
  void ParsePointing(const json& pointing, const std::string& ptr, ArmOptions::Pointing* o) {
    if (!ExpectObject(pointing, ptr,
                      "an object {\"axis\": [x, y, z], \"direction\": [x, y, z]} or with "
                      "\"look_at\": [x, y, z]")) {
      return;
    }
    CheckKeys(pointing, ptr, {"axis", "direction", "look_at", "weight", "tolerance"});
    const size_t before = problems.size();
    const auto vector = [this](const json& v, const std::string& p) { return Vector(v, p, 3); };
    std::optional<Eigen::VectorXd> axis, direction, point;
    Optional(pointing, ptr, "axis", vector, &axis);
    Optional(pointing, ptr, "direction", vector, &direction);
    Optional(pointing, ptr, "look_at", vector, &point);
    if (direction && point) {
      Add(ptr + "/look_at", "is not valid with \"direction\"; give one of them");
    } else if (!direction && !point) {
      Add(ptr, "has neither \"direction\" nor \"look_at\"; expected one of them");
    }
    Optional(
        pointing, ptr, "weight",
        [this](const json& v, const std::string& p) { return Number(v, p, Range::kPositive); },
        &o->weight);
    Optional(
        pointing, ptr, "tolerance",
        [this](const json& v, const std::string& p) { return Number(v, p, Range::kPositive); },
        &o->angle_tolerance);
    if (problems.size() != before) return;
    o->enabled = true;
    if (axis) o->axis = *axis;
    if (direction) o->direction = *direction;
    if (point) {
      o->look_at = true;
      o->point = *point;
    }
    ArmOptions options;
    options.pointing = *o;
    for (Problem p : options.Validate()) {  // zero vectors, a tolerance of 1 rad or more
      p.field = ptr + MemberPathToPointer(p.field.substr(std::string("pointing.").size()));
      problems.push_back(std::move(p));
    }
  }

  const RobotScenarioOptions& options_;
  std::string directory_;
};

RobotScenario ParseRobotJson(const json& root, const RobotScenarioOptions& options,
                             const std::string& directory) {
  RobotParser parser(options, directory);
  RobotScenario scenario = parser.Parse(root);
  ThrowIfAny(parser.problems);
  return scenario;
}

Problems ValidateRobotText(const std::string& json_text, const RobotScenarioOptions& options,
                           const std::string& directory) {
  json root;
  try {
    root = ParseJsonText(json_text);
  } catch (const InputError& e) {
    return {e.problem()};
  }
  RobotParser parser(options, directory);
  parser.Parse(root);
  return std::move(parser.problems);
}

// The directory relative URDF paths of the scenario file at `path` are taken from.
std::string DirectoryOf(const std::string& path, const RobotScenarioOptions& options) {
  if (!options.directory.empty()) return options.directory;
  return std::filesystem::path(path).parent_path().string();
}

}  // namespace

namespace internal {
RobotScenario ReadRobotScenario(const json& root, const RobotScenarioOptions& options,
                                const std::string& directory, Problems* problems) {
  RobotParser parser(options, directory);
  RobotScenario scenario = parser.Parse(root);
  for (Problem& p : parser.problems) problems->push_back(std::move(p));
  return scenario;
}
}  // namespace internal

RobotScenario ParseRobotScenarioText(const std::string& json_text,
                                     const RobotScenarioOptions& options) {
  return ParseRobotJson(ParseJsonText(json_text), options, options.directory);
}

Problems ValidateRobotScenarioText(const std::string& json_text,
                                   const RobotScenarioOptions& options) {
  return ValidateRobotText(json_text, options, options.directory);
}

RobotScenario LoadRobotScenarioFile(const std::string& path, const RobotScenarioOptions& options) {
  return ParseRobotJson(ReadJsonFile(path), options, DirectoryOf(path, options));
}

Problems ValidateRobotScenarioFile(const std::string& path, const RobotScenarioOptions& options) {
  return ValidateRobotText(ReadTextFile(path), options, DirectoryOf(path, options));
}

bool IsRobotScenarioText(const std::string& json_text) {
  return ScenarioKindOfText(json_text) == ScenarioKind::kRobot;
}

bool IsRobotScenarioFile(const std::string& path) {
  return IsRobotScenarioText(ReadTextFile(path));
}

std::string RobotScenarioSummary(const RobotScenario& s) {
  const ArmModel& m = s.model;
  char reach[40], tolerance[40];
  std::snprintf(reach, sizeof reach, "%.6g", m.reach());
  std::snprintf(tolerance, sizeof tolerance, "%.3g", s.options.tolerance);
  const auto rows = s.path.rows();
  std::string out = "robot, " + std::to_string(m.dim) + "D, " + std::to_string(m.num_links()) +
                    (m.num_links() == 1 ? " link, " : " links, ") + NameOf(m.joint()) +
                    " joints (reach " + reach + ")" + (m.has_limits() ? ", joint limits" : "") +
                    ", " + std::to_string(rows) + (rows == 1 ? " target" : " targets") +
                    ", method " + FixedBaseMethodName(s.options.method) + ", tolerance " +
                    tolerance;
  if (s.options.substeps > 1) out += ", " + std::to_string(s.options.substeps) + " sub-steps";
  if (m.has_axes()) {
    int prismatic = 0;
    for (int j = 0; j < m.num_links(); ++j) prismatic += m.prismatic(j) ? 1 : 0;
    const size_t points = JointGroups(m).size();
    if (prismatic > 0) out += ", " + std::to_string(prismatic) + " prismatic";
    if (points < static_cast<size_t>(m.num_links())) {
      out +=
          ", " + std::to_string(m.num_links()) + " joints at " + std::to_string(points) + " points";
    }
  }
  if (s.options.pointing.enabled) out += ", pointing";
  if (s.options.time_step > 0.0 && m.max_velocity.size() > 0) out += ", velocity limits";
  return out;
}

}  // namespace flexkin
