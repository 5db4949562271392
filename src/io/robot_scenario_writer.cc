// Robot trajectories out (docs/robot-format.md, "Outputs"): the trajectory JSON, one key and one
// step per line, and the joint CSV, each written whole or not at all, either from a trajectory
// in memory or streamed step by step as TrackPath produces them (RobotTrajectoryWriter,
// RobotJointsCsvWriter).
#include <cerrno>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "flexkin/arm.h"
#include "flexkin/error.h"
#include "flexkin/robot_scenario.h"
#include "io/atomic_file.h"
#include "io/colliders_json.h"

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
  // One point per distinct position: joints at one point (JointGroups) share theirs.
  const Points points = model.has_axes() ? ChainPoints(model, state.points) : state.points;
  out["points"] = json::array();
  for (int i = 0; i < points.rows(); ++i) out["points"].push_back(Row(points.row(i).transpose()));
  return out;
}

// Step `index` (0-based; "step" index + 1 in the file) toward path row `index`.
json StepJson(const RobotScenario& s, int64_t index, const ArmStepReport& r) {
  json step = StateJson(s.model, r.state);
  step["step"] = index + 1;
  step["target"] = Row(s.path.row(index).transpose());
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
  if (s.options.pointing.enabled) step["pointing_error"] = r.pointing_error;
  if (s.options.time_step > 0.0 && s.model.max_velocity.size() > 0) {
    step["velocity_legs"] = r.velocity_legs;
    step["velocity_ratio"] = r.velocity_ratio;
  }
  if (!s.options.colliders.empty()) {
    // The least clearance of any link's capsule from any collider after the step (length unit).
    step["clearance"] = r.clearance;
    step["contact"] = r.contact;
    step["blocked"] = r.blocked;
  }
  return step;
}

// Everything of the trajectory document but "steps" and "summary".
json HeadJson(const RobotScenario& s) {
  json doc;
  doc["format"] = kRobotTrajectoryFormat;
  doc["version"] = kRobotTrajectoryVersion;
  if (!s.name.empty()) doc["scenario"] = s.name;
  doc["dim"] = s.model.dim;
  doc["link_lengths"] = Row(s.model.link_lengths);
  doc["base"] = Row(s.model.base);
  doc["method"] = FixedBaseMethodName(s.options.method);
  doc["tolerance"] = s.options.tolerance;
  if (s.model.has_axes()) {
    doc["joint_types"] = json::array();
    for (int j = 0; j < s.model.num_links(); ++j) {
      doc["joint_types"].push_back(
          NameOf(s.model.prismatic(j) ? JointType::kPrismatic : JointType::kRevolute));
    }
    // The joints of each point of "points" (base first), as JointGroups gives them.
    doc["joint_groups"] = JointGroups(s.model);
  }
  if (s.options.pointing.enabled) {
    const ArmOptions::Pointing& p = s.options.pointing;
    json pointing = {{"axis", Row(p.axis)}, {"weight", p.weight}, {"tolerance", p.angle_tolerance}};
    if (p.look_at) {
      pointing["look_at"] = Row(p.point);
    } else {
      pointing["direction"] = Row(p.direction);
    }
    doc["pointing"] = pointing;
  }
  if (s.options.time_step > 0.0) doc["time_step"] = s.options.time_step;
  if (s.model.link_radii.size() > 0) doc["link_radii"] = Row(s.model.link_radii);
  if (!s.options.colliders.empty()) {
    doc["colliders"] = json::array();
    for (const Collider& c : s.options.colliders) {
      std::string text;
      AppendColliderJson(c, s.model.dim, &text);
      doc["colliders"].push_back(json::parse(text));
    }
  }
  doc["initial"] = StateJson(s.model, InitialState(s.model));
  return doc;
}

json SummaryJson(const ArmTrajectory& t, int64_t steps) {
  json summary = {{"steps", steps},
                  {"unreached", t.unreached},
                  {"max_ee_error", t.max_ee_error},
                  {"max_base_error", t.max_base_error},
                  {"max_iterations", t.max_iterations},
                  {"total_sweeps", t.total_sweeps},
                  {"seconds", t.seconds}};
  // Only where the run pointed or kept velocity limits (the steps say which).
  if (t.max_pointing_error > 0.0) summary["max_pointing_error"] = t.max_pointing_error;
  if (t.velocity_legs > 0) summary["velocity_legs"] = t.velocity_legs;
  if (std::isfinite(t.min_clearance)) {  // with colliders
    summary["min_clearance"] = t.min_clearance;
    summary["contact_steps"] = t.contact_steps;
    summary["blocked_steps"] = t.blocked_steps;
  }
  return summary;
}

std::optional<Problem> NotFinite(const std::string& field, double x) {
  if (std::isfinite(x)) return std::nullopt;
  return Problem(field, "value " + FormatNumber(x) + " is not a finite number", FormatNumber(x),
                 "a finite number");
}

std::optional<Problem> WrongSize(const std::string& field, Eigen::Index size, Eigen::Index n) {
  if (size == n) return std::nullopt;
  return Problem(field, "has " + std::to_string(size) + " values; expected " + std::to_string(n));
}

// The first problem of step `index` (0-based) that a file cannot hold: a shape that does not fit
// the model or a number that is not finite (JSON has none). `angles_only`: the joint CSV's part.
std::optional<Problem> StepProblem(const ArmModel& model, int64_t index, const ArmStepReport& r,
                                   bool angles_only) {
  const std::string at = "steps[" + std::to_string(index) + "].";
  const int n = model.num_links();
  const bool spherical = model.joint() == ArmJoint::kSpherical;
  const JointAngles& a = r.state.angles;
  if (auto p = WrongSize(at + "joint_angles", a.angle.size(), n)) return p;
  if (spherical) {
    if (auto p = WrongSize(at + "joint_azimuths", a.azimuth.size(), n)) return p;
  }
  for (int j = 0; j < n; ++j) {
    if (auto p = NotFinite(at + "joint_angles[" + std::to_string(j) + "]", a.angle[j])) return p;
    if (!spherical) continue;
    if (auto p = NotFinite(at + "joint_azimuths[" + std::to_string(j) + "]", a.azimuth[j])) {
      return p;
    }
  }
  if (angles_only) return std::nullopt;
  const Points& points = r.state.points;
  if (points.rows() != n + 1 || points.cols() != model.dim) {
    return Problem(at + "points", "shape " + std::to_string(points.rows()) + " by " +
                                      std::to_string(points.cols()) + " is not valid; expected " +
                                      std::to_string(n + 1) + " by " + std::to_string(model.dim));
  }
  for (int i = 0; i < points.rows(); ++i) {
    for (int k = 0; k < points.cols(); ++k) {
      const std::string field = at + "points[" + std::to_string(i) + "][" + std::to_string(k) + "]";
      if (auto p = NotFinite(field, points(i, k))) return p;
    }
  }
  if (auto p = NotFinite(at + "ee_error", r.ee_error)) return p;
  return NotFinite(at + "base_error", r.base_error);
}

std::optional<Problem> SummaryProblem(const ArmTrajectory& t) {
  if (auto p = NotFinite("summary.max_ee_error", t.max_ee_error)) return p;
  if (auto p = NotFinite("summary.max_base_error", t.max_base_error)) return p;
  return NotFinite("summary.seconds", t.seconds);
}

// The trajectory must be the one of the scenario: one step per target of its path.
std::optional<Problem> CountProblem(const RobotScenario& s, int64_t steps) {
  if (steps == s.path.rows()) return std::nullopt;
  return Problem("trajectory.steps", "has " + std::to_string(steps) +
                                         " steps; expected one per target of the path (" +
                                         std::to_string(s.path.rows()) + ")");
}

// A streamed step: one more than the path has targets is refused.
void CheckNextStep(const RobotScenario& s, int64_t steps) {
  if (steps < s.path.rows()) return;
  ThrowNothingWritten(Problem("trajectory.steps", "a step beyond the path's " +
                                                      std::to_string(s.path.rows()) + " targets"));
}

// A streamed trajectory at its end: one step per target, as many as its summary says.
void CheckCommit(const RobotScenario& s, int64_t steps, const ArmTrajectory& t) {
  if (auto p = CountProblem(s, steps)) ThrowNothingWritten(*p);
  if (t.num_steps != steps) {
    ThrowNothingWritten(Problem("summary.steps", "is " + std::to_string(t.num_steps) + ", but " +
                                                     std::to_string(steps) + " steps were added"));
  }
}

// The model and the path of a scenario whose trajectory is written.
void CheckScenario(const RobotScenario& s) {
  if (auto p = s.model.FirstProblem()) ThrowNothingWritten(*p);
  if (s.path.rows() < 1 || s.path.cols() != s.model.dim) {
    ThrowNothingWritten(Problem(
        "path", "shape " + std::to_string(s.path.rows()) + " by " + std::to_string(s.path.cols()) +
                    " is not valid; expected m >= 1 by " + std::to_string(s.model.dim)));
  }
}

// A whole trajectory in memory: its count and every step checked before anything is written.
void CheckTrajectory(const RobotScenario& s, const ArmTrajectory& t, bool angles_only) {
  if (auto p = CountProblem(s, static_cast<int64_t>(t.steps.size()))) ThrowNothingWritten(*p);
  for (size_t i = 0; i < t.steps.size(); ++i) {
    if (auto p = StepProblem(s.model, static_cast<int64_t>(i), t.steps[i], angles_only)) {
      ThrowNothingWritten(*p);
    }
  }
  if (!angles_only) {
    if (auto p = SummaryProblem(t)) ThrowNothingWritten(*p);
  }
}

// One key per line ("key": value, the first after "{\n", the others after ",\n").
void WriteKeys(const json& doc, std::ostream& out, bool first) {
  for (const auto& item : doc.items()) {
    out << (first ? "{\n" : ",\n") << json(item.key()).dump() << ": " << item.value().dump();
    first = false;
  }
}

bool SphericalAngles(const ArmModel& model) { return model.joint() == ArmJoint::kSpherical; }

// A CSV field: as it is, or quoted (RFC 4180) where it holds a comma, a quote or a line break.
std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

// The CSV header: "step", then each joint's name where the model has one (a URDF's), else
// "joint_j"; then ",azimuth_0,..." for spherical joints.
void CsvHeader(const ArmModel& model, std::ostream& out) {
  const int n = model.num_links();
  out << "step";
  for (int j = 0; j < n; ++j) {
    const bool named = static_cast<int>(model.joint_names.size()) == n &&
                       !model.joint_names[static_cast<size_t>(j)].empty();
    out << ","
        << (named ? CsvField(model.joint_names[static_cast<size_t>(j)])
                  : "joint_" + std::to_string(j));
  }
  if (SphericalAngles(model)) {
    for (int j = 0; j < n; ++j) out << ",azimuth_" << j;
  }
  out << "\n";
}

// One CSV row, at the stream's precision (17 digits where written).
void CsvRow(const ArmModel& model, int64_t step, const JointAngles& a, std::ostream& out) {
  const int n = model.num_links();
  out << step;
  for (int j = 0; j < n; ++j) out << "," << a.angle[j];
  if (SphericalAngles(model)) {
    for (int j = 0; j < n; ++j) out << "," << a.azimuth[j];
  }
  out << "\n";
}

// Runs `write` with the writer's state; any failure (a refused step, a failed write) removes the
// temporary file with the state and propagates. A failed write throws the system's reason.
template <class State, class Write>
void Guarded(std::unique_ptr<State>& state, const char* what, Write&& write) {
  if (state == nullptr) throw std::logic_error(std::string(what) + " after Commit or a failure");
  try {
    write(*state);
    if (!state->file.stream()) throw state->file.Error(EIO);
  } catch (...) {
    state.reset();  // removes the temporary file
    throw;
  }
}

}  // namespace

RobotOutputEstimate EstimateRobotOutput(const RobotScenario& s) {
  const double n = s.model.num_links(), dim = s.model.dim;
  const double steps = static_cast<double>(s.path.rows()) + 1;  // and the initial state
  const bool spherical = SphericalAngles(s.model);
  const double angles = n * (spherical ? 2 : 1);
  const double numbers = angles + (dim == 3 ? 4 * n : 0) + (n + 1) * dim + dim;
  auto bytes = [](double x) { return x < 1.8e19 ? static_cast<uint64_t>(x) : ~uint64_t{0}; };
  RobotOutputEstimate e;
  e.json_bytes = bytes(1024 + steps * (300 + numbers * 24 + (n + 1) * 3));
  e.csv_bytes = bytes(64 + angles * 12 + steps * (8 + angles * 24));
  return e;
}

void WriteRobotTrajectoryJson(const RobotScenario& s, const ArmTrajectory& t, std::ostream& out) {
  CheckTrajectory(s, t, false);
  json doc = HeadJson(s);
  doc["summary"] = SummaryJson(t, static_cast<int64_t>(t.steps.size()));
  doc["steps"] = json::array();
  for (size_t i = 0; i < t.steps.size(); ++i) {
    doc["steps"].push_back(StepJson(s, static_cast<int64_t>(i), t.steps[i]));
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
  CheckTrajectory(scenario, trajectory, false);  // before the destination is touched at all
  WriteFileAtomically(
      path, [&](std::ostream& out) { WriteRobotTrajectoryJson(scenario, trajectory, out); });
}

void WriteRobotJointsCsv(const RobotScenario& s, const ArmTrajectory& t, std::ostream& out) {
  CheckTrajectory(s, t, true);
  CsvHeader(s.model, out);
  const std::streamsize precision = out.precision(17);
  CsvRow(s.model, 0, InitialState(s.model).angles, out);
  for (size_t i = 0; i < t.steps.size(); ++i) {
    CsvRow(s.model, static_cast<int64_t>(i) + 1, t.steps[i].state.angles, out);
  }
  out.precision(precision);
}

void WriteRobotJointsCsv(const RobotScenario& scenario, const ArmTrajectory& trajectory,
                         const std::string& path) {
  CheckTrajectory(scenario, trajectory, true);
  WriteFileAtomically(path,
                      [&](std::ostream& out) { WriteRobotJointsCsv(scenario, trajectory, out); });
}

// The streamed trajectory JSON: the head (every key but "steps" and "summary") and "steps": [ at
// construction, a step per line from Add, then "summary" last at Commit.
class RobotTrajectoryWriter::Impl {
 public:
  Impl(const RobotScenario& s, const std::string& path) : scenario(s), file(path) {}
  const RobotScenario& scenario;
  AtomicFile file;
};

RobotTrajectoryWriter::RobotTrajectoryWriter(const RobotScenario& scenario,
                                             const std::string& path) {
  CheckScenario(scenario);
  impl_ = std::make_unique<Impl>(scenario, path);
  Guarded(impl_, "RobotTrajectoryWriter", [&](Impl& s) {
    WriteKeys(HeadJson(scenario), s.file.stream(), true);
    s.file.stream() << ",\n\"steps\": [";
  });
}

RobotTrajectoryWriter::~RobotTrajectoryWriter() = default;

void RobotTrajectoryWriter::Add(const ArmStepReport& step) {
  Guarded(impl_, "RobotTrajectoryWriter::Add", [&](Impl& s) {
    CheckNextStep(s.scenario, steps_);
    if (auto p = StepProblem(s.scenario.model, steps_, step, false)) ThrowNothingWritten(*p);
    s.file.stream() << (steps_ == 0 ? "\n  " : ",\n  ")
                    << StepJson(s.scenario, steps_, step).dump();
  });
  ++steps_;
}

void RobotTrajectoryWriter::Commit(const ArmTrajectory& trajectory) {
  std::unique_ptr<Impl> impl = std::move(impl_);  // whatever happens, once only
  if (impl == nullptr) {
    throw std::logic_error("RobotTrajectoryWriter::Commit after Commit or a failure");
  }
  CheckCommit(impl->scenario, steps_, trajectory);
  if (auto p = SummaryProblem(trajectory)) ThrowNothingWritten(*p);
  Guarded(impl, "RobotTrajectoryWriter::Commit", [&](Impl& s) {
    s.file.stream() << "\n],\n\"summary\": " << SummaryJson(trajectory, steps_).dump() << "\n}\n";
  });
  impl->file.Commit();
}

class RobotJointsCsvWriter::Impl {
 public:
  Impl(const RobotScenario& s, const std::string& path) : scenario(s), file(path) {}
  const RobotScenario& scenario;
  AtomicFile file;
};

RobotJointsCsvWriter::RobotJointsCsvWriter(const RobotScenario& scenario, const std::string& path) {
  CheckScenario(scenario);
  impl_ = std::make_unique<Impl>(scenario, path);
  Guarded(impl_, "RobotJointsCsvWriter", [&](Impl& s) {
    CsvHeader(scenario.model, s.file.stream());
    s.file.stream().precision(17);
    CsvRow(scenario.model, 0, InitialState(scenario.model).angles, s.file.stream());
  });
}

RobotJointsCsvWriter::~RobotJointsCsvWriter() = default;

void RobotJointsCsvWriter::Add(const ArmStepReport& step) {
  Guarded(impl_, "RobotJointsCsvWriter::Add", [&](Impl& s) {
    CheckNextStep(s.scenario, steps_);
    if (auto p = StepProblem(s.scenario.model, steps_, step, true)) ThrowNothingWritten(*p);
    CsvRow(s.scenario.model, steps_ + 1, step.state.angles, s.file.stream());
  });
  ++steps_;
}

void RobotJointsCsvWriter::Commit(const ArmTrajectory& trajectory) {
  std::unique_ptr<Impl> impl = std::move(impl_);
  if (impl == nullptr) {
    throw std::logic_error("RobotJointsCsvWriter::Commit after Commit or a failure");
  }
  CheckCommit(impl->scenario, steps_, trajectory);
  impl->file.Commit();
}

ArmTrajectory TrackToFiles(const RobotScenario& scenario, const std::string& trajectory,
                           const std::string& csv, ArmStepSink* also) {
  std::optional<RobotTrajectoryWriter> json;
  std::optional<RobotJointsCsvWriter> table;
  std::vector<ArmStepSink*> sinks;
  if (!trajectory.empty()) sinks.push_back(&json.emplace(scenario, trajectory));
  if (!csv.empty()) sinks.push_back(&table.emplace(scenario, csv));
  if (also != nullptr) sinks.push_back(also);
  ArmStepFanOut sink(sinks);
  const ArmTrajectory summary = TrackPath(scenario.model, scenario.path, scenario.options, &sink);
  if (json) json->Commit(summary);
  if (table) table->Commit(summary);
  return summary;
}

}  // namespace flexkin
