#pragma once
// `flexkin run GROOM.json -o HAIR.npz`: a groom scenario (docs/groom-format.md) run through the
// strand engine into a strand file (docs/strands.md). `flexkin run` hands a groom scenario here;
// the options it shares with chain scenarios keep their meaning.

#include <optional>
#include <string>

#include "flexkin/any_scenario.h"
#include "flexkin/groom.h"

namespace flexkin::cli {

struct GroomRunArgs {
  std::string scenario, output, max_output_size;
  std::optional<std::string> method, precision, projection;
  std::optional<int> substeps, record_every, threads;
  // Options of chain runs that have no meaning for a groom ("--csv"), refused by name.
  std::string unsupported;
  bool quiet = false;
};

// Runs the groom and writes the strand file. Returns the exit status (0); throws InputError (exit
// 1) and std::system_error (a file: exit 4) for flexkin_main to report.
// `scenario` is the file's, read and checked by the front door (flexkin/any_scenario.h).
int RunGroomCommand(const GroomRunArgs& args, AnyScenario scenario);

// `flexkin validate` of a groom scenario: the strand file's frames and size.
void PrintGroomOutput(const GroomScenario& scenario);

}  // namespace flexkin::cli
