#pragma once
// `flexkin robot SCENARIO.json -o TRAJECTORY.json [--csv JOINTS.csv] [--max-output-size SIZE]`:
// joint trajectories of a fixed-base hyper-redundant arm whose end effector follows a path
// (docs/robot-format.md, docs/robots.md). The scenario reader and the trajectory writers are the
// library's (flexkin/robot_scenario.h); this is the command line around them. Kept apart from
// flexkin_main.cc, which only registers it.

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "flexkin/any_scenario.h"

namespace flexkin::cli {

// What `flexkin robot` and `flexkin run` (which hands a robot scenario here) pass on.
struct RobotRunArgs {
  std::string scenario, output, csv, max_output_size;
  std::optional<std::string> method;  // a FixedBaseMethod's name
  // An option of chain runs with no meaning for a robot ("--substeps"), refused by name.
  std::string unsupported;
  bool quiet = false;
};

// Runs a robot scenario read and checked by the front door (flexkin/any_scenario.h) into its
// trajectory JSON (and joint CSV). Returns 0, or 3 if some target was not reached (the outputs are
// written); throws InputError (exit 1) and std::system_error (exit 4).
int RunRobotCommand(const RobotRunArgs& args, AnyScenario scenario);

// How the command line reads scenarios: URDF robots through the URDF component (flexkin/urdf.h).
ScenarioReadOptions RobotReadOptions();

class RobotCommand {
 public:
  // Adds the "robot" subcommand to `app`; `footer` is the exit-code help shown under --help.
  RobotCommand(CLI::App* app, const std::string& footer);

  bool Parsed() const { return command_->parsed(); }
  // Runs the scenario and writes the outputs. Returns 0, or 3 if some target was not reached
  // (the outputs are written); throws InputError (exit 1) and std::system_error (exit 4).
  int Run() const;

 private:
  CLI::App* command_ = nullptr;
  RobotRunArgs args_;
  std::string method_;
  CLI::Option* method_option_ = nullptr;
};

}  // namespace flexkin::cli
