#include "groom_command.h"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <iostream>
#include <string>

#include "flexkin/error.h"
#include "flexkin/groom.h"
#include "flexkin/strand_file.h"
#include "flexkin/vocabulary.h"
#include "interrupt.h"
#include "output_check.h"
#include "output_limit.h"

namespace flexkin::cli {
namespace {

// The strand file's size: the points, plus 112 bytes of pose, frame number and time per frame,
// the offsets and lengths, and a few KiB of ZIP and .npy headers and groom.json.
uint64_t StrandFileBytes(const StrandFileHeader& h) {
  const uint64_t f = static_cast<uint64_t>(h.num_frames), p = static_cast<uint64_t>(h.num_points());
  return f * p * static_cast<uint64_t>(h.dim) * (h.float32 ? 4 : 8) + f * 112 + 16 * p + 8192;
}

// The override of a scenario value by a command-line option, checked as the scenario's is.
void ApplyOverrides(const GroomRunArgs& args, GroomScenario* s) {
  if (!args.unsupported.empty()) {
    throw InputError(Problem(args.unsupported, "is not available for a groom scenario (" +
                                                   args.scenario +
                                                   "); it applies to chain scenarios only"));
  }
  GroomOverrides overrides;
  overrides.method = args.method;
  overrides.projection = args.projection;
  overrides.precision = args.precision;
  overrides.substeps = args.substeps;
  overrides.threads = args.threads;
  overrides.record_every = args.record_every;
  ApplyGroomOverrides(overrides, /*command_line=*/true, s);
}

void CheckSize(const GroomRunArgs& args, const StrandFileHeader& h) {
  const uint64_t limit =
      args.max_output_size.empty() ? kDefaultMaxOutputSize : ParseByteSize(args.max_output_size);
  const uint64_t bytes = StrandFileBytes(h);
  if (limit == 0 || bytes <= limit) return;
  const uint64_t frame_bytes = StrandFileBytes(h) / static_cast<uint64_t>(h.num_frames);
  const int64_t fit_frames = static_cast<int64_t>(limit / (frame_bytes + 1));
  std::string message = "the strand file " + args.output + " would be about " + FormatBytes(bytes) +
                        " (" + std::to_string(h.num_frames) + " frames of " +
                        std::to_string(h.num_points()) + " points), over the limit of " +
                        FormatBytes(limit) + ". Record fewer frames";
  if (fit_frames >= 2) {
    const int64_t every = (h.num_frames * h.record_every + fit_frames - 2) / (fit_frames - 1);
    message += " (--record-every " + std::to_string(every) + ")";
  }
  if (!h.float32) message += ", write float32 (--precision float32)";
  message +=
      ", or raise the limit with --max-output-size " + SizeOptionFor(bytes) + " (0 = no limit)";
  throw InputError(Problem(kMaxOutputSizeOption, message));
}

bool ShowProgress(int64_t done, int64_t total) {
  if (done % 16 == 0 || done == total) {
    std::fprintf(stderr, "\rflexkin: frame %lld of %lld (%.0f%%)", static_cast<long long>(done),
                 static_cast<long long>(total), total > 0 ? 100.0 * done / total : 100.0);
    if (done >= total) std::fputc('\n', stderr);
    std::fflush(stderr);
  }
  return true;
}

}  // namespace

int RunGroomCommand(const GroomRunArgs& args, AnyScenario any) {
  GroomScenario& scenario = *any.groom;
  ApplyOverrides(args, &scenario);
  const std::string& out = args.output;
  if (out.size() < 4 || out.compare(out.size() - 4, 4, ".npz") != 0) {
    throw InputError(Problem::Invalid("-o", "\"" + out + "\"",
                                      "a path ending in .npz: a groom run writes a strand file "
                                      "(NumPy archive, docs/strands.md)"));
  }
  const StrandFileHeader header = MakeStrandFileHeader(scenario);
  CheckSize(args, header);
  CheckOutputDirectory(out);
  const bool progress = !args.quiet && ::isatty(STDERR_FILENO);
  Writing(out);
  // The library's one call for every kind (flexkin/any_scenario.h). Called after every frame:
  // where a signal stops the run (by throwing).
  const StrandRunReport report =
      RunScenarioToFiles(any, {out, ""}, [progress](int64_t done, int64_t total) {
        ThrowIfInterrupted();
        if (progress) ShowProgress(done, total);
      }).strands;
  if (!args.quiet) {
    const int64_t frames = scenario.motion.num_frames();
    const std::string how = StrandMotionName(header);  // "dynamic, projection dftl", "tractrix"
    char line[512];
    std::snprintf(line, sizeof line,
                  "%s: %d strands, %lld points, %lld frames (%lld recorded, %s); %s on %s x %d "
                  "thread%s: %.3f ms per frame; largest link-length error %.2g\n",
                  out.c_str(), header.num_strands(), static_cast<long long>(header.num_points()),
                  static_cast<long long>(frames), static_cast<long long>(header.num_frames),
                  PrecisionName(header.float32), how.c_str(), report.engine.c_str(), report.threads,
                  report.threads == 1 ? "" : "s",
                  frames > 1 ? 1e3 * report.seconds / static_cast<double>(frames - 1) : 0.0,
                  report.max_length_error);
    std::cout << line;
  }
  return 0;
}

void PrintGroomOutput(const GroomScenario& scenario) {
  const StrandFileHeader h = MakeStrandFileHeader(scenario);
  std::cout << "output: " << h.num_frames << " frames recorded of " << scenario.motion.num_frames()
            << "; strand file about " << FormatBytes(StrandFileBytes(h)) << " ("
            << PrecisionName(h.float32) << "); streamed, memory independent of the frames\n";
}

}  // namespace flexkin::cli
