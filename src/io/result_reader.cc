#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "flexkin/error.h"
#include "flexkin/result_io.h"
#include "io/colliders_json.h"
#include "io/json_checked.h"
#include "io/json_file.h"
#include "io/result_check.h"
#include "io/result_json.h"

// Result files in (docs/result-format.md): the first problem is thrown, naming its JSON pointer.

namespace flexkin {
namespace {

using json = nlohmann::json;

using json_checked::Member;
using json_checked::ReadInteger;
using json_checked::ReadNumber;
using json_checked::Show;

bool ReadBool(const json& v, const std::string& ptr) {
  if (!v.is_boolean()) throw InputError(ptr, "value " + Show(v) + " is not true or false");
  return v.get<bool>();
}

// An array of numbers; `size` < 0 accepts any length.
Eigen::VectorXd ReadVector(const json& v, const std::string& ptr, Eigen::Index size) {
  if (!v.is_array() || (size >= 0 && v.size() != static_cast<size_t>(size))) {
    throw InputError(ptr, "value " + Show(v) + " is not valid; expected an array of " +
                              (size >= 0 ? std::to_string(size) + " " : std::string()) + "numbers");
  }
  Eigen::VectorXd out(v.size());
  for (size_t i = 0; i < v.size(); ++i) out[i] = ReadNumber(v[i], ptr + "/" + std::to_string(i));
  return out;
}

Points ReadPoints(const json& v, const std::string& ptr, Eigen::Index rows, int dim) {
  if (!v.is_array() || v.size() != static_cast<size_t>(rows)) {
    throw InputError(ptr, "is not valid; expected an array of " + std::to_string(rows) +
                              " points (one per link end)");
  }
  Points points(rows, dim);
  for (Eigen::Index i = 0; i < rows; ++i) {
    points.row(i) = ReadVector(v[i], ptr + "/" + std::to_string(i), dim).transpose();
  }
  return points;
}

}  // namespace

void ReadResultSummary(const json& j, const ResultArrays* arrays, ResultFile* out) {
  ResultFile& file = *out;
  RunResult& r = file.result;
  const json& format = Member(j, "", "format");
  if (format != kResultFormat) {
    throw InputError("/format",
                     "value " + Show(format) + " is not valid; expected \"" + kResultFormat + "\"");
  }
  const json& version = Member(j, "", "version");
  if (version != kResultVersion) {
    throw InputError("/version", "value " + Show(version) + " is not supported; expected " +
                                     std::to_string(kResultVersion));
  }
  const json& method = Member(j, "", "method");
  if (!method.is_string())
    throw InputError("/method", "value " + Show(method) + " is not a string");
  r.method = ParseMethod(method.get<std::string>(), "/method");
  if (const auto it = j.find("scenario"); it != j.end()) {
    if (!it->is_string()) throw InputError("/scenario", "value " + Show(*it) + " is not a string");
    file.scenario_name = it->get<std::string>();
  }
  file.dim = static_cast<int>(ReadInteger(Member(j, "", "dim"), "/dim", 2));
  if (file.dim > 3)
    throw InputError("/dim", "value " + std::to_string(file.dim) + " is not 2 or 3");
  if (const auto it = j.find("colliders"); it != j.end()) {
    Problems problems;
    file.colliders = ReadCollidersJson(*it, "/colliders", file.dim, &problems);
    ThrowIfAny(problems);
  }
  r.lengths =
      arrays ? arrays->lengths : ReadVector(Member(j, "", "link_lengths"), "/link_lengths", -1);
  const Eigen::Index n = r.lengths.size();
  if (const auto it = j.find("link_radii"); it != j.end()) {
    file.link_radii = ReadVector(*it, "/link_radii", n);
    if (auto problem = LinkRadiiProblem(file.link_radii, n, true)) throw InputError(*problem);
  }
  r.num_steps = ReadInteger(Member(j, "", "num_steps"), "/num_steps", 0);

  const json& accuracy = Member(j, "", "accuracy");
  r.accuracy.enabled = ReadBool(Member(accuracy, "/accuracy", "enabled"), "/accuracy/enabled");
  r.accuracy.tolerance =
      ReadNumber(Member(accuracy, "/accuracy", "tolerance"), "/accuracy/tolerance");
  r.accuracy.max_substeps = static_cast<int>(
      ReadInteger(Member(accuracy, "/accuracy", "max_substeps"), "/accuracy/max_substeps", 0));
  r.accuracy.substeps = static_cast<int>(
      ReadInteger(Member(accuracy, "/accuracy", "substeps"), "/accuracy/substeps", 1));
  r.accuracy.order =
      static_cast<int>(ReadInteger(Member(accuracy, "/accuracy", "order"), "/accuracy/order", 0));
  r.accuracy.estimated_error =
      ReadNumber(Member(accuracy, "/accuracy", "estimated_error"), "/accuracy/estimated_error");
  r.accuracy.met = ReadBool(Member(accuracy, "/accuracy", "met"), "/accuracy/met");
  if (const auto it = j.find("overall"); it != j.end()) {
    const json& o = *it;
    const json& w = Member(o, "/overall", "objective");
    for (const auto& [term, name, summary] : Vocabulary<ObjectiveTerm>::kEntries) {
      const std::string pointer = std::string("/overall/objective/") + name;
      // The L2 terms are optional: files written before they existed lack them.
      const bool optional = term == ObjectiveTerm::kL2 || term == ObjectiveTerm::kL2Weighted;
      if (const auto it = w.find(name); it != w.end()) {
        r.weights[term] = ReadNumber(*it, pointer);
      } else if (!optional) {
        Member(w, "/overall/objective", name);  // throws: a required term is missing
      }
    }
    r.overall.solves = ReadInteger(Member(o, "/overall", "solves"), "/overall/solves", 0);
    r.overall.failures = ReadInteger(Member(o, "/overall", "failures"), "/overall/failures", 0);
    r.overall.iterations =
        ReadInteger(Member(o, "/overall", "iterations"), "/overall/iterations", 0);
    r.overall.max_iterations = static_cast<int>(
        ReadInteger(Member(o, "/overall", "max_iterations"), "/overall/max_iterations", 0));
    r.overall.constraint_violation =
        ReadNumber(Member(o, "/overall", "constraint_violation"), "/overall/constraint_violation");
    r.overall.optimality = ReadNumber(Member(o, "/overall", "optimality"), "/overall/optimality");
  }

  if (const auto it = j.find("dynamics"); it != j.end()) {
    const json& d = *it;
    DynamicRunReport& report = r.dynamics;
    report.enabled = true;
    const json& projection = Member(d, "/dynamics", "projection");
    if (!projection.is_string()) {
      throw InputError("/dynamics/projection", "value " + Show(projection) + " is not a string");
    }
    report.projection = projection.get<std::string>();
    report.frame_rate = ReadNumber(Member(d, "/dynamics", "frame_rate"), "/dynamics/frame_rate");
    report.substeps =
        static_cast<int>(ReadInteger(Member(d, "/dynamics", "substeps"), "/dynamics/substeps", 1));
    report.failures = ReadInteger(Member(d, "/dynamics", "failures"), "/dynamics/failures", 0);
    // The contact counts (absent from files written before they were): 0 if absent.
    for (auto [key, to] : {std::pair{"contact_substeps", &report.contact_substeps},
                           std::pair{"contact_solves", &report.contact_solves},
                           std::pair{"contact_solve_failures", &report.contact_solve_failures}}) {
      if (const auto at = d.find(key); at != d.end()) {
        *to = ReadInteger(*at, std::string("/dynamics/") + key, 0);
      }
    }
    report.energy =
        ReadVector(Member(d, "/dynamics", "energy"), "/dynamics/energy", r.num_steps + 1);
  }

  const json& metrics = Member(j, "", "metrics");
  Metrics& m = r.metrics;
  m.l2_total = ReadNumber(Member(metrics, "/metrics", "l2_total"), "/metrics/l2_total");
  m.l2_weighted_total =
      ReadNumber(Member(metrics, "/metrics", "l2_weighted_total"), "/metrics/l2_weighted_total");
  m.max_relative_length_error = ReadNumber(Member(metrics, "/metrics", "max_relative_length_error"),
                                           "/metrics/max_relative_length_error");
  if (arrays != nullptr) {
    m.path_length = arrays->path_length;
    m.l2_per_step = arrays->l2_per_step;
    m.l2_weighted_per_step = arrays->l2_weighted_per_step;
  } else {
    m.path_length =
        ReadVector(Member(metrics, "/metrics", "path_length"), "/metrics/path_length", n + 1);
    m.l2_per_step =
        ReadVector(Member(metrics, "/metrics", "l2_per_step"), "/metrics/l2_per_step", r.num_steps);
    m.l2_weighted_per_step = ReadVector(Member(metrics, "/metrics", "l2_weighted_per_step"),
                                        "/metrics/l2_weighted_per_step", r.num_steps);
  }
  if (const auto it = j.find("seconds"); it != j.end()) r.seconds = ReadNumber(*it, "/seconds");
}

ResultFile ResultFromJson(const json& j) {
  ResultFile file;
  RunResult& r = file.result;
  ReadResultSummary(j, nullptr, &file);
  const Eigen::Index n = r.lengths.size();

  const json& frames = Member(j, "", "frames");
  if (!frames.is_array() || frames.empty()) {
    throw InputError("/frames", "is not valid; expected an array of at least one frame");
  }
  // Every frame has link angles or none has (the first frame says which).
  const bool with_angles = !Member(frames[0], "/frames/0", "link_angles").empty();
  r.frames.Reserve(static_cast<int64_t>(frames.size()), n + 1, file.dim, with_angles);
  for (size_t f = 0; f < frames.size(); ++f) {
    const std::string ptr = "/frames/" + std::to_string(f);
    const int64_t step = ReadInteger(Member(frames[f], ptr, "step"), ptr + "/step", 0);
    const Points points =
        ReadPoints(Member(frames[f], ptr, "points"), ptr + "/points", n + 1, file.dim);
    const json& angles = Member(frames[f], ptr, "link_angles");
    if (angles.empty() == with_angles) {
      throw InputError(ptr + "/link_angles",
                       with_angles ? "is empty while frame 0 has link angles; expected " +
                                         std::to_string(n) + " values, as in every frame"
                                   : "has values while frame 0 has none; expected [] in every "
                                     "frame or link angles in every frame");
    }
    r.frames.Add(step, points, ReadVector(angles, ptr + "/link_angles", with_angles ? n : 0));
  }
  // What the shapes read above do not say (positive lengths, increasing steps, ...): the one check
  // of results, its member path made the file's JSON pointer.
  if (Problems problems = ValidateResult(r, file.dim); !problems.empty()) {
    problems.front().field = MemberPathToPointer(problems.front().field);
    ThrowIfAny(problems);
  }
  return file;
}

ResultFile ReadResultJson(const std::string& path) { return ResultFromJson(ReadJsonFile(path)); }

ResultFile ReadResultFile(const std::string& path) {
  char magic[4] = {0, 0, 0, 0};
  if (std::FILE* file = std::fopen(path.c_str(), "rb")) {
    const size_t n = std::fread(magic, 1, sizeof magic, file);
    std::fclose(file);
    if (n == sizeof magic && std::memcmp(magic, "PK\x03\x04", 4) == 0) return ReadNpzResult(path);
  }
  return ReadResultJson(path);  // reports a file that cannot be read
}

ResultFile ResultFromText(const std::string& json_text) {
  return ResultFromJson(ParseJsonText(json_text));
}

}  // namespace flexkin
