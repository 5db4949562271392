#pragma once
// Helpers of the rendering tests (render_test.cc, render_cli_test.cc): the two small scenes of
// the golden images, a temporary directory, files and SVG paths.

#include <dirent.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/result_io.h"
#include "flexkin/run.h"
#include "scenes/scenes.h"
#include "test_util.h"

namespace flexkin::render_test {

// A curved chain of 5 links pulled through 6 leader steps: 7 frames. 2D: an arc; 3D: a helix
// pulled up and sideways. No three consecutive points are collinear, so that every point is a
// vertex of the drawn polyline (cairo merges collinear segments).
inline ResultFile SmallScene(int dim) {
  const Chain chain = scenes::CurvedChain(dim, 5, 1.0, 0.55);
  Points steps(6, dim);
  for (int k = 1; k <= 6; ++k) {
    steps(k - 1, 0) = 1.0 - 0.32 * k;
    steps(k - 1, 1) = -0.12 * k + 0.015 * k * k;
    if (dim == 3) steps(k - 1, 2) = 0.2 * k;
  }
  ResultFile file;
  file.result = Run(chain, steps, RunOptions());
  file.dim = dim;
  file.scenario_name = dim == 2 ? "small planar scene" : "small spatial scene";
  return file;
}

using test_util::ReadFile;

inline void WriteFile(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

inline bool Exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

// A fresh directory under the system's temporary directory, removed with its files.
class TempDir {
 public:
  TempDir() {
    std::string name = (std::filesystem::temp_directory_path() / "flexkin_render_XXXXXX").string();
    if (::mkdtemp(name.data()) != nullptr) dir_ = name;
  }
  ~TempDir() {
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
  }
  const std::string& dir() const { return dir_; }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  // The names of the files in the directory, sorted.
  std::vector<std::string> Files() const {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir_)) {
      names.push_back(e.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  std::string dir_;
};

// One <path> of an SVG document outside <defs> (glyph outlines are in <defs>).
struct SvgPath {
  std::string style;
  std::vector<std::pair<double, double>> vertices;  // of M and L commands, in order
  bool closed = false;                              // has a Z
  bool curved = false;                              // has a C (a disc or ring)
};

inline std::vector<SvgPath> SvgPaths(const std::string& svg) {
  std::vector<SvgPath> paths;
  const size_t defs_end = svg.find("</defs>");
  const std::string body = svg.substr(defs_end == std::string::npos ? 0 : defs_end);
  static const std::regex kPath(R"re(<path style="([^"]*)" d="([^"]*)")re");
  for (auto it = std::sregex_iterator(body.begin(), body.end(), kPath);
       it != std::sregex_iterator(); ++it) {
    SvgPath path;
    path.style = (*it)[1];
    std::istringstream d((*it)[2].str());
    std::string token;
    char command = 0;
    while (d >> token) {
      if (std::isalpha(static_cast<unsigned char>(token[0]))) {
        command = token[0];
        path.closed |= command == 'Z';
        path.curved |= command == 'C';
        continue;
      }
      if (command == 'M' || command == 'L') {
        double y = 0.0;
        d >> y;
        path.vertices.emplace_back(std::stod(token), y);
      } else if (command == 'C') {
        double skip;
        d >> skip;  // C takes three points; only their presence matters here
      }
    }
    paths.push_back(path);
  }
  return paths;
}

// The start of each filled curved path of an SVG: cairo's discs (plot markers).
inline std::vector<Eigen::Vector2d> Discs(const std::vector<SvgPath>& paths) {
  std::vector<Eigen::Vector2d> starts;
  for (const SvgPath& p : paths) {
    if (!p.curved || p.style.find("fill:none") != std::string::npos) continue;
    starts.emplace_back(p.vertices.front().first, p.vertices.front().second);
  }
  return starts;
}

}  // namespace flexkin::render_test
