// The flexkin command line: runs and checks scenario files.
//
//   flexkin run SCENARIO.json -o RESULT.json|RESULT.npz [--csv FRAMES.csv] [--method METHOD]
//       [--substeps N] [--tolerance T] [--max-substeps N] [--record-every N]
//       [--max-output-size SIZE] [--report brief|full] [--quiet]
//   flexkin run GROOM.json -o HAIR.npz [--method tractrix|ftl] [--substeps N] [--threads N]
//       [--record-every N] [--precision float32|float64] [--max-output-size SIZE] [--quiet]
//       (a groom scenario, recognised by its keys: groom_command.h)
//   flexkin run ROBOT.json -o TRAJECTORY.json [--csv JOINTS.csv] [--method newton|fixed_point]
//       [--max-output-size SIZE] [--quiet]   (a robot scenario: robot_command.h; = flexkin robot)
//   flexkin validate SCENARIO.json   (chain, robot or groom scenario, recognised by its keys)
//   flexkin render RESULT.json ...   (render_command.h)
//   flexkin robot SCENARIO.json ...  (robot_command.h)
//   flexkin vocabulary               (vocabulary_command.h: every enumerated name)
//   flexkin --version
//
// Exit codes are listed in kExitCodesHelp and in docs/scenario-format.md.

#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <iostream>
#include <memory>
#include <new>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "flexkin/any_scenario.h"
#include "flexkin/arm.h"
#include "flexkin/dynamics.h"
#include "flexkin/error.h"
#include "flexkin/groom.h"
#include "flexkin/propagate.h"
#include "flexkin/result_io.h"
#include "flexkin/robot_scenario.h"
#include "flexkin/run.h"
#include "flexkin/scenario.h"
#include "groom_command.h"
#include "interrupt.h"
#include "output_check.h"
#include "output_limit.h"
#include "render_command.h"
#include "robot_command.h"
#include "vocabulary_command.h"

namespace {

enum ExitCode : int {
  kExitOk = 0,
  kExitInvalidInput = 1,    // scenario or option values invalid, or any other failure
  kExitUsage = 2,           // command-line syntax (unknown option, missing argument, ...)
  kExitAccuracyNotMet = 3,  // run done and result written, but the tolerance was not met
  kExitIoError = 4,         // a file could not be read or written
  kExitNotConverged = 5,    // run done and result written, but an overall solve did not converge
  // Stopped by a signal: 128 + its number, as shells report it (130 SIGINT, 143 SIGTERM).
  kExitInterruptedBase = 128,
};

constexpr const char* kExitCodesHelp =
    "Exit codes:\n"
    "  0  success\n"
    "  1  invalid input: the scenario or an option value (the message names the file, the\n"
    "     field, the value and what is valid), or another failure\n"
    "  2  usage error: unknown option, missing argument, malformed number\n"
    "  3  the run completed and the result was written, but the accuracy target\n"
    "     (--tolerance) was not met within --max-substeps\n"
    "  4  I/O error: a file could not be read or written (an existing output file is\n"
    "     never left half-written)\n"
    "  5  method overall: the run completed and the result was written, but the solver\n"
    "     did not converge at some step (the result and the message say where)\n"
    "  130, 143  interrupted by SIGINT (Ctrl-C) or SIGTERM: stopped at once, the\n"
    "     output being written was not written and earlier files are unchanged";

void PrintError(const std::string& message) { std::cerr << "flexkin: error: " << message << "\n"; }

// After a signal, whatever exception ended the command (the interruption itself, or a failure
// it caused, such as an ffmpeg that the terminal's Ctrl-C stopped too): 128 + the signal.
int ExitInterrupted() {
  std::cerr << "flexkin: " << flexkin::cli::InterruptMessage() << "\n";
  return kExitInterruptedBase + flexkin::cli::InterruptSignal();
}

struct RunArgs {
  std::string scenario, output, csv, method, report = "brief", max_output_size, precision,
                                             projection;
  int substeps = 0, record_every = 0, max_substeps = 0, threads = 0;
  double tolerance = 0.0;
  bool quiet = false, no_link_angles = false;
  // Which overrides were given.
  CLI::Option *substeps_opt = nullptr, *record_every_opt = nullptr, *max_substeps_opt = nullptr,
              *tolerance_opt = nullptr, *method_opt = nullptr, *threads_opt = nullptr,
              *precision_opt = nullptr, *csv_opt = nullptr, *no_link_angles_opt = nullptr,
              *report_opt = nullptr, *projection_opt = nullptr;
};

// Progress on stderr, rewritten in place; only used when stderr is a terminal.
void ShowProgress(int64_t done, int64_t total) {
  std::fprintf(stderr, "\rflexkin: leader step %lld of %lld (%.0f%%)", static_cast<long long>(done),
               static_cast<long long>(total), total > 0 ? 100.0 * done / total : 100.0);
  if (done >= total) std::fputc('\n', stderr);
  std::fflush(stderr);
}

// Applies the command-line overrides to the scenario's options; throws InputError naming the
// option (or the scenario field it conflicts with). `dynamic`: a dynamic chain's, whose --substeps
// went to its "dynamics" (ApplyDynamicOverrides) and which takes --record-every and
// --no-link-angles only.
void ApplyOverrides(const RunArgs& args, flexkin::RunOptions* options, bool dynamic = false) {
  if (*args.method_opt && !dynamic) {
    options->method = flexkin::ParseMethod(args.method, "--method");
  }
  if (*args.substeps_opt && !dynamic) options->substeps = args.substeps;
  if (*args.record_every_opt) options->record_every = args.record_every;
  if (args.no_link_angles) options->link_angles = false;
  if (*args.tolerance_opt && !dynamic) options->tolerance = args.tolerance;
  if (*args.max_substeps_opt && !dynamic) {
    options->max_substeps = args.max_substeps;
  } else if (*args.substeps_opt && !dynamic && options->max_substeps < options->substeps) {
    options->max_substeps = options->substeps;  // a large --substeps raises the default cap
  }
  const flexkin::Problems problems = options->Validate();
  if (problems.empty()) return;
  // A value from the command line is named by its option, one from the file by its JSON pointer.
  const flexkin::Problem& p = problems.front();
  const flexkin::OptionLocation* location = flexkin::FindOptionLocation(p.field);
  const bool from_cli =
      location != nullptr && *location->flag != '\0' &&
      ((location->flag == std::string("--substeps") && *args.substeps_opt) ||
       (location->flag == std::string("--record-every") && *args.record_every_opt) ||
       (location->flag == std::string("--tolerance") && *args.tolerance_opt) ||
       (location->flag == std::string("--max-substeps") && *args.max_substeps_opt));
  flexkin::Problem located = flexkin::InScenarioFile(p);
  located.field = from_cli ? location->flag : args.scenario + ": " + located.field;
  throw flexkin::InputError(located);
}

// A dynamic chain scenario ("dynamics", docs/dynamics.md): --substeps and --projection set its
// sub-steps per frame and its projection; the options of kinematic runs it has no use for are
// refused by name.
void ApplyDynamicOverrides(const RunArgs& args, flexkin::Scenario* scenario) {
  const std::pair<CLI::Option*, const char*> unsupported[] = {
      {args.method_opt, "--method"},
      {args.tolerance_opt, "--tolerance"},
      {args.max_substeps_opt, "--max-substeps"}};
  for (const auto& [option, name] : unsupported) {
    if (*option) {
      throw flexkin::InputError(flexkin::Problem(
          name, std::string("is not used with a dynamic chain scenario (") + args.scenario +
                    " has \"dynamics\", docs/dynamics.md); choose its projection with "
                    "--projection and its sub-steps per frame with --substeps"));
    }
  }
  flexkin::DynamicOptions& d = *scenario->dynamics;
  if (*args.projection_opt) {
    d.projection = flexkin::ParseName<flexkin::Projection>(args.projection, "--projection");
  }
  if (*args.substeps_opt) {
    if (args.substeps < 1) {
      throw flexkin::InputError(flexkin::Problem::Invalid(
          "--substeps", std::to_string(args.substeps), "an integer >= 1 (sub-steps per frame)"));
    }
    d.substeps = args.substeps;
  }
}

// The --method help, from the library's vocabulary: every method with its one-line summary.
std::string MethodHelp() {
  std::string help = "Overrides the scenario's method:";
  for (const auto& entry : flexkin::Vocabulary<flexkin::Method>::kEntries) {
    help += std::string("\n  ") + entry.name + ": " + entry.summary;
  }
  help += "\nOf a robot scenario:";
  for (const auto& entry : flexkin::Vocabulary<flexkin::FixedBaseMethod>::kEntries) {
    help += std::string("\n  ") + entry.name + ": " + entry.summary;
  }
  return help;
}

// The --projection help, from the library's vocabulary.
std::string ProjectionHelp() {
  std::string help =
      "Dynamic chain and groom scenarios (\"dynamics\"): overrides dynamics/projection:";
  for (const auto& entry : flexkin::Vocabulary<flexkin::Projection>::kEntries) {
    help += std::string("\n  ") + entry.name + ": " + entry.summary;
  }
  return help;
}

// The smallest record_every (above the scenario's) whose output fits in `limit`; 0 if none does.
int64_t RecordEveryThatFits(const flexkin::Scenario& s, flexkin::ResultFileFormat format, bool csv,
                            uint64_t limit) {
  const int64_t steps = s.leader_steps.rows();
  auto fits = [&](int64_t every) {
    flexkin::RunOptions options = s.options;
    options.record_every = static_cast<int>(every);
    const flexkin::ResultSizeEstimate e =
        flexkin::EstimateResultSize(s.chain.num_links(), s.chain.dim(), steps, options);
    return e.bytes(format) <= limit && (!csv || e.csv_bytes <= limit);
  };
  int64_t lo = s.options.record_every + 1, hi = std::max<int64_t>(steps, lo);
  if (hi > (int64_t{1} << 30)) hi = int64_t{1} << 30;  // record_every is an int
  if (!fits(hi)) return 0;
  while (lo < hi) {
    const int64_t mid = lo + (hi - lo) / 2;
    if (fits(mid)) {
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  return lo;
}

// Refuses, before the run, outputs whose estimated size is over --max-output-size.
void CheckOutputSize(const RunArgs& args, const flexkin::Scenario& s,
                     flexkin::ResultFileFormat format) {
  const uint64_t limit = args.max_output_size.empty()
                             ? flexkin::cli::kDefaultMaxOutputSize
                             : flexkin::cli::ParseByteSize(args.max_output_size);
  if (limit == 0) return;
  const flexkin::ResultSizeEstimate e = flexkin::EstimateResultSize(
      s.chain.num_links(), s.chain.dim(), s.leader_steps.rows(), s.options);
  const bool csv = !args.csv.empty();
  const bool result_over = e.bytes(format) > limit;
  if (!result_over && !(csv && e.csv_bytes > limit)) return;
  using flexkin::cli::FormatBytes;
  const uint64_t bytes = result_over ? e.bytes(format) : e.csv_bytes;
  std::string message = (result_over ? "the result " + args.output : "the frames CSV " + args.csv) +
                        " would be about " + FormatBytes(bytes) + " (" + std::to_string(e.frames) +
                        " frames of " + std::to_string(s.chain.num_links() + 1) + " points, " +
                        std::to_string(s.leader_steps.rows()) + " leader steps, recording every " +
                        std::to_string(s.options.record_every) + "), over the limit of " +
                        FormatBytes(limit) + ". Record fewer frames";
  if (const int64_t every = RecordEveryThatFits(s, format, csv, limit); every > 0) {
    message += " with --record-every " + std::to_string(every) +
               " (or \"record\": {\"every\": " + std::to_string(every) + "} in the scenario)";
  } else {
    message += " (even recording only the first and last frames would not fit)";
  }
  if (result_over && format == flexkin::ResultFileFormat::kJson) {
    message += ", write the binary format (-o with .npz: about " + FormatBytes(e.npz_bytes) + ")";
  }
  message += ", or raise the limit with --max-output-size " + flexkin::cli::SizeOptionFor(bytes) +
             " (0 = no limit)";
  throw flexkin::InputError(flexkin::Problem(flexkin::cli::kMaxOutputSizeOption, message));
}

// A groom scenario (docs/groom-format.md) goes to the strand engine; the options it shares with
// chain runs keep their meaning, those it has no use for are refused by name.
int RunGroom(const RunArgs& args, flexkin::AnyScenario scenario) {
  flexkin::cli::GroomRunArgs g;
  g.scenario = args.scenario;
  g.output = args.output;
  g.max_output_size = args.max_output_size;
  g.quiet = args.quiet;
  if (*args.method_opt) g.method = args.method;
  if (*args.precision_opt) g.precision = args.precision;
  if (*args.substeps_opt) g.substeps = args.substeps;
  if (*args.record_every_opt) g.record_every = args.record_every;
  if (*args.threads_opt) g.threads = args.threads;
  if (*args.projection_opt) g.projection = args.projection;
  const std::pair<CLI::Option*, const char*> unsupported[] = {
      {args.csv_opt, "--csv"},
      {args.tolerance_opt, "--tolerance"},
      {args.max_substeps_opt, "--max-substeps"},
      {args.no_link_angles_opt, "--no-link-angles"},
      {args.report_opt, "--report"}};
  for (const auto& [option, name] : unsupported) {
    if (*option) g.unsupported = name;
  }
  try {
    return flexkin::cli::RunGroomCommand(g, std::move(scenario));
  } catch (const flexkin::InputError& e) {
    // Problems of the file are named by the file; those of options by the option.
    const std::string field = e.field();
    if (!field.empty() && field[0] == '/') {
      PrintError(args.scenario + ": " + e.what());
      return kExitInvalidInput;
    }
    throw;
  }
}

// The options of `flexkin run` that only chain scenarios take (a robot's and a tree's run refuse
// them), with their names.
std::vector<std::pair<CLI::Option*, const char*>> ChainRunOptions(const RunArgs& args) {
  return {{args.substeps_opt, "--substeps"},
          {args.projection_opt, "--projection"},
          {args.tolerance_opt, "--tolerance"},
          {args.max_substeps_opt, "--max-substeps"},
          {args.record_every_opt, "--record-every"},
          {args.threads_opt, "--threads"},
          {args.precision_opt, "--precision"},
          {args.no_link_angles_opt, "--no-link-angles"},
          {args.report_opt, "--report"}};
}

// The name of the last of `options` given on the command line, or null.
const char* LastGiven(const std::vector<std::pair<CLI::Option*, const char*>>& options) {
  const char* given = nullptr;
  for (const auto& [option, name] : options) {
    if (*option) given = name;
  }
  return given;
}

// A robot scenario (docs/robot-format.md) is tracked into its trajectory JSON (and joint CSV), as
// `flexkin robot` does; --method names a FixedBaseMethod, the options of chain runs are refused.
int RunRobot(const RunArgs& args, flexkin::AnyScenario scenario) {
  flexkin::cli::RobotRunArgs r;
  r.scenario = args.scenario;
  r.output = args.output;
  r.csv = args.csv;
  r.max_output_size = args.max_output_size;
  r.quiet = args.quiet;
  if (*args.method_opt) r.method = args.method;
  if (const char* name = LastGiven(ChainRunOptions(args))) r.unsupported = name;
  return flexkin::cli::RunRobotCommand(r, std::move(scenario));
}

// `flexkin run` on a tree scenario (docs/trees.md): the result (.npz or .json) and one line.
int RunTreeCommand(const RunArgs& args, const flexkin::AnyScenario& any) {
  std::vector<std::pair<CLI::Option*, const char*>> options = ChainRunOptions(args);
  options.push_back({args.csv_opt, "--csv"});
  options.push_back({args.method_opt, "--method"});
  if (const char* name = LastGiven(options)) {
    throw flexkin::InputError(flexkin::Problem(
        name, "is not available for a tree scenario (" + args.scenario +
                  "); the scenario file sets a tree's method and options (docs/trees.md)"));
  }
  flexkin::cli::CheckOutputDirectory(args.output);
  flexkin::cli::Writing(args.output);
  const flexkin::TreeRunResult result =
      flexkin::RunScenarioToFiles(any, {args.output, ""}, [](int64_t, int64_t) {
        flexkin::cli::ThrowIfInterrupted();
      }).tree;
  if (!args.quiet) std::cout << result.BriefReport() << "\n";
  if (result.failures() > 0) {
    std::fprintf(stderr,
                 "flexkin: warning: %d of %zu frames did not reach their targets or converge "
                 "(their residuals are in the result); the result was written to %s\n",
                 result.failures(), result.reached.size(), args.output.c_str());
    return kExitNotConverged;
  }
  return kExitOk;
}

int RunCommand(const RunArgs& args) {
  // One read, one parse: the kind and every problem (flexkin/any_scenario.h).
  flexkin::AnyScenario any =
      flexkin::ReadScenarioFile(args.scenario, flexkin::cli::RobotReadOptions());
  if (!any.valid()) {
    PrintError(args.scenario + ": " + any.problems.front().Text());
    return kExitInvalidInput;
  }
  if (any.kind == flexkin::ScenarioKind::kRobot) return RunRobot(args, std::move(any));
  if (any.kind == flexkin::ScenarioKind::kGroom) return RunGroom(args, std::move(any));
  if (any.kind == flexkin::ScenarioKind::kTree) return RunTreeCommand(args, any);
  if (*args.threads_opt || *args.precision_opt) {
    throw flexkin::InputError(
        flexkin::Problem(*args.threads_opt ? "--threads" : "--precision",
                         "is an option of groom scenarios (docs/groom-format.md); " +
                             args.scenario + " is a chain scenario"));
  }
  flexkin::Scenario& scenario = *any.chain;
  const flexkin::ResultFileFormat format = flexkin::ResultFileFormatOfPath(args.output, "-o");
  if (scenario.dynamics) {
    ApplyDynamicOverrides(args, &scenario);
    ApplyOverrides(args, &scenario.options, /*dynamic=*/true);
  } else {
    if (*args.projection_opt) {
      throw flexkin::InputError(
          flexkin::Problem("--projection",
                           "is an option of dynamic chain scenarios (\"dynamics\", "
                           "docs/dynamics.md); " +
                               args.scenario + " has no \"dynamics\""));
    }
    ApplyOverrides(args, &scenario.options);
  }
  CheckOutputSize(args, scenario, format);
  flexkin::cli::CheckOutputDirectory(args.output);
  if (!args.csv.empty()) flexkin::cli::CheckOutputDirectory(args.csv);
  // The progress callback comes about every 0.1 s: where a signal stops the run (by throwing).
  const bool show_progress = !args.quiet && ::isatty(STDERR_FILENO);
  scenario.options.progress = [show_progress](int64_t done, int64_t total) {
    flexkin::cli::ThrowIfInterrupted();
    if (show_progress) ShowProgress(done, total);
  };
  flexkin::cli::Writing(args.output + (args.csv.empty() ? "" : " or " + args.csv));

  // The library's one call for every kind (flexkin/any_scenario.h): the frames stream to the
  // files as the run records them; the files are renamed into place only after the run, and
  // removed if it fails.
  const flexkin::RunResult result = flexkin::RunScenarioToFiles(any, {args.output, args.csv}).chain;

  if (!args.quiet) {
    std::cout << (args.report == "full" ? result.FullReport() : result.BriefReport() + "\n");
  }
  if (result.overall.failures > 0) {
    std::fprintf(stderr,
                 "flexkin: warning: the overall solver did not converge at %lld of %lld "
                 "sub-steps; first: %s; the result was written to %s\n",
                 static_cast<long long>(result.overall.failures),
                 static_cast<long long>(result.overall.solves),
                 result.overall.first_failure.c_str(), args.output.c_str());
    return kExitNotConverged;
  }
  if (result.accuracy.enabled && !result.accuracy.met) {
    std::fprintf(stderr,
                 "flexkin: warning: accuracy target not met: estimated error %.3g > tolerance "
                 "%.3g with %d sub-steps (raise --max-substeps or --tolerance); the result was "
                 "written to %s\n",
                 result.accuracy.estimated_error, scenario.options.tolerance,
                 result.accuracy.substeps, args.output.c_str());
    return kExitAccuracyNotMet;
  }
  return kExitOk;
}

// validate for a robot scenario (docs/robot-format.md): the estimated sizes of the trajectory
// JSON and the joint CSV.
void PrintRobotOutput(const flexkin::RobotScenario& scenario) {
  const flexkin::RobotOutputEstimate e = flexkin::EstimateRobotOutput(scenario);
  using flexkin::cli::FormatBytes;
  std::cout << "output: " << scenario.path.rows() + 1
            << " states (the initial one and one per target); trajectory about "
            << FormatBytes(e.json_bytes) << " as .json; --csv about " << FormatBytes(e.csv_bytes)
            << "; streamed, memory independent of the targets\n";
}

void PrintChainOutput(const flexkin::Scenario& scenario) {
  const flexkin::ResultSizeEstimate e =
      flexkin::EstimateResultSize(scenario.chain.num_links(), scenario.chain.dim(),
                                  scenario.leader_steps.rows(), scenario.options);
  using flexkin::cli::FormatBytes;
  std::cout << "output: " << e.frames << " frames (recording every "
            << scenario.options.record_every << " of " << scenario.leader_steps.rows()
            << (scenario.dynamics ? " frames of the dynamic chain" : " leader steps")
            << "); result about " << FormatBytes(e.json_bytes) << " as .json, "
            << FormatBytes(e.npz_bytes) << " as .npz; --csv about " << FormatBytes(e.csv_bytes)
            << "; keeping every frame in memory (Run without a sink) about "
            << FormatBytes(e.recorder_bytes) << "\n";
}

// Any kind of scenario, read once: every problem (exit 1), or its summary and output sizes.
int ValidateCommand(const std::string& path) {
  const flexkin::AnyScenario s = flexkin::ReadScenarioFile(path, flexkin::cli::RobotReadOptions());
  if (!s.valid()) {
    for (const auto& p : s.problems) std::cout << path << ": " << p.Text() << "\n";
    return kExitInvalidInput;
  }
  std::cout << "ok: " << s.Summary() << "\n";
  switch (s.kind) {
    case flexkin::ScenarioKind::kChain:
      PrintChainOutput(*s.chain);
      break;
    case flexkin::ScenarioKind::kGroom:
      flexkin::cli::PrintGroomOutput(*s.groom);
      break;
    case flexkin::ScenarioKind::kRobot:
      PrintRobotOutput(*s.robot);
      break;
    case flexkin::ScenarioKind::kTree:
      std::cout << "output: " << s.tree->frames() + 1
                << " frames (the start and one per path point) of " << s.tree->tree.points.rows()
                << " points, as .npz or .json\n";
      break;
  }
  return kExitOk;
}

int Main(int argc, char** argv) {
  CLI::App app{
      "flexkin: natural, length-preserving motion of a chain of rigid links whose\n"
      "leading end is moved along a path (tractrix method).",
      "flexkin"};
  app.set_version_flag("--version", std::string("flexkin ") + FLEXKIN_VERSION);
  app.require_subcommand(1);
  app.footer(kExitCodesHelp);

  RunArgs args;
  CLI::App* run = app.add_subcommand("run", "Run a scenario file and write the result.");
  run->add_option("scenario", args.scenario,
                  "Scenario file (JSON): a chain (docs/scenario-format.md), a groom "
                  "(docs/groom-format.md) or a robot (docs/robot-format.md)")
      ->required();
  run->add_option("-o,--output", args.output,
                  "File to write: a chain's result (.json or .npz, by its extension), a groom's "
                  "strand file (.npz), a robot's trajectory (.json)")
      ->required();
  args.csv_opt = run->add_option("--csv", args.csv,
                                 "Also write the recorded frames (a robot's joint angles) as CSV");
  args.method_opt = run->add_option("--method", args.method, MethodHelp());
  args.substeps_opt = run->add_option(
      "--substeps", args.substeps,
      "Sub-steps per leader step (>= 1); of a dynamic chain, per frame (its dynamics/substeps)");
  args.projection_opt = run->add_option("--projection", args.projection, ProjectionHelp());
  args.tolerance_opt = run->add_option(
      "--tolerance", args.tolerance,
      "Automatic sub-steps: largest distance to the continuous motion (length unit); 0 = off");
  args.max_substeps_opt = run->add_option("--max-substeps", args.max_substeps,
                                          "Upper bound of the automatic sub-steps");
  args.record_every_opt = run->add_option("--record-every", args.record_every,
                                          "Record every N-th leader step (and the last)");
  args.threads_opt = run->add_option(
      "--threads", args.threads, "Groom scenarios: threads stepping the strands (0: all cores)");
  args.precision_opt = run->add_option("--precision", args.precision,
                                       "Groom scenarios: points stored as float32 or float64");
  args.no_link_angles_opt =
      run->add_flag("--no-link-angles", args.no_link_angles,
                    "Record frames without their link angles (an atan2 per link per frame saved)");
  flexkin::cli::AddMaxOutputSizeOption(run, &args.max_output_size);
  args.report_opt = run->add_option("--report", args.report, "Report printed after the run")
                        ->check(CLI::IsMember({"brief", "full"}));
  run->add_flag("-q,--quiet", args.quiet, "Print no report and no progress");
  run->footer(kExitCodesHelp);

  std::string validate_path;
  CLI::App* validate = app.add_subcommand(
      "validate", "Check a scenario file (chain, robot or groom); list every problem.");
  validate->add_option("scenario", validate_path, "Scenario file (JSON)")->required();
  validate->footer(kExitCodesHelp);

  const flexkin::cli::RenderCommand render(&app, kExitCodesHelp);
  const flexkin::cli::RobotCommand robot(&app, kExitCodesHelp);
  const flexkin::cli::VocabularyCommand vocabulary(&app, kExitCodesHelp);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  flexkin::cli::InstallInterruptHandlers();
  try {
    if (*run) return RunCommand(args);
    if (render.Parsed()) return render.Run();
    if (robot.Parsed()) return robot.Run();
    if (vocabulary.Parsed()) return vocabulary.Run();
    return ValidateCommand(validate_path);
  } catch (const flexkin::cli::Interrupted&) {
    return ExitInterrupted();
  } catch (const flexkin::InputError& e) {
    if (flexkin::cli::InterruptSignal() != 0) return ExitInterrupted();
    PrintError(e.what());
    return kExitInvalidInput;
  } catch (const std::system_error& e) {  // files; std::ios_base::failure is one too
    if (flexkin::cli::InterruptSignal() != 0) return ExitInterrupted();
    PrintError(e.what());
    return kExitIoError;
  } catch (const std::exception&) {
    if (flexkin::cli::InterruptSignal() != 0) return ExitInterrupted();
    throw;
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Main(argc, argv);
  } catch (const std::bad_alloc&) {
    PrintError("out of memory");
  } catch (const std::exception& e) {
    PrintError(std::string("unexpected failure: ") + e.what());
  } catch (...) {
    PrintError("unexpected failure");
  }
  return kExitInvalidInput;
}
