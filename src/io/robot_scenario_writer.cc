// Robot trajectories out (docs/robot-format.md, "Outputs"): the trajectory JSON, one key and one
// step per line, and the joint CSV, each written whole or not at all.
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "flexkin/arm.h"
#include "flexkin/error.h"
#include "flexkin/robot_scenario.h"
#include "io/atomic_file.h"

namespace flexkin {
namespace {

using json = nlohmann::json;

json Row(const Eigen::VectorXd& v) {
  return json(std::vector<double>(v.data(), v.data() + v.size()));
}

json StateJson(const ArmModel& model, const ArmState& state) {
  json out;
  out["joint_angles"] = Row(state.angles.angle);
  if (model.dim == 3) {
    if (model.joint() == ArmJoint::kSpherical) out["joint_azimuths"] = Row(state.angles.azimuth);
    const Eigen::MatrixXd q = JointQuaternions(model, state.angles);
    out["joint_quaternions"] = json::array();
    for (int j = 0; j < q.rows(); ++j)
      out["joint_quaternions"].push_back(Row(q.row(j).transpose()));
  }
  out["points"] = json::array();
  for (int i = 0; i < state.points.rows(); ++i) {
    out["points"].push_back(Row(state.points.row(i).transpose()));
  }
  return out;
}

// The trajectory must be the one of the scenario: one step per target of its path.
void CheckSteps(const RobotScenario& s, const ArmTrajectory& t) {
  if (t.steps.size() != static_cast<size_t>(s.path.rows())) {
    throw InputError("trajectory.steps", "has " + std::to_string(t.steps.size()) +
                                             " steps; expected one per target of the path (" +
                                             std::to_string(s.path.rows()) + ")");
  }
}

}  // namespace

void WriteRobotTrajectoryJson(const RobotScenario& s, const ArmTrajectory& t, std::ostream& out) {
  CheckSteps(s, t);
  json doc;
  doc["format"] = kRobotTrajectoryFormat;
  doc["version"] = kRobotTrajectoryVersion;
  if (!s.name.empty()) doc["scenario"] = s.name;
  doc["dim"] = s.model.dim;
  doc["link_lengths"] = Row(s.model.link_lengths);
  doc["base"] = Row(s.model.base);
  doc["method"] = FixedBaseMethodName(s.options.method);
  doc["tolerance"] = s.options.tolerance;
  doc["summary"] = {{"steps", t.steps.size()},
                    {"unreached", t.unreached},
                    {"max_ee_error", t.max_ee_error},
                    {"max_base_error", t.max_base_error},
                    {"max_iterations", t.max_iterations},
                    {"total_sweeps", t.total_sweeps},
                    {"seconds", t.seconds}};
  doc["initial"] = StateJson(s.model, InitialState(s.model));
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
}

void WriteRobotTrajectoryJson(const RobotScenario& scenario, const ArmTrajectory& trajectory,
                              const std::string& path) {
  WriteFileAtomically(
      path, [&](std::ostream& out) { WriteRobotTrajectoryJson(scenario, trajectory, out); });
}

void WriteRobotJointsCsv(const RobotScenario& s, const ArmTrajectory& t, std::ostream& out) {
  CheckSteps(s, t);
  const int n = s.model.num_links();
  // Azimuths only where the joints have them (spherical joints), in the header as in the rows.
  const bool azimuths = s.model.joint() == ArmJoint::kSpherical;
  out << "step";
  for (int j = 0; j < n; ++j) out << ",joint_" << j;
  if (azimuths) {
    for (int j = 0; j < n; ++j) out << ",azimuth_" << j;
  }
  const std::streamsize precision = out.precision(17);
  out << "\n";
  auto row = [&](size_t step, const JointAngles& a) {
    out << step;
    for (int j = 0; j < n; ++j) out << "," << a.angle[j];
    if (azimuths) {
      for (int j = 0; j < n; ++j) out << "," << a.azimuth[j];
    }
    out << "\n";
  };
  row(0, InitialState(s.model).angles);
  for (size_t i = 0; i < t.steps.size(); ++i) row(i + 1, t.steps[i].state.angles);
  out.precision(precision);
}

void WriteRobotJointsCsv(const RobotScenario& scenario, const ArmTrajectory& trajectory,
                         const std::string& path) {
  WriteFileAtomically(path,
                      [&](std::ostream& out) { WriteRobotJointsCsv(scenario, trajectory, out); });
}

}  // namespace flexkin
