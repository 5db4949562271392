// flexkin robot: a robot scenario in, a trajectory JSON (and a joint CSV) out, each written whole
// or not at all. The scenario's format is in docs/robot-format.md; reading and writing are the
// library's (flexkin/robot_scenario.h), URDF arms read by the URDF component (flexkin/urdf.h).
#include "robot_command.h"

#include <filesystem>
#include <iostream>
#include <system_error>

#include "flexkin/arm.h"
#include "flexkin/error.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/urdf.h"
#include "flexkin/vocabulary.h"
#include "output_check.h"

namespace flexkin::cli {
namespace {

// The --method help, from the library's vocabulary.
std::string MethodHelp() {
  std::string help = "How the base is brought back:";
  for (const auto& entry : Vocabulary<FixedBaseMethod>::kEntries) {
    help += std::string("\n  ") + entry.name + ": " + entry.summary;
  }
  return help;
}

}  // namespace

RobotCommand::RobotCommand(CLI::App* app, const std::string& footer) {
  command_ = app->add_subcommand(
      "robot", "Joint trajectories of a fixed-base arm whose end effector follows a path.");
  command_->add_option("scenario", scenario_, "Robot scenario (JSON, docs/robot-format.md)")
      ->required();
  command_->add_option("-o,--output", output_, "Trajectory file to write (JSON)")->required();
  command_->add_option("--csv", csv_, "Also write the joint trajectories as CSV");
  command_->add_option("--method", method_, MethodHelp());
  command_->add_flag("-q,--quiet", quiet_, "Print no report");
  command_->footer(footer);
}

int RobotCommand::Run() const {
  RobotScenario s;
  try {
    s = LoadRobotScenarioFile(scenario_, UrdfRobotScenarioOptions());
  } catch (const InputError& e) {
    Problem p = e.problem();  // the file's name before the JSON pointer
    p.field = p.field.empty() ? scenario_ : scenario_ + ": " + p.field;
    throw InputError(p);
  }
  if (!method_.empty()) s.options.method = ParseFixedBaseMethod(method_, "--method");
  CheckOutputDirectory(output_);
  if (!csv_.empty()) CheckOutputDirectory(csv_);
  const ArmTrajectory t = TrackPath(s.model, s.path, s.options);
  WriteRobotTrajectoryJson(s, t, output_);
  if (!csv_.empty()) WriteRobotJointsCsv(s, t, csv_);
  if (!quiet_) std::cout << t.BriefReport() << "\n";
  if (t.unreached > 0) {
    std::cerr << "flexkin: warning: " << t.unreached << " of " << t.steps.size()
              << " targets were not reached (see \"reached\" in " << output_ << ")\n";
    return 3;
  }
  return 0;
}

}  // namespace flexkin::cli
