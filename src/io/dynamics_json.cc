// The "dynamics" object of chain and groom scenario files (docs/scenario-format.md "dynamics",
// docs/groom-format.md "dynamics"): the options of dynamic chains and strands
// (flexkin/dynamics.h), read once for both.

#include <string>
#include <utility>
#include <vector>

#include "flexkin/dynamics.h"
#include "flexkin/error.h"
#include "flexkin/vocabulary.h"
#include "io/json_values.h"

namespace flexkin::json_internal {

std::optional<DynamicOptions> JsonReader::ReadDynamics(const json& v, const std::string& ptr,
                                                       int dim, int num_links, bool strands) {
  const char* what = strands ? "the strands' dimension" : "the chain's dimension";
  if (!ExpectObject(v, ptr,
                    strands ? "an object {\"gravity\": [0, 0, -9.81], \"projection\": "
                              "\"tractrix\", ...} (the options of dynamic strands)"
                            : "an object {\"gravity\": [x, y], \"projection\": \"overall\", ...} "
                              "(the options of a dynamic chain)")) {
    return std::nullopt;
  }
  // "frame_rate" and "substeps" are known keys for strands too, refused below with the reason.
  const std::vector<std::string> keys = {"projection",   "gravity",    "damping",
                                         "wind",         "wind_keys",  "mass",
                                         "dftl_damping", "frame_rate", "substeps"};
  const size_t before = problems.size();
  for (const char* key : {"frame_rate", "substeps"}) {
    if (strands && v.contains(key)) {
      Add(ptr + "/" + key,
          std::string("is not a key of a groom's \"dynamics\": ") +
              (std::string(key) == "frame_rate" ? "the frame rate is the motion's \"fps\""
                                                : "the sub-steps are the groom's \"substeps\""),
          v[key].dump(), "no \"" + std::string(key) + "\"");
    }
  }
  CheckKeys(v, ptr, keys);
  DynamicOptions d;
  if (const json* p = Find(v, "projection")) {
    if (const auto name = String(*p, ptr + "/projection")) {
      if (const NamedValue<Projection>* entry = FindName<Projection>(*name)) {
        d.projection = entry->value;
      } else {
        problems.push_back(UnknownName(ptr + "/projection", Vocabulary<Projection>::kKind, *name,
                                       NamesOf<Projection>()));
      }
    }
  }
  const auto vector = [this, dim](const json& x, const std::string& p) {
    return Vector(x, p, dim);
  };
  const auto non_negative = [this](const json& x, const std::string& p) {
    return Number(x, p, Range::kNonNegative);
  };
  Require(v, ptr, "gravity",
          std::string("an array of ") + what + " (length units per s^2, e.g. " +
              (strands ? "[0, 0, -9.81])" : "[0, -9.81])"),
          vector, &d.gravity);
  Optional(v, ptr, "damping", non_negative, &d.damping);
  Optional(v, ptr, "wind", vector, &d.wind);
  if (const json* keys_json = Find(v, "wind_keys")) {
    const std::string kp = ptr + "/wind_keys";
    if (v.contains("wind")) {
      Add(kp,
          "is given with \"wind\"; expected one of them: a constant \"wind\" or the keyframed "
          "\"wind_keys\"");
    } else if (!keys_json->is_array() || keys_json->empty()) {
      TypeProblem(*keys_json, kp,
                  "an array of at least 1 key {\"time\": s, \"velocity\": [...]}, times "
                  "strictly increasing");
    } else {
      for (size_t i = 0; i < keys_json->size(); ++i) {
        const json& key = (*keys_json)[i];
        const std::string at = kp + "/" + std::to_string(i);
        if (!ExpectObject(key, at, "an object {\"time\": s, \"velocity\": [...]}")) continue;
        CheckKeys(key, at, {"time", "velocity"});
        DynamicOptions::WindKey k;
        Require(
            key, at, "time", "a finite number (seconds from the run's start)",
            [this](const json& x, const std::string& p) { return Number(x, p, Range::kAny); },
            &k.time);
        Require(key, at, "velocity", std::string("an array of ") + what + " (the air's velocity)",
                vector, &k.velocity);
        d.wind_keys.push_back(std::move(k));
      }
    }
  }
  if (!strands) {
    Optional(
        v, ptr, "frame_rate",
        [this](const json& x, const std::string& p) { return Number(x, p, Range::kPositive); },
        &d.frame_rate);
    if (const json* s = Find(v, "substeps")) {
      if (const auto n = Integer(*s, ptr + "/substeps", 1, int64_t{1} << 30)) {
        d.substeps = static_cast<int>(*n);
      }
    }
  }
  if (const json* m = Find(v, "mass")) {
    const std::string mp = ptr + "/mass";
    if (m->is_string()) {
      if (const auto choice = Choice(*m, mp, {"by_length", "uniform"})) {
        d.mass_by_length = *choice == "by_length";
      }
    } else if (m->is_array()) {
      if (auto masses = NumberList(*m, mp, 1, Range::kPositive)) {
        if (num_links > 0 && masses->size() != num_links) {
          Add(mp,
              "has " + std::to_string(masses->size()) + " numbers; expected " +
                  std::to_string(num_links) +
                  ", one per free point (points 1 to n; the chain has " +
                  std::to_string(num_links) + " links)",
              m->dump(), std::to_string(num_links) + " numbers > 0");
        } else {
          d.masses = std::move(*masses);
        }
      }
    } else {
      TypeProblem(*m, mp,
                  "\"by_length\" (each point half of each link it touches), \"uniform\" "
                  "(every free point the same) or an array of one number > 0 per free point "
                  "(points 1 to n" +
                      std::string(strands ? " of every strand)" : ")"));
    }
  }
  Optional(v, ptr, "dftl_damping", non_negative, &d.dftl_damping);
  if (problems.size() != before || dim == 0) return std::nullopt;
  // What the library's own check says (increasing wind times, dftl_damping <= 1, ...), its
  // member names made the file's pointers ("wind_keys[1].time" -> "/dynamics/wind_keys/1/time").
  for (Problem p : d.ValidateFor(dim)) {
    std::string field = p.field;
    if (field.rfind("masses", 0) == 0) field = "mass" + field.substr(6);
    p.field = ptr + MemberPathToPointer(field);
    problems.push_back(std::move(p));
  }
  if (problems.size() != before) return std::nullopt;
  return d;
}

}  // namespace flexkin::json_internal
