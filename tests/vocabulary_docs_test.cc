// Every enumerated name is defined once, in the library's vocabulary tables
// (flexkin/vocabulary.h); the docs and the JSON Schemas must say the same. docs/vocabulary.md is
// the output of `flexkin vocabulary` (printed from the tables), the schemas' enums and objective
// keys are the tables' names, and the command line's help lists every method and format.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "flexkin/arm.h"
#include "flexkin/overall.h"
#include "flexkin/propagate.h"
#include "flexkin/render.h"
#include "flexkin/vocabulary.h"
#include "test_util.h"

namespace flexkin {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::string kCli = FLEXKIN_CLI;
const fs::path kSource = FLEXKIN_SOURCE_DIR;

json Schema(const char* name) {
  return json::parse(test_util::ReadFile((kSource / "docs" / "schema" / name).string()));
}

std::vector<std::string> Keys(const json& object) {
  std::vector<std::string> keys;
  for (auto it = object.begin(); it != object.end(); ++it) keys.push_back(it.key());
  return keys;
}

std::vector<std::string> Sorted(std::vector<std::string> v) {
  std::sort(v.begin(), v.end());
  return v;
}

class VocabularyDocsTest : public testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(kCli.empty()) << "the flexkin command line was not built";
    dir_ = fs::temp_directory_path() / ("flexkin_vocabulary_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(VocabularyDocsTest, DocsVocabularyPageIsTheLibrarysTables) {
  const test_util::CliResult r = test_util::RunCli(kCli, dir_.string(), "vocabulary");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Every name of every table is in the output.
  for (const std::string& name : NamesOf<Method>())
    EXPECT_NE(r.out.find("`" + name + "`"), std::string::npos) << name;
  for (const std::string& name : NamesOf<ObjectiveTerm>())
    EXPECT_NE(r.out.find("`" + name + "`"), std::string::npos) << name;
  for (const std::string& name : NamesOf<OutputFormat>())
    EXPECT_NE(r.out.find("`" + name + "`"), std::string::npos) << name;
  EXPECT_EQ(r.out, test_util::ReadFile((kSource / "docs" / "vocabulary.md").string()))
      << "docs/vocabulary.md is not the output of `flexkin vocabulary`; regenerate it with "
         "build/apps/flexkin vocabulary > docs/vocabulary.md";
}

TEST(VocabularySchemaTest, SchemasNameWhatTheLibraryNames) {
  const json scenario = Schema("scenario.schema.json");
  EXPECT_EQ(scenario["properties"]["method"]["enum"].get<std::vector<std::string>>(),
            NamesOf<Method>());
  EXPECT_EQ(Sorted(Keys(scenario["properties"]["objective"]["properties"])),
            Sorted(NamesOf<ObjectiveTerm>()));
  const json result = Schema("result.schema.json");
  EXPECT_EQ(result["properties"]["method"]["enum"].get<std::vector<std::string>>(),
            NamesOf<Method>());
  EXPECT_EQ(Sorted(Keys(result["properties"]["overall"]["properties"]["objective"]["properties"])),
            Sorted(NamesOf<ObjectiveTerm>()));
  const json robot = Schema("robot.schema.json");
  EXPECT_EQ(
      robot["properties"]["solver"]["properties"]["method"]["enum"].get<std::vector<std::string>>(),
      NamesOf<FixedBaseMethod>());
}

TEST_F(VocabularyDocsTest, CommandLineHelpListsEveryMethodAndFormat) {
  const test_util::CliResult run = test_util::RunCli(kCli, dir_.string(), "run --help");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  for (const auto& entry : Vocabulary<Method>::kEntries) {
    EXPECT_NE(run.out.find(std::string(entry.name) + ": " + entry.summary), std::string::npos)
        << entry.name << " is missing from `flexkin run --help`:\n"
        << run.out;
  }
  const test_util::CliResult render = test_util::RunCli(kCli, dir_.string(), "render --help");
  ASSERT_EQ(render.exit_code, 0) << render.err;
  for (const auto& entry : Vocabulary<OutputFormat>::kEntries) {
    EXPECT_NE(render.out.find(std::string(entry.name) + ": " + entry.summary), std::string::npos)
        << entry.name << " is missing from `flexkin render --help`";
  }
}

TEST(VocabularyTest, NamesParseBackAndNearMissesAreSuggested) {
  for (const auto& entry : Vocabulary<Method>::kEntries) {
    EXPECT_EQ(ParseName<Method>(entry.name, "method"), entry.value);
    EXPECT_STREQ(NameOf(entry.value), entry.name);
  }
  try {
    ParseName<Method>("tractrx", "--method");
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "--method");
    EXPECT_EQ(e.problem().value, "\"tractrx\"");
    EXPECT_EQ(e.problem().expected, QuotedNames<Method>());
    EXPECT_NE(std::string(e.what()).find("did you mean \"tractrix\"?"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(QuotedList({"a", "b", "c"}), "\"a\", \"b\" or \"c\"");
  EXPECT_EQ(QuotedList({"a"}), "\"a\"");
}

}  // namespace
}  // namespace flexkin
