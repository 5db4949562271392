// Tree results read back (flexkin/tree_scenario.h ReadTreeResultFile; docs/trees.md "Results"):
// the .npz form (tree.json beside frames.npy) and the JSON form, checked member by member.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/tree_scenario.h"
#include "io/json_file.h"
#include "io/json_values.h"
#include "io/npz.h"

namespace flexkin {
namespace {

using json = nlohmann::json;

constexpr uint64_t kMaxTreeHeaderBytes = 64u << 20;
constexpr int64_t kMaxTreePoints = 1 << 24;

// The header's keys (both forms) and what the JSON form adds.
class TreeResultReader : public json_internal::JsonReader {
 public:
  // The format, name, method, dim, parents, targets and fixed of `root`; `json_form`: the keys of
  // the JSON form (frames and the reports per frame) are allowed too.
  void ReadHeader(const json& root, bool json_form, TreeResultFile* out) {
    if (!ExpectObject(root, "", "an object (a tree result, docs/trees.md)")) return;
    std::vector<std::string> keys = {"format",           "name",     "method", "dim",
                                     "parents",          "targets",  "looks",  "fixed",
                                     "max_length_error", "failures", "joints", "sliding",
                                     "prismatic"};
    if (json_form) {
      for (const char* k : {"frames", "goals", "angles", "passes", "residual", "reached",
                            "converged", "finished"}) {
        keys.push_back(k);
      }
    }
    CheckKeys(root, "", keys);
    if (const json* format =
            Required(root, "", "format", "\"flexkin-tree-result\" (a tree result)")) {
      if (!(format->is_string() && *format == "flexkin-tree-result")) {
        ValueProblem(*format, "/format", "\"flexkin-tree-result\" (a tree result)");
      }
    }
    Optional(
        root, "", "name", [&](const json& v, const std::string& p) { return String(v, p); },
        &out->name);
    std::string method = NameOf(out->method);
    Optional(
        root, "", "method",
        [&](const json& v, const std::string& p) {
          return Choice(
              v, p, {"tractrix", "ftl", "min_rotation", "min_joint_angle", "overall", "newton"});
        },
        &method);
    out->robot = method == "newton";  // a robot tree's joints solved in joint space
    if (!out->robot) out->method = ParseName<Method>(method, "/method");
    if (const json* joints = Find(root, "joints")) {
      if (!joints->is_array()) {
        TypeProblem(*joints, "/joints", "an array of joint names");
      } else {
        for (size_t k = 0; k < joints->size(); ++k) {
          if (auto name = String((*joints)[k], "/joints/" + std::to_string(k))) {
            out->joints.push_back(*name);
          }
        }
      }
    }
    int64_t dim = 0;
    Require(
        root, "", "dim", "2 or 3",
        [&](const json& v, const std::string& p) { return Integer(v, p, 2, 3); }, &dim);
    out->dim = static_cast<int>(dim);
    out->parents = Indices(root, "parents", -1, kMaxTreePoints, true);
    const int last = static_cast<int>(out->parents.size()) - 1;
    out->targets = Indices(root, "targets", 0, std::max(last, 0), false);
    out->fixed = Indices(root, "fixed", 0, std::max(last, 0), false);
    if (Find(root, "looks") != nullptr) Flags(root, "looks", out->targets.size(), &out->looks);
    out->sliding = Indices(root, "sliding", 1, std::max(last, 1), false);
    if (Find(root, "prismatic") != nullptr) {
      Flags(root, "prismatic", out->joints.size(), &out->prismatic);
    }
  }

  // The JSON form's frames, each (n+1) by dim, and "reached" and "converged" (F - 1 booleans).
  void ReadJsonArrays(const json& root, TreeResultFile* out) {
    const int rows = static_cast<int>(out->parents.size());
    const json* frames = Required(root, "", "frames", "an array of frames");
    if (frames == nullptr) return;
    if (!frames->is_array() || frames->empty()) {
      TypeProblem(*frames, "/frames", "an array of at least 1 frame");
      return;
    }
    dimension_of_ = "the tree";
    for (size_t f = 0; f < frames->size(); ++f) {
      const std::string ptr = "/frames/" + std::to_string(f);
      const auto p = PointList((*frames)[f], ptr, out->dim, rows, rows);
      if (!p) return;
      out->frames.push_back(*p);
    }
    if (const json* goals = Find(root, "goals")) {
      if (!goals->is_array() || goals->size() + 1 != frames->size()) {
        TypeProblem(*goals, "/goals",
                    "an array of " + std::to_string(frames->size() - 1) +
                        " frames of goals, one per frame after the first");
        return;
      }
      const int k = static_cast<int>(out->targets.size());
      for (size_t f = 0; f < goals->size(); ++f) {
        const auto g = PointList((*goals)[f], "/goals/" + std::to_string(f), out->dim, k, k);
        if (!g) return;
        out->goals.push_back(*g);
      }
    }
    if (const json* angles = Find(root, "angles")) {
      const int n = static_cast<int>(out->joints.size());
      if (!angles->is_array() || angles->size() != frames->size()) {
        TypeProblem(*angles, "/angles",
                    "an array of " + std::to_string(frames->size()) +
                        " arrays of joint angles, one per frame");
        return;
      }
      for (size_t f = 0; f < angles->size(); ++f) {
        const std::string ptr = "/angles/" + std::to_string(f);
        const json& a = (*angles)[f];
        if (!a.is_array() || static_cast<int>(a.size()) != n) {
          TypeProblem(a, ptr, "an array of " + std::to_string(n) + " angles (one per joint)");
          return;
        }
        Eigen::VectorXd q(n);
        for (int j = 0; j < n; ++j) {
          const auto x = Number(a[j], ptr + "/" + std::to_string(j), json_internal::Range::kAny);
          if (!x) return;
          q[j] = *x;
        }
        out->angles.push_back(q);
      }
    }
    std::vector<char> converged;
    Flags(root, "reached", frames->size() - 1, &out->reached);
    Flags(root, "converged", frames->size() - 1, &converged);
    for (size_t k = 0; k < converged.size() && k < out->reached.size(); ++k) {
      out->reached[k] = out->reached[k] && converged[k];
    }
  }

 private:
  std::vector<int> Indices(const json& root, const char* key, int64_t min, int64_t max,
                           bool required) {
    std::vector<int> out;
    const std::string expected =
        std::string("an array of point indices") + (min < 0 ? ", -1 for the root" : "");
    const json* v = required ? Required(root, "", key, expected) : Find(root, key);
    if (v == nullptr) return out;
    const std::string ptr = std::string("/") + key;
    if (!v->is_array() || (required && v->size() < 2)) {
      TypeProblem(*v, ptr, required ? expected + " (at least 2)" : expected);
      return out;
    }
    for (size_t k = 0; k < v->size(); ++k) {
      if (auto i = Integer((*v)[k], ptr + "/" + std::to_string(k), min, max)) {
        out.push_back(static_cast<int>(*i));
      }
    }
    return out;
  }

  void Flags(const json& root, const char* key, size_t count, std::vector<char>* out) {
    const std::string expected = "an array of " + std::to_string(count) + " booleans";
    const json* v = Required(root, "", key, expected);
    if (v == nullptr) return;
    if (!v->is_array() || v->size() != count) {
      TypeProblem(*v, std::string("/") + key, expected);
      return;
    }
    for (size_t k = 0; k < count; ++k) {
      if (!(*v)[k].is_boolean()) {
        TypeProblem((*v)[k], std::string("/") + key + "/" + std::to_string(k), "a boolean");
        return;
      }
      out->push_back((*v)[k].get<bool>() ? 1 : 0);
    }
  }
};

// `field` of the problem with `prefix` before it ("tree.json" + "/parents/4").
[[noreturn]] void Rethrow(const InputError& e, const std::string& prefix) {
  Problem p = e.problem();
  p.field = prefix + p.field;
  throw InputError(p);
}

// A 1-dimensional member of `descr` and `count` entries, whole.
template <typename T>
std::vector<T> ReadFlat(ZipReader* zip, const std::string& name, const char* descr,
                        uint64_t count) {
  ZipReader::Member member(zip, name);
  const NpyArray a = ReadNpyHeader(&member, name, descr);
  ExpectNpyShape(a, name, {count}, "a valid tree result");
  std::vector<T> v(count);
  member.Read(v.data(), sizeof(T) * count);
  member.Finish();
  return v;
}

TreeResultFile ReadNpz(const std::string& path) {
  ZipReader zip(path, {"frames.npy", "parents.npy", "reached.npy", "converged.npy", "goals.npy",
                       "angles.npy"});
  if (!zip.Has("tree.json")) {
    throw InputError("tree.json", "missing; a tree result's .npz holds tree.json and frames.npy");
  }
  TreeResultFile out;
  TreeResultReader reader;
  try {
    reader.ReadHeader(ParseJsonText(zip.ReadWhole("tree.json", kMaxTreeHeaderBytes)), false, &out);
    ThrowIfAny(reader.problems);
  } catch (const InputError& e) {
    Rethrow(e, "tree.json");
  }
  const uint64_t rows = out.parents.size(), dim = static_cast<uint64_t>(out.dim);
  const std::vector<int64_t> parents = ReadFlat<int64_t>(&zip, "parents.npy", "<i8", rows);
  for (uint64_t i = 0; i < rows; ++i) {
    if (parents[i] != out.parents[i]) {
      throw InputError("parents.npy",
                       "entry " + std::to_string(i) + " is " + std::to_string(parents[i]) +
                           " but tree.json's parents have " + std::to_string(out.parents[i]) +
                           "; not a valid tree result");
    }
  }
  ZipReader::Member frames(&zip, "frames.npy");
  const NpyArray fa = ReadNpyHeader(&frames, "frames.npy", "<f8");
  const uint64_t count = fa.shape.empty() ? 0 : fa.shape[0];
  ExpectNpyShape(fa, "frames.npy", {count, rows, dim}, "a valid tree result");
  if (count == 0) throw InputError("frames.npy", "has no frames; expected at least the start");
  for (uint64_t f = 0; f < count; ++f) {
    Points p(rows, dim);
    frames.Read(p.data(), sizeof(double) * rows * dim);
    out.frames.push_back(std::move(p));
  }
  frames.Finish();
  if (zip.Has("goals.npy")) {
    ZipReader::Member goals(&zip, "goals.npy");
    const uint64_t k = out.targets.size();
    ExpectNpyShape(ReadNpyHeader(&goals, "goals.npy", "<f8"), "goals.npy", {count - 1, k, dim},
                   "a valid tree result");
    for (uint64_t f = 0; f + 1 < count; ++f) {
      Points g(k, dim);
      goals.Read(g.data(), sizeof(double) * k * dim);
      out.goals.push_back(std::move(g));
    }
    goals.Finish();
  }
  if (zip.Has("angles.npy")) {  // a robot tree's joints, every frame
    ZipReader::Member angles(&zip, "angles.npy");
    const uint64_t n = out.joints.size();
    ExpectNpyShape(ReadNpyHeader(&angles, "angles.npy", "<f8"), "angles.npy", {count, n},
                   "a valid tree result (a row of joint angles per frame)");
    for (uint64_t f = 0; f < count; ++f) {
      Eigen::VectorXd q(n);
      angles.Read(q.data(), sizeof(double) * n);
      if (!q.allFinite()) {
        throw InputError("angles.npy", "frame " + std::to_string(f) +
                                           " has an angle that is not finite; expected finite "
                                           "numbers");
      }
      out.angles.push_back(std::move(q));
    }
    angles.Finish();
  }
  const std::vector<char> reached = ReadFlat<char>(&zip, "reached.npy", "|b1", count - 1);
  const std::vector<char> converged = ReadFlat<char>(&zip, "converged.npy", "|b1", count - 1);
  for (uint64_t k = 0; k + 1 < count; ++k) out.reached.push_back(reached[k] && converged[k]);
  return out;
}

TreeResultFile ReadJson(const std::string& path) {
  const json root = ReadJsonFile(path);
  TreeResultFile out;
  TreeResultReader reader;
  reader.ReadHeader(root, true, &out);
  ThrowIfAny(reader.problems);
  reader.ReadJsonArrays(root, &out);
  ThrowIfAny(reader.problems);
  return out;
}

// How a problem's place is named: a file's member or JSON pointer, or a member path.
enum class Naming { kNpz, kJson, kMember };

// A tree result's checks (ReadTreeResultFile after reading, ValidateTreeResult): shapes, finite
// coordinates, the parents a tree without links of length 0 in the first frame, targets and
// fixed points among the points, a report per frame after the first. The first problem found.
Problems CheckTreeResult(const TreeResultFile& out, Naming naming) {
  const bool member = naming == Naming::kMember, npz = naming == Naming::kNpz;
  auto point = [&](size_t f, Eigen::Index i) {
    return member ? "frames[" + std::to_string(f) + "][" + std::to_string(i) + "]"
           : npz  ? "frames.npy[" + std::to_string(f) + "][" + std::to_string(i) + "]"
                  : "/frames/" + std::to_string(f) + "/" + std::to_string(i);
  };
  auto coordinate = [&](size_t f, Eigen::Index i, Eigen::Index k) {
    return naming == Naming::kJson ? point(f, i) + "/" + std::to_string(k)
                                   : point(f, i) + "[" + std::to_string(k) + "]";
  };
  const Eigen::Index rows = static_cast<Eigen::Index>(out.parents.size());
  if (member) {  // what the readers have checked already
    if (out.dim != 2 && out.dim != 3) {
      return {Problem::Invalid("dim", std::to_string(out.dim), "2 or 3")};
    }
    if (out.frames.empty()) return {Problem("frames", "is empty; expected at least the start")};
    for (size_t f = 0; f < out.frames.size(); ++f) {
      if (out.frames[f].rows() != rows || out.frames[f].cols() != out.dim) {
        return {Problem("frames[" + std::to_string(f) + "]",
                        "is " + std::to_string(out.frames[f].rows()) + " by " +
                            std::to_string(out.frames[f].cols()) + "; expected " +
                            std::to_string(rows) + " by " + std::to_string(out.dim) +
                            " (a row per parent entry, dim columns)")};
      }
    }
    if (out.reached.size() + 1 != out.frames.size()) {
      return {Problem("reached", "has " + std::to_string(out.reached.size()) +
                                     " entries; expected one per frame after the first (" +
                                     std::to_string(out.frames.size() - 1) + ")")};
    }
    if (!out.looks.empty() && out.looks.size() != out.targets.size()) {
      return {Problem("looks", "has " + std::to_string(out.looks.size()) +
                                   " entries; expected one per target (" +
                                   std::to_string(out.targets.size()) + ") or none")};
    }
    if (!out.prismatic.empty() && out.prismatic.size() != out.joints.size()) {
      return {Problem("prismatic", "has " + std::to_string(out.prismatic.size()) +
                                       " entries; expected one per joint (" +
                                       std::to_string(out.joints.size()) + ") or none")};
    }
    if (!out.goals.empty() && out.goals.size() + 1 != out.frames.size()) {
      return {Problem("goals", "has " + std::to_string(out.goals.size()) +
                                   " frames; expected one per frame after the first (" +
                                   std::to_string(out.frames.size() - 1) + ") or none")};
    }
    for (size_t f = 0; f < out.goals.size(); ++f) {
      if (out.goals[f].rows() != static_cast<Eigen::Index>(out.targets.size()) ||
          out.goals[f].cols() != out.dim || !out.goals[f].allFinite()) {
        return {Problem("goals[" + std::to_string(f) + "]",
                        "is not one finite row per target of dim columns")};
      }
    }
    for (const auto& [name, points] :
         {std::pair<const char*, const std::vector<int>*>{"targets", &out.targets},
          {"fixed", &out.fixed}}) {
      for (size_t k = 0; k < points->size(); ++k) {
        if ((*points)[k] < 0 || (*points)[k] >= rows) {
          return {Problem::Invalid(std::string(name) + "[" + std::to_string(k) + "]",
                                   std::to_string((*points)[k]),
                                   "a point from 0 to " + std::to_string(rows - 1))};
        }
      }
    }
  }
  for (size_t f = 0; f < out.frames.size(); ++f) {
    const Points& p = out.frames[f];
    for (Eigen::Index i = 0; i < p.rows(); ++i) {
      for (Eigen::Index k = 0; k < p.cols(); ++k) {
        if (!std::isfinite(p(i, k))) {
          return {Problem(coordinate(f, i, k),
                          FormatNumber(p(i, k)) + " is not valid; expected a finite number")};
        }
      }
    }
  }
  std::vector<char> sliding(static_cast<size_t>(rows), 0);
  for (size_t k = 0; k < out.sliding.size(); ++k) {
    if (out.sliding[k] < 1 || out.sliding[k] >= rows) {
      return {Problem::Invalid(member ? "sliding[" + std::to_string(k) + "]"
                               : npz  ? "tree.json/sliding/" + std::to_string(k)
                                      : "/sliding/" + std::to_string(k),
                               std::to_string(out.sliding[k]),
                               "a point from 1 to " + std::to_string(rows - 1))};
    }
    sliding[out.sliding[k]] = 1;
  }
  try {
    ValidateTree(Tree{out.frames.front(), out.parents}, "", &sliding);
  } catch (const InputError& e) {
    Problem p = e.problem();
    // "parents[4]" -> the parents' entry; "points[7]" -> point 7 of the first frame.
    const size_t open = p.field.find('['), close = p.field.find(']');
    const std::string index =
        open == std::string::npos ? "" : p.field.substr(open + 1, close - open - 1);
    if (p.field.rfind("points", 0) == 0) {
      p.field = point(0, std::stol(index)) + p.field.substr(close + 1);
    } else if (p.field.rfind("parents", 0) == 0 && !member) {
      p.field = (npz ? "tree.json/parents/" : "/parents/") + index;
    }
    return {p};
  }
  return {};
}

}  // namespace

TreeResultFile ReadTreeResultFile(const std::string& path) {
  char magic[4] = {0, 0, 0, 0};
  bool npz = false;
  if (std::FILE* file = std::fopen(path.c_str(), "rb")) {
    npz = std::fread(magic, 1, sizeof magic, file) == sizeof magic &&
          std::memcmp(magic, "PK\x03\x04", 4) == 0;
    std::fclose(file);
  }
  TreeResultFile out = npz ? ReadNpz(path) : ReadJson(path);
  ThrowIfAny(CheckTreeResult(out, npz ? Naming::kNpz : Naming::kJson));
  return out;
}

Problems ValidateTreeResult(const TreeResultFile& tree) {
  return CheckTreeResult(tree, Naming::kMember);
}

}  // namespace flexkin
