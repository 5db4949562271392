#pragma once
// `flexkin vocabulary`: every enumerated name of flexkin (methods, objective terms, fixed-base
// methods, joint kinds, plots, output formats, glTF up axes) as Markdown tables, printed from the
// library's vocabulary (flexkin/vocabulary.h). docs/vocabulary.md is this output, and a test
// checks that it still is.

#include <CLI/CLI.hpp>
#include <iosfwd>
#include <string>

namespace flexkin::cli {

class VocabularyCommand {
 public:
  VocabularyCommand(CLI::App* app, const std::string& footer);
  bool Parsed() const { return command_->parsed(); }
  int Run() const;

 private:
  CLI::App* command_ = nullptr;
};

// The Markdown text that `flexkin vocabulary` prints.
void PrintVocabulary(std::ostream& out);

}  // namespace flexkin::cli
