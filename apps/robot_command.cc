// flexkin robot: a robot scenario in, a trajectory JSON (and a joint CSV) out, each written whole
// or not at all, streamed step by step. The scenario's format is in docs/robot-format.md; reading
// and writing are the library's (flexkin/robot_scenario.h), URDF arms read by the URDF component
// (flexkin/urdf.h).
#include "robot_command.h"

#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <system_error>
#include <utility>

#include "flexkin/any_scenario.h"
#include "flexkin/arm.h"
#include "flexkin/error.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/urdf.h"
#include "flexkin/vocabulary.h"
#include "interrupt.h"
#include "output_check.h"
#include "output_limit.h"

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

// The vocabulary's summary of `method` (the --method help's words).
const char* MethodSummary(FixedBaseMethod method) {
  for (const auto& entry : Vocabulary<FixedBaseMethod>::kEntries) {
    if (entry.value == method) return entry.summary;
  }
  return "";
}

}  // namespace

ScenarioReadOptions RobotReadOptions() {
  ScenarioReadOptions options;
  options.robot = UrdfRobotScenarioOptions();
  return options;
}

int RunRobotCommand(const RobotRunArgs& args, AnyScenario any) {
  if (!args.unsupported.empty()) {
    throw InputError(Problem(args.unsupported, "is not available for a robot scenario (" +
                                                   args.scenario +
                                                   "); it applies to chain scenarios only"));
  }
  RobotScenario& s = *any.robot;
  if (args.method) s.options.method = ParseFixedBaseMethod(*args.method, "--method");
  const bool fixed_point = s.options.method == FixedBaseMethod::kFixedPoint;
  const std::string& output = args.output;
  const std::string& csv = args.csv;
  const uint64_t limit =
      args.max_output_size.empty() ? kDefaultMaxOutputSize : ParseByteSize(args.max_output_size);
  const RobotOutputEstimate estimate = EstimateRobotOutput(s);
  const bool json_over = estimate.json_bytes > limit;
  if (limit > 0 && (json_over || (!csv.empty() && estimate.csv_bytes > limit))) {
    const uint64_t bytes = json_over ? estimate.json_bytes : estimate.csv_bytes;
    throw InputError(Problem(
        kMaxOutputSizeOption,
        (json_over ? "the trajectory " + output : "the joint CSV " + csv) + " would be about " +
            FormatBytes(bytes) + " (" + std::to_string(s.path.rows()) + " targets, " +
            std::to_string(s.model.num_links()) + " joints), over the limit of " +
            FormatBytes(limit) + ". Follow a path with fewer targets, or raise the limit with " +
            "--max-output-size " + SizeOptionFor(bytes) + " (0 = no limit)"));
  }
  CheckOutputDirectory(output);
  if (!csv.empty()) CheckOutputDirectory(csv);
  Writing(output + (csv.empty() ? "" : " or " + csv));
  if (!args.quiet) std::cout << JointGroupsReport(s.model);
  if (fixed_point) {  // what the user chose, in the library's words, before the wait
    std::cerr << "flexkin: note: method fixed_point is "
              << MethodSummary(FixedBaseMethod::kFixedPoint)
              << "; method newton (the default) is the one to use\n";
  }
  // The library's one call for every kind (flexkin/any_scenario.h): streamed, the steps go to the
  // files as they are produced, each renamed into place only when complete. Called now and then:
  // where a signal stops the tracking (by throwing).
  const ArmTrajectory t =
      RunScenarioToFiles(any, {output, csv}, [](int64_t, int64_t) { ThrowIfInterrupted(); }).robot;
  if (!args.quiet) std::cout << t.BriefReport() << "\n";
  if (t.unreached > 0) {
    std::cerr << "flexkin: warning: " << t.unreached << " of " << t.num_steps
              << " targets were not reached (largest end-effector error " << t.max_ee_error
              << "; see \"reached\" in " << output << ")"
              << (fixed_point ? "; method fixed_point does not converge on every arm: try "
                                "--method newton"
                              : "")
              << "\n";
    return 3;
  }
  return 0;
}

RobotCommand::RobotCommand(CLI::App* app, const std::string& footer) {
  command_ = app->add_subcommand(
      "robot",
      "Joint trajectories of a fixed-base arm whose end effector follows a path (the same as "
      "`flexkin run` of a robot scenario).");
  command_->add_option("scenario", args_.scenario, "Robot scenario (JSON, docs/robot-format.md)")
      ->required();
  command_->add_option("-o,--output", args_.output, "Trajectory file to write (JSON)")->required();
  command_->add_option("--csv", args_.csv, "Also write the joint trajectories as CSV");
  method_option_ = command_->add_option("--method", method_, MethodHelp());
  AddMaxOutputSizeOption(command_, &args_.max_output_size);
  command_->add_flag("-q,--quiet", args_.quiet, "Print no report");
  command_->footer(footer);
}

int RobotCommand::Run() const {
  // One read, one parse (flexkin/any_scenario.h); the file's problems named by the file.
  AnyScenario any = ReadScenarioFile(args_.scenario, RobotReadOptions());
  if (!any.valid()) {
    Problem p = any.problems.front();
    p.field = p.field.empty() ? args_.scenario : args_.scenario + ": " + p.field;
    throw InputError(p);
  }
  if (any.kind != ScenarioKind::kRobot) {
    throw InputError(Problem(args_.scenario, std::string("is a ") + NameOf(any.kind) +
                                                 " scenario, not a robot scenario "
                                                 "(docs/robot-format.md); run it with `flexkin "
                                                 "run " +
                                                 args_.scenario + " -o ...`"));
  }
  RobotRunArgs args = args_;
  if (*method_option_) args.method = method_;
  return RunRobotCommand(args, std::move(any));
}

}  // namespace flexkin::cli
