#pragma once
// `flexkin robot SCENARIO.json -o TRAJECTORY.json [--csv JOINTS.csv]`: joint trajectories of a
// fixed-base hyper-redundant arm whose end effector follows a path (docs/robot-format.md,
// docs/robots.md). Kept apart from flexkin_main.cc, which only registers it.

#include <CLI/CLI.hpp>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "flexkin/arm.h"

namespace flexkin::cli {

// A robot scenario file read in.
struct RobotScenario {
  std::string name;
  ArmModel model;
  Points path;  // m by dim end-effector targets
  ArmOptions options;
};

// Reads a robot scenario document (docs/robot-format.md). Throws InputError whose field is the
// JSON pointer of the first problem ("/arm/link_lengths/2"). A relative "urdf" file name is
// taken relative to `scenario_dir` ("" = the working directory).
RobotScenario ParseRobotScenario(const nlohmann::json& json, const std::string& scenario_dir = "");

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
  std::string scenario_, output_, csv_, method_;
  bool quiet_ = false;
};

}  // namespace flexkin::cli
