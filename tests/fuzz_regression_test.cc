// The fuzz targets' inputs in the normal test build (docs/fuzzing.md): every file of
// fuzz/regressions/<target>/ (inputs that once crashed or misbehaved, kept after the fix) and of
// fuzz/corpus/<target>/ (the seeds) goes through the target's reader (fuzz/readers.h), which must
// succeed or throw flexkin::InputError with a message.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "readers.h"

namespace flexkin::fuzz {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> FilesIn(const fs::path& dir) {
  std::vector<fs::path> files;
  if (!fs::is_directory(dir)) return files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file() && entry.path().filename() != "README.md") {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Runs every file of fuzz/<folder>/<target>/ through its target's reader; returns how many.
int CheckFolder(const std::string& folder) {
  int files = 0;
  for (const Target& target : Targets()) {
    const fs::path dir = fs::path(FLEXKIN_SOURCE_DIR) / "fuzz" / folder / target.name;
    for (const fs::path& file : FilesIn(dir)) {
      SCOPED_TRACE(file.string());
      ++files;
      try {
        target.read(ReadBytes(file));
      } catch (const InputError& e) {
        EXPECT_FALSE(std::string(e.what()).empty());
        EXPECT_FALSE(e.message().empty());
      }
    }
  }
  return files;
}

TEST(FuzzRegression, EveryRegressionIsReadOrRefusedWithAnInputError) { CheckFolder("regressions"); }

TEST(FuzzRegression, EverySeedIsReadOrRefusedWithAnInputError) {
  EXPECT_GT(CheckFolder("corpus"), 0);
}

}  // namespace
}  // namespace flexkin::fuzz
