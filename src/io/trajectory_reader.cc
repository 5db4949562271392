// Robot trajectory files in (docs/robot-format.md, "Outputs"): what drawing them takes, each
// value checked once where it enters (the first problem thrown, named by its JSON pointer), and
// the trajectory as a chain result for the pictures and the viewer.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/robot_scenario.h"
#include "io/colliders_json.h"
#include "io/json_checked.h"
#include "io/json_file.h"
#include "io/result_check.h"

namespace flexkin {
namespace {

using json = nlohmann::json;

using json_checked::Member;
using json_checked::ReadInteger;
using json_checked::ReadNumber;
using json_checked::Show;

// An array of numbers; `size` < 0 accepts any length >= 1.
Eigen::VectorXd Vector(const json& v, const std::string& ptr, Eigen::Index size) {
  if (!v.is_array() || v.empty() || (size >= 0 && v.size() != static_cast<size_t>(size))) {
    throw InputError(ptr, "value " + Show(v) + " is not valid; expected an array of " +
                              (size >= 0 ? std::to_string(size) + " " : std::string()) + "numbers");
  }
  Eigen::VectorXd out(v.size());
  for (size_t i = 0; i < v.size(); ++i) out[i] = ReadNumber(v[i], ptr + "/" + std::to_string(i));
  return out;
}

// A state's "points": `rows` points of `dim` numbers (rows 0: as many as the first state has,
// at least 2).
Points StatePoints(const json& state, const std::string& ptr, Eigen::Index rows, int dim) {
  const json& v = Member(state, ptr, "points");
  const std::string at = ptr + "/points";
  if (!v.is_array() || v.size() < 2 || (rows > 0 && v.size() != static_cast<size_t>(rows))) {
    throw InputError(at, "is not valid; expected an array of " +
                             (rows > 0 ? std::to_string(rows) : std::string("at least 2")) +
                             " points (base first, as in \"initial\")");
  }
  Points points(static_cast<Eigen::Index>(v.size()), dim);
  for (size_t i = 0; i < v.size(); ++i) {
    points.row(static_cast<Eigen::Index>(i)) =
        Vector(v[i], at + "/" + std::to_string(i), dim).transpose();
  }
  return points;
}

RobotTrajectoryFile TrajectoryFromJson(const json& j) {
  RobotTrajectoryFile t;
  const json& format = Member(j, "", "format");
  if (format != kRobotTrajectoryFormat) {
    throw InputError("/format", "value " + Show(format) + " is not valid; expected \"" +
                                    kRobotTrajectoryFormat + "\"");
  }
  const json& version = Member(j, "", "version");
  if (version != kRobotTrajectoryVersion) {
    throw InputError("/version", "value " + Show(version) + " is not supported; expected " +
                                     std::to_string(kRobotTrajectoryVersion));
  }
  if (const auto it = j.find("scenario"); it != j.end()) {
    if (!it->is_string()) throw InputError("/scenario", "value " + Show(*it) + " is not a string");
    t.scenario_name = it->get<std::string>();
  }
  t.dim = static_cast<int>(ReadInteger(Member(j, "", "dim"), "/dim", 2));
  if (t.dim > 3) throw InputError("/dim", "value " + std::to_string(t.dim) + " is not 2 or 3");
  const json& method = Member(j, "", "method");
  if (!method.is_string())
    throw InputError("/method", "value " + Show(method) + " is not a string");
  t.method = method.get<std::string>();
  t.link_lengths = Vector(Member(j, "", "link_lengths"), "/link_lengths", -1);
  t.base = Vector(Member(j, "", "base"), "/base", t.dim);
  if (const auto it = j.find("colliders"); it != j.end()) {
    Problems problems;
    t.colliders = ReadCollidersJson(*it, "/colliders", t.dim, &problems);
    ThrowIfAny(problems);
  }
  if (const auto it = j.find("link_radii"); it != j.end()) {
    t.link_radii = Vector(*it, "/link_radii", t.link_lengths.size());
    if (auto problem = LinkRadiiProblem(t.link_radii, t.link_lengths.size(), true)) {
      throw InputError(*problem);
    }
  }

  t.states.push_back(StatePoints(Member(j, "", "initial"), "/initial", 0, t.dim));
  const Eigen::Index rows = t.states.front().rows();
  const json& steps = Member(j, "", "steps");
  if (!steps.is_array()) throw InputError("/steps", "is not valid; expected an array of steps");
  t.targets.resize(static_cast<Eigen::Index>(steps.size()), t.dim);
  for (size_t s = 0; s < steps.size(); ++s) {
    const std::string at = "/steps/" + std::to_string(s);
    t.states.push_back(StatePoints(steps[s], at, rows, t.dim));
    t.targets.row(static_cast<Eigen::Index>(s)) =
        Vector(Member(steps[s], at, "target"), at + "/target", t.dim).transpose();
    const json& reached = Member(steps[s], at, "reached");
    if (!reached.is_boolean()) {
      throw InputError(at + "/reached", "value " + Show(reached) + " is not true or false");
    }
    t.reached.push_back(reached.get<bool>());
  }
  const json& summary = Member(j, "", "summary");
  t.unreached = ReadInteger(Member(summary, "/summary", "unreached"), "/summary/unreached", 0);
  t.max_ee_error = ReadNumber(Member(summary, "/summary", "max_ee_error"), "/summary/max_ee_error");
  t.seconds = ReadNumber(Member(summary, "/summary", "seconds"), "/summary/seconds");
  return t;
}

// Stops parsing at the top-level "format" key's value, which it keeps.
class FormatProbe : public nlohmann::json_sax<json> {
 public:
  std::string format;

  bool null() override { return Value(); }
  bool boolean(bool) override { return Value(); }
  bool number_integer(number_integer_t) override { return Value(); }
  bool number_unsigned(number_unsigned_t) override { return Value(); }
  bool number_float(number_float_t, const string_t&) override { return Value(); }
  bool string(string_t& value) override {
    if (depth_ == 1 && at_format_) {
      format = value;
      return false;
    }
    return Value();
  }
  bool binary(binary_t&) override { return Value(); }
  bool start_object(std::size_t) override { return Open(); }
  bool end_object() override { return Close(); }
  bool start_array(std::size_t) override { return Open(); }
  bool end_array() override { return Close(); }
  bool key(string_t& key) override {
    if (depth_ == 1) at_format_ = key == "format";
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    return false;
  }

 private:
  // A top-level "format" that is not a string: not a trajectory.
  bool Value() { return !(depth_ == 1 && at_format_); }
  bool Open() {
    if (!Value()) return false;
    ++depth_;
    return true;
  }
  bool Close() {
    --depth_;
    return depth_ > 0;
  }
  int depth_ = 0;
  bool at_format_ = false;
};

}  // namespace

std::string JsonFileFormat(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  FormatProbe probe;
  try {
    json::sax_parse(in, &probe);
  } catch (...) {
    return "";
  }
  return probe.format;
}

bool IsRobotTrajectoryFile(const std::string& path) {
  return JsonFileFormat(path) == kRobotTrajectoryFormat;
}

RobotTrajectoryFile ReadRobotTrajectoryFile(const std::string& path) {
  return TrajectoryFromJson(ReadJsonFile(path));
}

RobotTrajectoryFile RobotTrajectoryFromText(const std::string& json_text) {
  return TrajectoryFromJson(ParseJsonText(json_text));
}

ResultFile RobotTrajectoryAsResult(const RobotTrajectoryFile& t) {
  if (t.states.empty()) throw InputError("states", "the trajectory has no states");
  const Eigen::Index g = t.states.front().rows();
  if (g < 2) throw InputError("states[0]", "has fewer than 2 points; expected the base and more");
  for (size_t s = 0; s < t.states.size(); ++s) {
    if (t.states[s].rows() != g || t.states[s].cols() != t.dim) {
      throw InputError("states[" + std::to_string(s) + "]",
                       "is " + std::to_string(t.states[s].rows()) + " by " +
                           std::to_string(t.states[s].cols()) + "; expected " + std::to_string(g) +
                           " by " + std::to_string(t.dim) + ", as the initial state");
    }
  }
  ResultFile file;
  file.dim = t.dim;
  file.scenario_name = t.scenario_name;
  file.colliders = t.colliders;
  RunResult& r = file.result;
  r.num_steps = static_cast<int64_t>(t.states.size()) - 1;
  r.seconds = t.seconds;
  r.lengths = Eigen::VectorXd::Zero(g - 1);
  for (size_t s = 0; s < t.states.size(); ++s) {
    const Points points = t.states[s].colwise().reverse();  // the end effector first
    for (Eigen::Index i = 0; i + 1 < g; ++i) {
      r.lengths[i] = std::max(r.lengths[i], (points.row(i + 1) - points.row(i)).norm());
    }
    r.frames.Add(static_cast<int64_t>(s), points);
  }
  for (Eigen::Index i = 0; i + 1 < g; ++i) {
    if (!(r.lengths[i] > 0.0)) r.lengths[i] = 1.0;
  }
  // The links' capsules, end effector first as the points: one per drawn link where the arm has
  // one link per distinct point, else (joints at one point) the largest radius for every link.
  if (t.link_radii.size() > 0) {
    file.link_radii = t.link_radii.size() == g - 1
                          ? Eigen::VectorXd(t.link_radii.reverse())
                          : Eigen::VectorXd::Constant(g - 1, t.link_radii.maxCoeff());
  }
  Metrics& m = r.metrics;
  m.path_length = Eigen::VectorXd::Zero(g);
  m.l2_per_step = Eigen::VectorXd::Zero(r.num_steps);
  m.l2_weighted_per_step = Eigen::VectorXd::Zero(r.num_steps);
  for (int64_t s = 1; s <= r.num_steps; ++s) {
    const Points& a = r.frames[static_cast<size_t>(s - 1)].points;
    const Points& b = r.frames[static_cast<size_t>(s)].points;
    for (Eigen::Index i = 0; i < g; ++i) {
      const double d = (b.row(i) - a.row(i)).norm();
      m.path_length[i] += d;
      m.l2_per_step[s - 1] += d;
    }
  }
  m.l2_total = m.l2_per_step.sum();
  return file;
}

}  // namespace flexkin
