// flexkin robot: a robot scenario in, a trajectory JSON (and a joint CSV) out, each written whole
// or not at all, streamed step by step. The scenario's format is in docs/robot-format.md; reading
// and writing are the library's (flexkin/robot_scenario.h), URDF arms read by the URDF component
// (flexkin/urdf.h).
#include "robot_command.h"

#include <filesystem>
#include <iostream>
#include <optional>
#include <system_error>
#include <vector>

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

// First of the step sinks: a signal stops the tracking at the next step (by throwing).
class InterruptCheck : public ArmStepSink {
 public:
  void Add(const ArmStepReport&) override { ThrowIfInterrupted(); }
};

}  // namespace

RobotCommand::RobotCommand(CLI::App* app, const std::string& footer) {
  command_ = app->add_subcommand(
      "robot", "Joint trajectories of a fixed-base arm whose end effector follows a path.");
  command_->add_option("scenario", scenario_, "Robot scenario (JSON, docs/robot-format.md)")
      ->required();
  command_->add_option("-o,--output", output_, "Trajectory file to write (JSON)")->required();
  command_->add_option("--csv", csv_, "Also write the joint trajectories as CSV");
  command_->add_option("--method", method_, MethodHelp());
  AddMaxOutputSizeOption(command_, &max_output_size_);
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
  const bool fixed_point = s.options.method == FixedBaseMethod::kFixedPoint;
  const uint64_t limit =
      max_output_size_.empty() ? kDefaultMaxOutputSize : ParseByteSize(max_output_size_);
  const RobotOutputEstimate estimate = EstimateRobotOutput(s);
  const bool json_over = estimate.json_bytes > limit;
  if (limit > 0 && (json_over || (!csv_.empty() && estimate.csv_bytes > limit))) {
    const uint64_t bytes = json_over ? estimate.json_bytes : estimate.csv_bytes;
    throw InputError(Problem(
        kMaxOutputSizeOption,
        (json_over ? "the trajectory " + output_ : "the joint CSV " + csv_) + " would be about " +
            FormatBytes(bytes) + " (" + std::to_string(s.path.rows()) + " targets, " +
            std::to_string(s.model.num_links()) + " joints), over the limit of " +
            FormatBytes(limit) + ". Follow a path with fewer targets, or raise the limit with " +
            "--max-output-size " + SizeOptionFor(bytes) + " (0 = no limit)"));
  }
  CheckOutputDirectory(output_);
  if (!csv_.empty()) CheckOutputDirectory(csv_);
  // Streamed: the steps go to the files as they are produced, so memory does not grow with the
  // targets; each file is renamed into place only when complete (flexkin/robot_scenario.h).
  InterruptCheck interrupt_check;
  Writing(output_ + (csv_.empty() ? "" : " or " + csv_));
  if (!quiet_) std::cout << JointGroupsReport(s.model);
  if (fixed_point) {  // what the user chose, in the library's words, before the wait
    std::cerr << "flexkin: note: method fixed_point is "
              << MethodSummary(FixedBaseMethod::kFixedPoint)
              << "; method newton (the default) is the one to use\n";
  }
  const ArmTrajectory t = TrackToFiles(s, output_, csv_, &interrupt_check);
  if (!quiet_) std::cout << t.BriefReport() << "\n";
  if (t.unreached > 0) {
    std::cerr << "flexkin: warning: " << t.unreached << " of " << t.num_steps
              << " targets were not reached (largest end-effector error " << t.max_ee_error
              << "; see \"reached\" in " << output_ << ")"
              << (fixed_point ? "; method fixed_point does not converge on every arm: try "
                                "--method newton"
                              : "")
              << "\n";
    return 3;
  }
  return 0;
}

}  // namespace flexkin::cli
