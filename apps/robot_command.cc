// flexkin robot: a robot scenario in, a trajectory JSON (and a joint CSV) out, each written whole
// or not at all. The scenario's format is in docs/robot-format.md.
#include "robot_command.h"

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <system_error>
#include <iomanip>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/result_io.h"
#include "flexkin/urdf.h"
#include "io/scenario_parser.h"

namespace flexkin::cli {
namespace {

using nlohmann::json;
using scenario_internal::JsonTypeName;
using scenario_internal::ShowJson;

constexpr double kPi = 3.14159265358979323846;

[[noreturn]] void Fail(const std::string& ptr, const std::string& message) {
  throw InputError(ptr, message);
}
[[noreturn]] void TypeFail(const json& v, const std::string& ptr, const std::string& expected) {
  Fail(ptr, "value " + ShowJson(v) + " (" + JsonTypeName(v) + ") is not valid; expected " + expected);
}

// Refuses keys outside `allowed`, suggesting the nearest one for a typo.
void CheckKeys(const json& obj, const std::string& ptr, const std::vector<std::string>& allowed) {
  for (const auto& item : obj.items()) {
    bool known = false;
    std::string nearest;
    size_t best = 3;
    for (const std::string& a : allowed) {
      known |= a == item.key();
      const size_t d = scenario_internal::EditDistance(a, item.key());
      if (d < best) best = d, nearest = a;
    }
    if (!known) {
      Fail(ptr + "/" + scenario_internal::EscapePointerToken(item.key()),
           "unknown key" + (nearest.empty() ? "; expected one of " + QuotedList(allowed)
                                            : "; did you mean \"" + nearest + "\"?"));
    }
  }
}

const json& Object(const json& v, const std::string& ptr) {
  if (!v.is_object()) TypeFail(v, ptr, "an object");
  return v;
}
const json* Find(const json& obj, const char* key) {
  const auto it = obj.find(key);
  return it == obj.end() ? nullptr : &*it;
}
const json& Require(const json& obj, const std::string& ptr, const char* key) {
  if (const json* v = Find(obj, key)) return *v;
  Fail(ptr + "/" + key, "missing; it is required");
}
double Number(const json& v, const std::string& ptr, bool positive = false) {
  if (!v.is_number()) TypeFail(v, ptr, positive ? "a finite number > 0" : "a finite number");
  const double x = v.get<double>();
  if (!std::isfinite(x) || (positive && !(x > 0.0))) {
    TypeFail(v, ptr, positive ? "a finite number > 0" : "a finite number");
  }
  return x;
}
int Integer(const json& v, const std::string& ptr, int min, int max) {
  const std::string expected =
      "an integer from " + std::to_string(min) + " to " + std::to_string(max);
  if (!v.is_number_integer() || v.get<int64_t>() < min || v.get<int64_t>() > max) {
    TypeFail(v, ptr, expected);
  }
  return static_cast<int>(v.get<int64_t>());
}
// A list of `size` numbers, or (if `broadcast`) one number meaning `size` equal values.
Eigen::VectorXd Numbers(const json& v, const std::string& ptr, int size, bool broadcast,
                        bool positive = false) {
  if (broadcast && v.is_number()) return Eigen::VectorXd::Constant(size, Number(v, ptr, positive));
  const std::string expected = (broadcast ? "a number or " : std::string()) + "a list of " +
                               std::to_string(size) + " numbers";
  if (!v.is_array() || static_cast<int>(v.size()) != size) TypeFail(v, ptr, expected);
  Eigen::VectorXd out(size);
  for (int i = 0; i < size; ++i) out[i] = Number(v[i], ptr + "/" + std::to_string(i), positive);
  return out;
}

ArmModel ParseArm(const json& arm, const std::string& ptr) {
  Object(arm, ptr);
  CheckKeys(arm, ptr, {"dim", "links", "link_length", "link_lengths", "base", "base_direction",
                       "joint_limits", "initial_angles", "initial_azimuths"});
  ArmModel m;
  m.dim = Find(arm, "dim") ? Integer(arm["dim"], ptr + "/dim", 2, 3) : 2;
  const int dim = m.dim;
  if (const json* lengths = Find(arm, "link_lengths")) {
    if (Find(arm, "link_length")) Fail(ptr + "/link_length", "give link_length or link_lengths, not both");
    if (!lengths->is_array() || lengths->empty()) TypeFail(*lengths, ptr + "/link_lengths", "a non-empty list of numbers > 0");
    m.link_lengths = Numbers(*lengths, ptr + "/link_lengths", static_cast<int>(lengths->size()), false, true);
    if (const json* links = Find(arm, "links")) {
      if (Integer(*links, ptr + "/links", 1, 1 << 20) != m.num_links()) {
        Fail(ptr + "/links", "value " + ShowJson(*links) + " differs from the " +
                                 std::to_string(m.num_links()) + " link_lengths");
      }
    }
  } else {
    const int n = Integer(Require(arm, ptr, "links"), ptr + "/links", 1, 1 << 20);
    const double l = Number(Require(arm, ptr, "link_length"), ptr + "/link_length", true);
    m.link_lengths = Eigen::VectorXd::Constant(n, l);
  }
  const int n = m.num_links();
  m.base = Find(arm, "base") ? Numbers(arm["base"], ptr + "/base", dim, false) : Eigen::VectorXd::Zero(dim);
  m.base_direction = Find(arm, "base_direction")
                         ? Numbers(arm["base_direction"], ptr + "/base_direction", dim, false)
                         : Eigen::VectorXd(Eigen::VectorXd::Unit(dim, 0));
  if (!(m.base_direction.squaredNorm() > 0.0)) Fail(ptr + "/base_direction", "is zero; expected a non-zero vector");
  if (const json* limits = Find(arm, "joint_limits")) {
    const std::string lp = ptr + "/joint_limits";
    Object(*limits, lp);
    if (dim == 2) {
      CheckKeys(*limits, lp, {"min", "max"});
      m.joint_min = Numbers(Require(*limits, lp, "min"), lp + "/min", n, true);
      m.joint_max = Numbers(Require(*limits, lp, "max"), lp + "/max", n, true);
      for (int j = 0; j < n; ++j) {
        if (!(-kPi <= m.joint_min[j] && m.joint_min[j] <= m.joint_max[j] && m.joint_max[j] <= kPi)) {
          Fail(lp, "joint " + std::to_string(j) + ": limits [" + FormatNumber(m.joint_min[j]) + ", " +
                       FormatNumber(m.joint_max[j]) + "] rad are not valid; expected -pi <= min <= max <= pi");
        }
      }
    } else {
      CheckKeys(*limits, lp, {"max_bend"});
      m.max_bend = Numbers(Require(*limits, lp, "max_bend"), lp + "/max_bend", n, true, true);
    }
  }
  m.initial.angle = Find(arm, "initial_angles")
                        ? Numbers(arm["initial_angles"], ptr + "/initial_angles", n, true)
                        : Eigen::VectorXd(Eigen::VectorXd::Zero(n));
  if (dim == 3) {
    m.initial.azimuth = Find(arm, "initial_azimuths")
                            ? Numbers(arm["initial_azimuths"], ptr + "/initial_azimuths", n, true)
                            : Eigen::VectorXd(Eigen::VectorXd::Zero(n));
  } else if (Find(arm, "initial_azimuths")) {
    Fail(ptr + "/initial_azimuths", "planar arms (dim 2) have no azimuths");
  }
  // What is left (ranges of the limits and the initial angles) is the model's own check.
  if (const std::optional<Problem> problem = m.FirstProblem()) {
    // The model's members as the robot file names them.
    std::string field = problem->field;
    const std::pair<const char*, const char*> keys[] = {{"initial.angle", "initial_angles"},
                                                        {"initial.azimuth", "initial_azimuths"},
                                                        {"max_bend", "joint_limits/max_bend"}};
    for (const auto& [member, key] : keys) {
      if (field.rfind(member, 0) == 0) field = key + field.substr(std::string(member).size());
    }
    Fail(ptr + scenario_internal::FieldToPointer(field), problem->message);
  }
  return m;
}

Points ParsePath(const json& path, const std::string& ptr, const ArmModel& model) {
  Object(path, ptr);
  const int dim = model.dim;
  const json& type = Require(path, ptr, "type");
  if (type == "points") {
    CheckKeys(path, ptr, {"type", "points"});
    const json& list = Require(path, ptr, "points");
    if (!list.is_array() || list.empty()) TypeFail(list, ptr + "/points", "a non-empty list of points");
    Points out(list.size(), dim);
    for (size_t i = 0; i < list.size(); ++i) {
      out.row(i) = Numbers(list[i], ptr + "/points/" + std::to_string(i), dim, false).transpose();
    }
    return out;
  }
  const Eigen::VectorXd ee = ForwardKinematics(model, model.initial).row(model.num_links()).transpose();
  if (type == "line") {
    CheckKeys(path, ptr, {"type", "to", "steps"});
    const Eigen::VectorXd to = Numbers(Require(path, ptr, "to"), ptr + "/to", dim, false);
    const int steps = Integer(Require(path, ptr, "steps"), ptr + "/steps", 1, 10000000);
    Points out(steps, dim);
    for (int i = 0; i < steps; ++i) out.row(i) = (ee + (to - ee) * (double(i + 1) / steps)).transpose();
    return out;
  }
  if (type == "circle") {
    CheckKeys(path, ptr, {"type", "center", "steps", "turns", "normal"});
    const Eigen::VectorXd c = Numbers(Require(path, ptr, "center"), ptr + "/center", dim, false);
    const int steps = Integer(Require(path, ptr, "steps"), ptr + "/steps", 1, 10000000);
    const double turns = Find(path, "turns") ? Number(path["turns"], ptr + "/turns", true) : 1.0;
    const Eigen::VectorXd r = ee - c;
    if (!(r.norm() > 0.0)) Fail(ptr + "/center", "is the end effector's initial position; the circle needs a radius");
    Eigen::VectorXd side(dim);
    if (dim == 2) {
      side << -r[1], r[0];
    } else {
      const Eigen::Vector3d normal =
          Find(path, "normal") ? Eigen::Vector3d(Numbers(path["normal"], ptr + "/normal", 3, false))
                               : Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d s = normal.normalized().cross(Eigen::Vector3d(r));
      if (!(s.norm() > 1e-12 * r.norm())) Fail(ptr + "/normal", "is zero or along the radius; expected a vector across it");
      side = s.normalized() * r.norm();
    }
    Points out(steps, dim);
    for (int i = 0; i < steps; ++i) {
      const double a = 2.0 * kPi * turns * (i + 1) / steps;
      out.row(i) = (c + std::cos(a) * r + std::sin(a) * side).transpose();
    }
    return out;
  }
  TypeFail(type, ptr + "/type", "\"points\", \"line\" or \"circle\"");
}

ArmOptions ParseSolver(const json& solver, const std::string& ptr) {
  Object(solver, ptr);
  CheckKeys(solver, ptr, {"method", "tolerance", "max_iterations", "max_fixed_point_iterations",
                          "substeps", "edge_margin", "restarts"});
  ArmOptions o;
  if (const json* v = Find(solver, "method")) {
    if (!v->is_string()) TypeFail(*v, ptr + "/method", "\"newton\" or \"fixed_point\"");
    o.method = ParseFixedBaseMethod(v->get<std::string>(), ptr + "/method");
  }
  if (const json* v = Find(solver, "tolerance")) o.tolerance = Number(*v, ptr + "/tolerance", true);
  if (const json* v = Find(solver, "max_iterations")) o.max_iterations = Integer(*v, ptr + "/max_iterations", 1, 1000000);
  if (const json* v = Find(solver, "max_fixed_point_iterations")) {
    o.max_fixed_point_iterations = Integer(*v, ptr + "/max_fixed_point_iterations", 1, 100000000);
  }
  if (const json* v = Find(solver, "substeps")) o.substeps = Integer(*v, ptr + "/substeps", 1, 1000000);
  if (const json* v = Find(solver, "edge_margin")) o.edge_margin = Number(*v, ptr + "/edge_margin");
  if (const json* v = Find(solver, "restarts")) o.restarts = Integer(*v, ptr + "/restarts", 0, 1000);
  if (const Problems problems = o.Validate(); !problems.empty()) {
    Fail(ptr + "/" + problems.front().field, problems.front().message);  // the keys are the members
  }
  return o;
}

// Fails before the run if an output's directory does not exist, so that no output is written
// when another cannot be.
void CheckDirectory(const std::string& path) {
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!std::filesystem::is_directory(dir.empty() ? "." : dir, ec)) {
    throw std::system_error(std::make_error_code(std::errc::no_such_file_or_directory),
                            "cannot write '" + path + "'");
  }
}

json Row(const Eigen::VectorXd& v) { return json(std::vector<double>(v.data(), v.data() + v.size())); }

json StateJson(const ArmModel& model, const ArmState& state) {
  json out;
  out["joint_angles"] = Row(state.angles.angle);
  if (model.dim == 3) {
    if (model.joint() == ArmJoint::kSpherical) out["joint_azimuths"] = Row(state.angles.azimuth);
    const Eigen::MatrixXd q = JointQuaternions(model, state.angles);
    out["joint_quaternions"] = json::array();
    for (int j = 0; j < q.rows(); ++j) out["joint_quaternions"].push_back(Row(q.row(j).transpose()));
  }
  out["points"] = json::array();
  for (int i = 0; i < state.points.rows(); ++i) out["points"].push_back(Row(state.points.row(i).transpose()));
  return out;
}

}  // namespace

// The arm of a scenario that names a URDF file ("urdf", "base_link", "tip_link").
ArmModel ParseUrdfArm(const json& root, const std::string& scenario_dir) {
  const json& file = Require(root, "", "urdf");
  if (!file.is_string() || file.get<std::string>().empty()) TypeFail(file, "/urdf", "a URDF file name");
  if (Find(root, "arm")) Fail("/arm", "give arm or urdf, not both");
  UrdfChain chain;
  for (const char* key : {"base_link", "tip_link"}) {
    if (const json* v = Find(root, key)) {
      if (!v->is_string()) TypeFail(*v, std::string("/") + key, "a link name");
      (key[0] == 'b' ? chain.base_link : chain.tip_link) = v->get<std::string>();
    }
  }
  std::filesystem::path path(file.get<std::string>());
  if (path.is_relative() && !scenario_dir.empty()) path = std::filesystem::path(scenario_dir) / path;
  try {
    return ArmFromUrdfFile(path.string(), chain);
  } catch (const InputError& e) {
    const std::string what = std::string(e.what()).substr(e.field().size() + 2);
    if (e.field() == "base_link" || e.field() == "tip_link") throw InputError("/" + e.field(), what);
    throw InputError("/urdf", path.string() + ": " + e.field() + ": " + what);
  }
}

RobotScenario ParseRobotScenario(const json& root, const std::string& scenario_dir) {
  Object(root, "");
  CheckKeys(root, "", {"format", "name", "arm", "urdf", "base_link", "tip_link", "path", "solver"});
  if (const json* f = Find(root, "format")) {
    if (*f != "flexkin-robot") TypeFail(*f, "/format", "\"flexkin-robot\"");
  }
  RobotScenario s;
  if (const json* name = Find(root, "name")) {
    if (!name->is_string()) TypeFail(*name, "/name", "a string");
    s.name = name->get<std::string>();
  }
  if (Find(root, "urdf")) {
    s.model = ParseUrdfArm(root, scenario_dir);
  } else {
    for (const char* key : {"base_link", "tip_link"}) {
      if (Find(root, key)) Fail(std::string("/") + key, "belongs to a URDF arm; expected \"urdf\" too");
    }
    s.model = ParseArm(Require(root, "", "arm"), "/arm");
  }
  s.path = ParsePath(Require(root, "", "path"), "/path", s.model);
  if (const json* solver = Find(root, "solver")) s.options = ParseSolver(*solver, "/solver");
  return s;
}

RobotCommand::RobotCommand(CLI::App* app, const std::string& footer) {
  command_ = app->add_subcommand(
      "robot", "Joint trajectories of a fixed-base arm whose end effector follows a path.");
  command_->add_option("scenario", scenario_, "Robot scenario (JSON, docs/robot-format.md)")->required();
  command_->add_option("-o,--output", output_, "Trajectory file to write (JSON)")->required();
  command_->add_option("--csv", csv_, "Also write the joint trajectories as CSV");
  command_->add_option("--method", method_, "newton (default) or fixed_point (the baseline)");
  command_->add_flag("-q,--quiet", quiet_, "Print no report");
  command_->footer(footer);
}

int RobotCommand::Run() const {
  RobotScenario s;
  try {
    s = ParseRobotScenario(ReadJsonFile(scenario_),
                           std::filesystem::path(scenario_).parent_path().string());
    if (!method_.empty()) s.options.method = ParseFixedBaseMethod(method_, "--method");
  } catch (const InputError& e) {
    throw InputError(scenario_ + ": " + e.field(), std::string(e.what()).substr(e.field().size() + 2));
  }
  CheckDirectory(output_);
  if (!csv_.empty()) CheckDirectory(csv_);
  const ArmTrajectory t = TrackPath(s.model, s.path, s.options);
  const ArmState initial = InitialState(s.model);

  json doc;
  doc["format"] = "flexkin-robot-trajectory";
  doc["version"] = 1;
  if (!s.name.empty()) doc["scenario"] = s.name;
  doc["dim"] = s.model.dim;
  doc["link_lengths"] = Row(s.model.link_lengths);
  doc["base"] = Row(s.model.base);
  doc["method"] = FixedBaseMethodName(s.options.method);
  doc["tolerance"] = s.options.tolerance;
  doc["summary"] = {{"steps", t.steps.size()},          {"unreached", t.unreached},
                    {"max_ee_error", t.max_ee_error},   {"max_base_error", t.max_base_error},
                    {"max_iterations", t.max_iterations}, {"total_sweeps", t.total_sweeps},
                    {"seconds", t.seconds}};
  doc["initial"] = StateJson(s.model, initial);
  doc["steps"] = json::array();
  for (size_t i = 0; i < t.steps.size(); ++i) {
    const ArmStepReport& r = t.steps[i];
    json step = StateJson(s.model, r.state);
    step["step"] = i + 1;
    step["target"] = Row(s.path.row(i).transpose());
    step["ee_error"] = r.ee_error;
    step["base_error"] = r.base_error;
    step["iterations"] = r.iterations;
    step["sweeps"] = r.sweeps;
    step["reached"] = r.reached;
    step["stretched"] = r.stretched;
    step["limited"] = r.limited;
    step["legs"] = r.legs;
    step["joint_space"] = r.joint_space;
    step["restarts"] = r.restarts;
    doc["steps"].push_back(std::move(step));
  }
  // One key per line and one step per line: readable, and diffs stay local.
  WriteFileAtomically(output_, [&](std::ostream& out) {
    const char* separator = "{\n";
    for (const auto& item : doc.items()) {
      out << separator << json(item.key()).dump() << ": ";
      separator = ",\n";
      if (item.key() != "steps") {
        out << item.value().dump();
        continue;
      }
      out << "[";
      for (size_t i = 0; i < item.value().size(); ++i) {
        out << (i == 0 ? "\n  " : ",\n  ") << item.value()[i].dump();
      }
      out << "\n]";
    }
    out << "\n}\n";
  });
  if (!csv_.empty()) {
    WriteFileAtomically(csv_, [&](std::ostream& out) {
      const int n = s.model.num_links();
      out << "step";
      for (int j = 0; j < n; ++j) out << ",joint_" << j;
      if (s.model.dim == 3) for (int j = 0; j < n; ++j) out << ",azimuth_" << j;
      out << "\n" << std::setprecision(17);
      auto row = [&](size_t step, const JointAngles& a) {
        out << step;
        for (int j = 0; j < n; ++j) out << "," << a.angle[j];
        for (int j = 0; j < a.azimuth.size(); ++j) out << "," << a.azimuth[j];
        out << "\n";
      };
      row(0, initial.angles);
      for (size_t i = 0; i < t.steps.size(); ++i) row(i + 1, t.steps[i].state.angles);
    });
  }
  if (!quiet_) std::cout << t.BriefReport() << "\n";
  if (t.unreached > 0) {
    std::cerr << "flexkin: warning: " << t.unreached << " of " << t.steps.size()
              << " targets were not reached (see \"reached\" in " << output_ << ")\n";
    return 3;
  }
  return 0;
}

}  // namespace flexkin::cli
