#include "vocabulary_command.h"

#include <iostream>

#include "flexkin/arm.h"
#include "flexkin/curves.h"
#include "flexkin/dynamics.h"
#include "flexkin/gltf.h"
#include "flexkin/overall.h"
#include "flexkin/propagate.h"
#include "flexkin/render.h"
#include "flexkin/scenario_kind.h"
#include "flexkin/strand_file.h"
#include "flexkin/tree.h"
#include "flexkin/vocabulary.h"

namespace flexkin::cli {
namespace {

template <typename Enum>
void Table(std::ostream& out, const char* title, const char* where) {
  out << "## " << title << "\n\n" << where << "\n\n| name | meaning |\n|---|---|\n";
  for (const auto& entry : Vocabulary<Enum>::kEntries) {
    out << "| `" << entry.name << "` | " << entry.summary << " |\n";
  }
  out << "\n";
}

}  // namespace

void PrintVocabulary(std::ostream& out) {
  out << "# flexkin's vocabulary\n\n"
         "Every enumerated name that flexkin reads or writes, defined once in the library "
         "(`include/flexkin/vocabulary.h` and the table next to each enum). This page is the "
         "output of `flexkin vocabulary`; a test checks that it still is (regenerate it with "
         "`build/apps/flexkin vocabulary > docs/vocabulary.md`).\n\n";
  Table<Method>(out, "Methods",
                "`\"method\"` of a scenario file and of a result file, `flexkin run --method` "
                "(`Method`, flexkin/propagate.h).");
  Table<ScenarioKind>(out, "Scenario kinds",
                      "What `flexkin run`, `flexkin validate` and Python's `validate_scenario` "
                      "tell apart by a file's keys (`ScenarioKind`, flexkin/scenario_kind.h).");
  Table<BranchRule>(out, "Branch rules",
                    "`\"branch_rule\"` of a tree scenario, `reach_tree(branch_rule=)`: where a "
                    "tree's pulled branches meet (`BranchRule`, flexkin/tree.h; docs/trees.md).");
  Table<StrandPrecision>(out, "Strand file precisions",
                         "`\"record\"/\"precision\"` of a groom scenario, `flexkin run "
                         "--precision`, `run_groom(precision=)` (`StrandPrecision`, "
                         "flexkin/strand_file.h).");
  Table<CurveTurn>(out, "Curve turns",
                   "`\"curve\"/\"turn\"` of an arc or a helix in a scenario file, the `turn=` of "
                   "Python's `arc` and `helix` (`CurveTurn`, flexkin/curves.h).");
  Table<CurveSide>(out, "Parabola sides",
                   "`\"curve\"/\"side\"` of a parabola in a scenario file, the `side=` of Python's "
                   "`parabola` (`CurveSide`, flexkin/curves.h).");
  Table<ObjectiveTerm>(out, "Objective terms",
                       "The keys of `\"objective\"` in a scenario file (method `overall`) and of "
                       "`\"overall\"/\"objective\"` in a result file (`ObjectiveTerm`, "
                       "flexkin/overall.h).");
  Table<Projection>(out, "Projections",
                    "`\"dynamics\"/\"projection\"` of a dynamic chain scenario, `flexkin run "
                    "--projection`: how a dynamic chain's links are put back to their lengths "
                    "(`Projection`, flexkin/dynamics.h; docs/dynamics.md).");
  Table<FixedBaseMethod>(out, "Fixed-base methods",
                         "`\"solver\"/\"method\"` of a robot scenario file, `flexkin robot "
                         "--method` (`FixedBaseMethod`, flexkin/arm.h).");
  Table<ArmJoint>(out, "Joint kinds",
                  "The joints of a fixed-base arm (`ArmJoint`, flexkin/arm.h); the kind follows "
                  "from the arm's dimension and axes.");
  Table<PlotKind>(out, "Plots",
                  "The plots of `flexkin render --formats plots`, named in their files "
                  "(`PlotKind`, include/flexkin/render.h).");
  Table<OutputFormat>(out, "Output formats",
                      "`flexkin render --formats` (`OutputFormat`, include/flexkin/render.h); the "
                      "meaning column says which files each writes.");
  Table<GltfUpAxis>(out, "glTF up axes",
                    "Which flexkin axis points up in an exported glTF scene (`GltfUpAxis`, "
                    "include/flexkin/gltf.h).");
}

VocabularyCommand::VocabularyCommand(CLI::App* app, const std::string& footer) {
  command_ = app->add_subcommand(
      "vocabulary", "Print every enumerated name (methods, objective terms, ...) as Markdown.");
  command_->footer(footer);
}

int VocabularyCommand::Run() const {
  PrintVocabulary(std::cout);
  return 0;
}

}  // namespace flexkin::cli
