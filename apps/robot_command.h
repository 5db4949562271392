#pragma once
// `flexkin robot SCENARIO.json -o TRAJECTORY.json [--csv JOINTS.csv] [--max-output-size SIZE]`:
// joint trajectories of a fixed-base hyper-redundant arm whose end effector follows a path
// (docs/robot-format.md, docs/robots.md). The scenario reader and the trajectory writers are the
// library's (flexkin/robot_scenario.h); this is the command line around them. Kept apart from
// flexkin_main.cc, which only registers it.

#include <CLI/CLI.hpp>
#include <string>

namespace flexkin::cli {

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
  std::string scenario_, output_, csv_, method_, max_output_size_;
  bool quiet_ = false;
};

}  // namespace flexkin::cli
