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

namespace flexkin::cli {
namespace {

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

}  // namespace

RobotCommand::RobotCommand(CLI::App* app, const std::string& footer) {
  command_ = app->add_subcommand(
      "robot", "Joint trajectories of a fixed-base arm whose end effector follows a path.");
  command_->add_option("scenario", scenario_, "Robot scenario (JSON, docs/robot-format.md)")
      ->required();
  command_->add_option("-o,--output", output_, "Trajectory file to write (JSON)")->required();
  command_->add_option("--csv", csv_, "Also write the joint trajectories as CSV");
  command_->add_option("--method", method_, "newton (default) or fixed_point (the baseline)");
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
  CheckDirectory(output_);
  if (!csv_.empty()) CheckDirectory(csv_);
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
