// Groom scenario files in (docs/groom-format.md): a GroomParser on the value readers every file
// reader shares (src/io/json_values.h), so numbers, messages and suggestions are those of chain
// and robot scenario files, and every problem is listed before the first one is thrown.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "flexkin/chain.h"
#include "flexkin/error.h"
#include "flexkin/groom.h"
#include "flexkin/propagate.h"
#include "flexkin/result_io.h"
#include "flexkin/scenario_kind.h"
#include "flexkin/vocabulary.h"
#include "groom/groom_reader.h"
#include "groom/grow_internal.h"
#include "io/colliders_json.h"
#include "io/json_file.h"
#include "io/json_values.h"
#include "io/scenario_kinds.h"

namespace flexkin {
namespace {

using json_internal::json;
using json_internal::Range;
using json_internal::ShowJson;

constexpr int64_t kMaxLinks = int64_t{1} << 20;
constexpr int64_t kMaxSeed = int64_t{1} << 53;  // every integer up to here is exact in JSON

const char* const kRootExpected =
    "an object with \"groom\" (or \"strands\") and \"motion\" (docs/groom-format.md)";

// A GrowSpec member path as the JSON pointer of the key that sets it.
std::string GrowFieldToPointer(const std::string& field, const std::string& shape) {
  const std::pair<const char*, const char*> keys[] = {
      {"scalp.shape", "/groom/scalp/shape"},
      {"scalp.center", "/groom/scalp/center"},
      {"roots", "/groom/roots"},
      {"links", "/groom/links"},
      {"link_length", "/groom/link_length"},
      {"length_variation", "/groom/length_variation"},
      {"droop", "/groom/direction/droop"},
      {"gravity", "/groom/direction/gravity"},
      {"region_axis", "/groom/region/axis"},
      {"max_angle_deg", "/groom/region/max_angle_deg"},
      {"region", "/groom/region"}};
  for (const auto& [member, pointer] : keys) {
    if (field == member) return pointer;
  }
  if (field.rfind("scalp.radii", 0) == 0) {
    if (shape == "sphere") return "/groom/scalp/radius";
    return "/groom/scalp/radii" + MemberPathToPointer(field.substr(11));
  }
  return "/groom";
}

class GroomParser : public json_internal::JsonReader {
 public:
  // grow: grow the strands of a "groom" (else only place their roots, to check the region).
  explicit GroomParser(bool grow) : grow_(grow) { dimension_of_ = "the scenario"; }

  // The scenario with its strands grown (or given); valid if and only if no problem was added.
  GroomScenario Parse(const json& root) {
    GroomScenario s;
    if (!ExpectObject(root, "", kRootExpected)) return s;
    CheckKeys(root, "",
              {"$schema", "name", "description", "groom", "strands", "motion", "method", "substeps",
               "pinned", "threads", "record", "colliders", "world_colliders", "scalp_collider",
               "dynamics"});
    for (const char* key : {"$schema", "name", "description"}) {
      if (const json* v = Find(root, key)) {
        if (const auto text = String(*v, std::string("/") + key)) {
          if (key == std::string("name")) s.name = *text;
          if (key == std::string("description")) s.description = *text;
        }
      }
    }
    std::optional<GrowSpec> spec;
    std::optional<std::vector<Points>> strands;
    int dim = 0;  // unknown
    const json* groom = Find(root, "groom");
    const json* given = Find(root, "strands");
    if (groom != nullptr && given != nullptr) {
      Add("/strands",
          "is not valid with \"groom\"; give groom (strands grown on a scalp) or "
          "strands (given point by point), not both");
    } else if (groom != nullptr) {
      dim = 3;
      spec = ParseGroom(*groom, "/groom");
    } else if (given != nullptr) {
      strands = ParseStrands(*given, "/strands", &dim);
    } else {
      Add("/groom",
          "missing; expected an object {\"scalp\": ..., \"roots\": n, \"links\": n, "
          "\"link_length\": l, ...}, or \"strands\": [{\"points\": [...]}, ...]",
          "", "an object, or \"strands\"");
    }
    std::optional<BodyMotion> motion;
    if (const json* m = Required(root, "", "motion",
                                 "an object {\"fps\": 30, \"keyframes\": [{\"time\": 0, ...}]}")) {
      motion = ParseMotion(*m, "/motion", dim);
    }
    ParseOptions(root, &s);
    if (const json* d = Find(root, "dynamics")) {
      s.options.dynamics = ReadDynamics(*d, "/dynamics", dim, 0, /*strands=*/true);
      if (s.options.dynamics) {
        s.options.dynamics->substeps = s.options.substeps;
        if (motion) s.options.dynamics->frame_rate = motion->fps;
      }
      if (root.contains("method")) {
        Add("/method",
            "is not used with \"dynamics\" (dynamic strands are moved by inertia and "
            "\"dynamics/projection\"); remove \"method\"",
            root["method"].dump(), "no \"method\"");
      }
    }
    bool scalp_collider = true;
    if (const json* v = Find(root, "scalp_collider")) {
      if (!v->is_boolean()) {
        TypeProblem(*v, "/scalp_collider", "true or false");
      } else {
        scalp_collider = v->get<bool>();
      }
    }
    if (dim != 0) {
      if (const json* c = Find(root, "colliders")) {
        s.options.body_colliders =
            ReadCollidersJson(*c, "/colliders", dim, &problems, directory, "seconds");
        // They move with the body: a keyframed collider is a world collider.
        for (size_t i = 0; i < s.options.body_colliders.size(); ++i) {
          if (!s.options.body_colliders[i].motion) continue;
          Add("/colliders/" + std::to_string(i) + "/motion",
              "is not valid for a collider that moves with the body; a keyframed collider is a "
              "world collider (\"world_colliders\")",
              "{...}", "no \"motion\" here");
          s.options.body_colliders[i].motion = nullptr;
        }
      }
      if (const json* c = Find(root, "world_colliders")) {
        s.options.colliders =
            ReadCollidersJson(*c, "/world_colliders", dim, &problems, directory, "seconds");
      }
    }
    if (!problems.empty()) return s;

    s.dim = dim;
    s.motion = std::move(*motion);
    if (spec) {
      s.scalp = spec->scalp;
      try {
        if (grow_) {
          s.strands = GrowStrands(*spec);
        } else {
          groom_internal::PlaceRoots(*spec,
                                     [](const Eigen::Vector3d&, const Eigen::Vector3d&, double) {});
        }
      } catch (const InputError& e) {
        Problem p = e.problem();
        p.field = GrowFieldToPointer(p.field, spec->scalp.shape);
        problems.push_back(std::move(p));
      }
    } else {
      s.strands = std::move(*strands);
    }
    CheckMasses(spec ? spec->links : 0, &s);
    // The scalp is a collider too, unless the file says otherwise: the last body collider.
    if (spec && scalp_collider) {
      Collider scalp;
      scalp.pose.translation() = spec->scalp.center;
      if (spec->scalp.shape == "sphere") {
        scalp.shape = ColliderShape::kSphere;
        scalp.radius = spec->scalp.radii[0];
      } else {
        scalp.shape = ColliderShape::kEllipsoid;
        scalp.extents = spec->scalp.radii;
      }
      s.options.body_colliders.push_back(scalp);
    }
    if (problems.empty() && !s.strands.empty()) CheckStart(s, spec.has_value() && scalp_collider);
    return s;
  }

 private:
  // Given masses: the strands' own need "dynamics"; the one profile of "dynamics/mass" needs
  // every strand without its own to have as many links (`links`: the grown strands', 0 for given
  // strands).
  void CheckMasses(int links, GroomScenario* s) {
    if (!given_masses_.empty()) {
      if (!s->options.dynamics) {
        for (size_t i = 0; i < given_masses_.size(); ++i) {
          if (given_masses_[i].size() == 0) continue;
          Add("/strands/" + std::to_string(i) + "/masses",
              "is given without \"dynamics\"; masses are for dynamic strands", "[...]",
              "no \"masses\", or a \"dynamics\" object");
          return;
        }
      }
      given_masses_.resize(s->strands.size());
      s->options.masses = std::move(given_masses_);
    }
    if (!s->options.dynamics || s->options.dynamics->masses.size() == 0) return;
    const Eigen::Index profile = s->options.dynamics->masses.size();
    const std::string valid = "one number > 0 per free point of every strand";
    if (links > 0 && links != profile) {
      Add("/dynamics/mass",
          "has " + std::to_string(profile) + " numbers; expected " + std::to_string(links) +
              ", one per free point (the strands grow " + std::to_string(links) + " links)",
          "[...]", valid);
      return;
    }
    for (size_t i = 0; links == 0 && i < s->strands.size(); ++i) {
      const Eigen::Index n = s->strands[i].rows() - 1;
      if (n == profile || (i < s->options.masses.size() && s->options.masses[i].size() != 0)) {
        continue;
      }
      Add("/dynamics/mass",
          "has " + std::to_string(profile) + " numbers; /strands/" + std::to_string(i) + " has " +
              std::to_string(n) + " links (give it its own \"masses\")",
          "[...]", valid);
      return;
    }
  }

  // A strand that starts inside a collider (at the first keyframe's pose) is a problem of the
  // collider's entry, naming the root (the strand) and the point.
  void CheckStart(const GroomScenario& s, bool scalp_last) {
    StrandOptions options = s.options;
    // The strands are in body coordinates: the world's colliders brought into them.
    const BodyPose start = s.motion.PoseAt(0);
    Eigen::Isometry3d to_body = Eigen::Isometry3d::Identity();
    to_body.linear() = start.rotation;
    to_body.translation() = start.translation;
    if (s.dim == 2) {
      to_body.linear().row(2).setZero(), to_body.linear().col(2).setZero();
      to_body.linear()(2, 2) = 1.0;
      to_body.translation()[2] = 0.0;
    }
    to_body = to_body.inverse();
    for (Collider& c : options.colliders) {
      c = ColliderAt(c, s.motion.TimeOf(0));  // a keyframed one where its motion starts it
      c.pose = to_body * c.pose;
    }
    const std::optional<StrandInside> in = FindStrandInside(s.strands, options, BodyPose());
    if (!in) return;
    const int num_body = static_cast<int>(s.options.body_colliders.size());
    std::string ptr;
    if (in->body && scalp_last && in->collider == num_body - 1) {
      ptr = "/groom/scalp";
    } else {
      ptr = std::string(in->body ? "/colliders/" : "/world_colliders/") +
            std::to_string(in->collider);
    }
    const std::string strand = s.scalp.shape.empty()
                                   ? "strand " + std::to_string(in->strand) + " (/strands/" +
                                         std::to_string(in->strand) + ")"
                                   : "the strand of root " + std::to_string(in->strand);
    Add(ptr, "holds " + strand + " at the start: " +
                 (in->link ? "its link " + std::to_string(in->point) + " (points " +
                                 std::to_string(in->point - 1) + " to " +
                                 std::to_string(in->point) + ") passes through it"
                           : "its point " + std::to_string(in->point) + " lies inside it") +
                 " by " + FormatNumber(in->depth) + " (" + FormatNumber(in->relative) +
                 " of the link's length); every strand must start outside every collider (move or "
                 "shrink the collider, or set \"scalp_collider\": false for the scalp)");
  }

  std::optional<int> Int(const json& v, const std::string& ptr, int64_t min, int64_t max) {
    const auto n = Integer(v, ptr, min, max);
    return n ? std::optional<int>(static_cast<int>(*n)) : std::nullopt;
  }
  auto NumberOf(Range range) {
    return [this, range](const json& v, const std::string& p) { return Number(v, p, range); };
  }
  auto VectorOf(int dim) {
    return [this, dim](const json& v, const std::string& p) { return Vector(v, p, dim); };
  }
  // A number in [0, 1) (below_one) or [0, 1].
  std::optional<double> Fraction(const json& v, const std::string& ptr, bool below_one) {
    const char* expected = below_one ? "a number >= 0 and < 1" : "a number from 0 to 1";
    if (!v.is_number()) {
      TypeProblem(v, ptr, expected);
      return std::nullopt;
    }
    const double x = v.get<double>();
    if (!(x >= 0.0 && (below_one ? x < 1.0 : x <= 1.0))) {
      ValueProblem(v, ptr, expected);
      return std::nullopt;
    }
    return x;
  }

  // "groom": the spec, checked but not grown.
  std::optional<GrowSpec> ParseGroom(const json& groom, const std::string& ptr) {
    if (!ExpectObject(groom, ptr,
                      "an object {\"scalp\": ..., \"roots\": n, \"links\": n, \"link_length\": "
                      "l, ...}")) {
      return std::nullopt;
    }
    CheckKeys(groom, ptr,
              {"scalp", "roots", "region", "links", "link_length", "length_variation", "direction",
               "seed"});
    const size_t before = problems.size();
    GrowSpec spec;
    if (const json* scalp = Required(groom, ptr, "scalp",
                                     "an object {\"shape\": \"sphere\", \"center\": [x, y, z], "
                                     "\"radius\": r} or {\"shape\": \"ellipsoid\", ..., "
                                     "\"radii\": [a, b, c]}")) {
      ParseScalp(*scalp, ptr + "/scalp", &spec.scalp);
    }
    Require(
        groom, ptr, "roots", "an integer >= 1 (the number of strands)",
        [this](const json& v, const std::string& p) { return Int(v, p, 1, kMaxGroomRoots); },
        &spec.roots);
    Require(
        groom, ptr, "links", "an integer >= 1 (links per strand)",
        [this](const json& v, const std::string& p) { return Int(v, p, 1, kMaxLinks); },
        &spec.links);
    Require(groom, ptr, "link_length", "a finite number > 0 (the length of a link)",
            NumberOf(Range::kPositive), &spec.link_length);
    Optional(
        groom, ptr, "length_variation",
        [this](const json& v, const std::string& p) { return Fraction(v, p, true); },
        &spec.length_variation);
    if (const json* region = Find(groom, "region")) {
      const std::string rp = ptr + "/region";
      if (ExpectObject(*region, rp, "an object {\"axis\": [x, y, z], \"max_angle_deg\": a}")) {
        CheckKeys(*region, rp, {"axis", "max_angle_deg"});
        Eigen::VectorXd axis = spec.region_axis;
        Optional(*region, rp, "axis", VectorOf(3), &axis);
        spec.region_axis = axis;
        Optional(*region, rp, "max_angle_deg", NumberOf(Range::kPositive), &spec.max_angle_deg);
      }
    }
    if (const json* direction = Find(groom, "direction")) {
      const std::string dp = ptr + "/direction";
      if (ExpectObject(*direction, dp, "an object {\"droop\": d, \"gravity\": [x, y, z]}")) {
        CheckKeys(*direction, dp, {"droop", "gravity"});
        Optional(
            *direction, dp, "droop",
            [this](const json& v, const std::string& p) { return Fraction(v, p, false); },
            &spec.droop);
        Eigen::VectorXd gravity = spec.gravity;
        Optional(*direction, dp, "gravity", VectorOf(3), &gravity);
        spec.gravity = gravity;
      }
    }
    int64_t seed = 1;
    Optional(
        groom, ptr, "seed",
        [this](const json& v, const std::string& p) { return Integer(v, p, 0, kMaxSeed); }, &seed);
    spec.seed = static_cast<uint64_t>(seed);
    if (problems.size() != before) return std::nullopt;
    // What is left (zero vectors, the angle's range, the number of points) is the spec's own
    // check.
    for (Problem p : ValidateGrowSpec(spec)) {
      p.field = GrowFieldToPointer(p.field, spec.scalp.shape);
      problems.push_back(std::move(p));
    }
    if (problems.size() != before) return std::nullopt;
    return spec;
  }

  void ParseScalp(const json& scalp, const std::string& ptr, ScalpShape* out) {
    if (!ExpectObject(scalp, ptr,
                      "an object {\"shape\": \"sphere\", \"radius\": r, ...} or {\"shape\": "
                      "\"ellipsoid\", \"radii\": [a, b, c], ...}")) {
      return;
    }
    std::optional<std::string> shape;
    if (const json* v = Required(scalp, ptr, "shape", "\"sphere\" or \"ellipsoid\"")) {
      shape = Choice(*v, ptr + "/shape", {"sphere", "ellipsoid"});
    }
    if (!shape) {
      CheckKeys(scalp, ptr, {"shape", "center", "radius", "radii"});
      return;
    }
    out->shape = *shape;
    Eigen::VectorXd center = Eigen::Vector3d::Zero();
    Optional(scalp, ptr, "center", VectorOf(3), &center);
    out->center = center;
    if (*shape == "sphere") {
      CheckKeys(scalp, ptr, {"shape", "center", "radius"});
      double radius = 0.0;
      Require(scalp, ptr, "radius", "a finite number > 0 (the sphere's radius)",
              NumberOf(Range::kPositive), &radius);
      out->radii = Eigen::Vector3d::Constant(radius);
      return;
    }
    CheckKeys(scalp, ptr, {"shape", "center", "radii"});
    const json* radii =
        Required(scalp, ptr, "radii", "an array of 3 numbers > 0 (the semi-axes along x, y and z)");
    if (radii == nullptr) return;
    const size_t before = problems.size();
    Eigen::VectorXd r = Eigen::Vector3d::Zero();
    Optional(scalp, ptr, "radii", VectorOf(3), &r);
    if (problems.size() != before) return;
    for (int k = 0; k < 3; ++k) {
      if (!(r[k] > 0.0))
        ValueProblem((*radii)[k], ptr + "/radii/" + std::to_string(k), "a finite number > 0");
    }
    out->radii = r;
  }

  // "strands": every strand a chain, all of one dimension (set into *dim).
  std::optional<std::vector<Points>> ParseStrands(const json& list, const std::string& ptr,
                                                  int* dim) {
    const std::string expected = "an array of at least 1 strand {\"points\": [[x, y, z], ...]}";
    if (!list.is_array()) {
      TypeProblem(list, ptr, expected);
      return std::nullopt;
    }
    if (list.empty()) {
      Add(ptr, "has 0 strands; expected " + expected, "[]", expected);
      return std::nullopt;
    }
    if (list.size() > size_t(kMaxGroomRoots)) {
      Add(ptr, "has " + std::to_string(list.size()) + " strands; expected at most " +
                   std::to_string(kMaxGroomRoots));
      return std::nullopt;
    }
    const size_t before = problems.size();
    std::vector<Points> strands;
    strands.reserve(list.size());
    int64_t total = 0;
    for (size_t i = 0; i < list.size(); ++i) {
      const std::string sp = ptr + "/" + std::to_string(i);
      if (!ExpectObject(list[i], sp, "an object {\"points\": [[x, y, z], ...]}")) continue;
      CheckKeys(list[i], sp, {"points", "masses"});
      const json* v = Required(list[i], sp, "points", "an array of at least 2 points");
      if (v == nullptr) continue;
      const auto points = PointList(*v, sp + "/points", *dim, 2, kMaxLinks + 1);
      if (!points) continue;
      // A dynamic strand's own masses: one per free point (points 1 to n).
      if (const json* m = Find(list[i], "masses")) {
        const Eigen::Index n = points->rows() - 1;
        if (auto masses = NumberList(*m, sp + "/masses", 1, Range::kPositive)) {
          if (masses->size() != n) {
            Add(sp + "/masses",
                "has " + std::to_string(masses->size()) + " numbers; expected " +
                    std::to_string(n) + ", one per free point (points 1 to " + std::to_string(n) +
                    " of the strand's " + std::to_string(n + 1) + ")",
                m->dump(), std::to_string(n) + " numbers > 0");
          } else {
            given_masses_.resize(list.size());
            given_masses_[i] = std::move(*masses);
          }
        }
      }
      if (*dim == 0) *dim = static_cast<int>(points->cols());
      try {
        ValidateChain(MakeChain(*points), "strand");
      } catch (const InputError& e) {
        Problem p = e.problem();
        std::string field = p.field;
        if (field.rfind("strand.", 0) == 0) field = field.substr(7);
        p.field = sp + MemberPathToPointer(field);
        problems.push_back(std::move(p));
        continue;
      }
      total += points->rows();
      strands.push_back(std::move(*points));
    }
    if (total > kMaxGroomPoints) {
      Add(ptr, "has " + std::to_string(total) + " points in all; expected at most " +
                   std::to_string(kMaxGroomPoints));
    }
    if (problems.size() != before) return std::nullopt;
    return strands;
  }

  // "motion"; dim 0: the scenario's dimension is not known (only what does not depend on it is
  // checked).
  std::optional<BodyMotion> ParseMotion(const json& motion, const std::string& ptr, int dim) {
    if (!ExpectObject(motion, ptr, "an object {\"fps\": 30, \"keyframes\": [...]}")) {
      return std::nullopt;
    }
    CheckKeys(motion, ptr, {"fps", "interpolation", "keyframes"});
    const size_t before = problems.size();
    BodyMotion m;
    Optional(motion, ptr, "fps", NumberOf(Range::kPositive), &m.fps);
    const bool fps_ok = problems.size() == before;
    if (auto keys = ReadKeyframes(motion, ptr, dim, "seconds", kMaxGroomKeyframes)) {
      m.keyframes = std::move(keys->first);
      m.interpolation = keys->second;
    }
    if (problems.size() != before) return std::nullopt;
    if (fps_ok) {
      const double duration = m.keyframes.back().time - m.keyframes.front().time;
      const double frames = std::floor(duration * m.fps + 1e-9) + 1.0;
      if (!(frames <= double(kMaxGroomFrames))) {
        Add(ptr + "/fps",
            "value " + FormatNumber(m.fps) + " over the keyframes' " + FormatNumber(duration) +
                " s makes " + FormatNumber(frames) + " frames; expected at most " +
                std::to_string(kMaxGroomFrames) + " frames",
            FormatNumber(m.fps),
            "at most " + std::to_string(kMaxGroomFrames) + " frames over the motion");
        return std::nullopt;
      }
    }
    return m;
  }

  // "method", "substeps", "pinned", "threads" and "record".
  void ParseOptions(const json& root, GroomScenario* s) {
    StrandOptions& o = s->options;
    o.threads = 0;  // all cores, unless the file says otherwise
    const size_t before = problems.size();
    if (const json* v = Find(root, "method")) {
      if (const auto name = String(*v, "/method")) {
        try {
          o.method = ParseStrandMethod(*name, "/method");
        } catch (const InputError& e) {
          problems.push_back(e.problem());
        }
      }
    }
    const auto integer = [this](int64_t min, int64_t max) {
      return [this, min, max](const json& v, const std::string& p) { return Int(v, p, min, max); };
    };
    Optional(root, "", "substeps", integer(1, 1000000), &o.substeps);
    Optional(root, "", "pinned", integer(1, kMaxLinks + 1), &o.pinned);
    Optional(root, "", "threads", integer(0, 1024), &o.threads);
    if (const json* record = Find(root, "record")) {
      if (ExpectObject(*record, "/record",
                       "an object {\"every\": e, \"precision\": \"float32\"}")) {
        CheckKeys(*record, "/record", {"every", "precision"});
        Optional(*record, "/record", "every", integer(1, kMaxGroomFrames), &s->record_every);
        if (const json* p = Find(*record, "precision")) {
          // As --precision and Python's precision= are read: ParseName, the same message.
          if (const auto name = String(*p, "/record/precision")) {
            try {
              s->float32 = ParseName<StrandPrecision>(*name, "/record/precision") ==
                           StrandPrecision::kFloat32;
            } catch (const InputError& e) {
              problems.push_back(e.problem());
            }
          }
        }
      }
    }
    if (problems.size() != before) return;
    for (Problem p : o.Validate()) {
      p.field = MemberPathToPointer(p.field);
      problems.push_back(std::move(p));
    }
  }

  bool grow_;
  std::vector<Eigen::VectorXd> given_masses_;  // "/strands/i/masses" (empty: none given)

 public:
  std::string directory;  // of mesh colliders' relative files ("": the working directory)
};

GroomScenario ParseGroomJson(const json& root) {
  GroomParser parser(/*grow=*/true);
  GroomScenario scenario = parser.Parse(root);
  ThrowIfAny(parser.problems);
  return scenario;
}

}  // namespace

namespace internal {
GroomScenario ReadGroomScenario(const json& root, Problems* problems,
                                const std::string& directory) {
  GroomParser parser(/*grow=*/true);
  parser.directory = directory;
  GroomScenario scenario = parser.Parse(root);
  for (Problem& p : parser.problems) problems->push_back(std::move(p));
  return scenario;
}
}  // namespace internal

GroomScenario ParseGroomText(const std::string& json_text) {
  return ParseGroomJson(ParseJsonText(json_text));
}

GroomScenario LoadGroomFile(const std::string& path) { return ParseGroomJson(ReadJsonFile(path)); }

Problems ValidateGroomText(const std::string& json_text) {
  json root;
  try {
    root = ParseJsonText(json_text);
  } catch (const InputError& e) {
    return {e.problem()};
  }
  GroomParser parser(/*grow=*/false);
  parser.Parse(root);
  return std::move(parser.problems);
}

Problems ValidateGroomFile(const std::string& path) {
  return ValidateGroomText(ReadTextFile(path));
}

void ApplyGroomOverrides(const GroomOverrides& overrides, bool command_line,
                         GroomScenario* scenario) {
  // "--record-every" on the command line, "record_every" in Python.
  const auto name = [command_line](std::string field) {
    if (!command_line) return field;
    std::replace(field.begin(), field.end(), '_', '-');
    return "--" + field;
  };
  StrandOptions& o = scenario->options;
  if (overrides.method) {
    if (o.dynamics) {
      throw InputError(name("method"),
                       "is not used by dynamic strands (the scenario has \"dynamics\"): they "
                       "are moved by inertia and the projection; give " +
                           name("projection") + " instead");
    }
    o.method = ParseStrandMethod(*overrides.method, name("method"));
  }
  if (overrides.projection) {
    if (!o.dynamics) {
      throw InputError(name("projection"),
                       "is for dynamic strands; the scenario has no \"dynamics\" (its strands "
                       "are kinematic: " +
                           name("method") + " chooses their link rule)");
    }
    o.dynamics->projection = ParseName<Projection>(*overrides.projection, name("projection"));
  }
  if (overrides.substeps) {
    o.substeps = *overrides.substeps;
    if (o.dynamics) o.dynamics->substeps = o.substeps;
  }
  if (overrides.pinned) o.pinned = *overrides.pinned;
  if (overrides.threads) o.threads = *overrides.threads;
  if (overrides.record_every) {
    const int64_t every = *overrides.record_every;
    if (every < 1 || every > kMaxGroomFrames) {
      throw InputError(Problem::Invalid(
          name("record_every"), std::to_string(every),
          every < 1 ? "an integer >= 1" : "at most " + std::to_string(kMaxGroomFrames)));
    }
    scenario->record_every = static_cast<int>(*overrides.record_every);
  }
  if (overrides.precision) {
    scenario->float32 = ParseName<StrandPrecision>(*overrides.precision, name("precision")) ==
                        StrandPrecision::kFloat32;
  }
  const Problems problems = o.Validate();
  if (!problems.empty()) {
    Problem p = problems.front();
    p.field = name(p.field);
    throw InputError(p);
  }
}

bool IsGroomText(const std::string& json_text) {
  return ScenarioKindOfText(json_text) == ScenarioKind::kGroom;
}

bool IsGroomFile(const std::string& path) {
  try {
    return IsGroomText(ReadTextFile(path));
  } catch (const std::exception&) {
    return false;
  }
}

std::string GroomSummary(const GroomScenario& s) {
  const size_t count = s.strands.size();
  int min_links = 0, max_links = 0;
  int64_t points = 0;
  double total_length = 0.0;
  for (size_t i = 0; i < count; ++i) {
    const int n = static_cast<int>(s.strands[i].rows()) - 1;
    min_links = i == 0 ? n : std::min(min_links, n);
    max_links = i == 0 ? n : std::max(max_links, n);
    points += s.strands[i].rows();
    for (int j = 0; j < n; ++j) {
      total_length += (s.strands[i].row(j + 1) - s.strands[i].row(j)).norm();
    }
  }
  char mean[40], radius[80], seconds[40], fps[40];
  std::snprintf(mean, sizeof mean, "%.3g", count > 0 ? total_length / double(count) : 0.0);
  const std::string links = min_links == max_links
                                ? std::to_string(min_links)
                                : std::to_string(min_links) + " to " + std::to_string(max_links);
  std::string out = std::to_string(s.dim) + "D, " + std::to_string(count) +
                    (count == 1 ? " strand of " : " strands of ") + links +
                    (max_links == 1 ? " link" : " links") + " (" + std::to_string(points) +
                    " points, mean length " + mean;
  if (s.scalp.shape == "sphere") {
    std::snprintf(radius, sizeof radius, ", on a sphere of radius %.3g", s.scalp.radii[0]);
    out += radius;
  } else if (s.scalp.shape == "ellipsoid") {
    std::snprintf(radius, sizeof radius, ", on an ellipsoid of radii %.3g, %.3g, %.3g",
                  s.scalp.radii[0], s.scalp.radii[1], s.scalp.radii[2]);
    out += radius;
  }
  const int64_t frames = s.motion.num_frames();
  const double duration = s.motion.keyframes.empty()
                              ? 0.0
                              : s.motion.keyframes.back().time - s.motion.keyframes[0].time;
  std::snprintf(seconds, sizeof seconds, "%.4g", duration);
  std::snprintf(fps, sizeof fps, "%.4g", s.motion.fps);
  const size_t keys = s.motion.keyframes.size();
  out += std::string("), ") + std::to_string(frames) + (frames == 1 ? " frame" : " frames") +
         " at " + fps + " fps (" + seconds + " s, " + std::to_string(keys) +
         (keys == 1 ? " keyframe, " : " keyframes, ") +
         (s.motion.interpolation == KeyframeInterpolation::kLinear ? "linear" : "smooth") + "), " +
         (s.options.dynamics
              ? std::string("dynamic, projection ") + ProjectionName(s.options.dynamics->projection)
              : std::string("method ") + MethodName(s.options.method)) +
         ", " + std::to_string(s.options.substeps) +
         (s.options.substeps == 1 ? " sub-step" : " sub-steps");
  if (s.options.dynamics) {
    const DynamicOptions& d = *s.options.dynamics;
    char text[40];
    out += ", gravity [";
    for (Eigen::Index k = 0; k < d.gravity.size(); ++k) {
      std::snprintf(text, sizeof text, k == 0 ? "%.4g" : ", %.4g", d.gravity[k]);
      out += text;
    }
    std::snprintf(text, sizeof text, "], damping %.4g /s", d.damping);
    out += text;
  }
  if (s.options.pinned != 1) out += ", " + std::to_string(s.options.pinned) + " pinned points";
  // Frames 0, e, 2e, ... and the last: as a chain run records its leader steps.
  const int64_t recorded = frames == 0 ? 0 : CountRecordedFrames(frames - 1, s.record_every);
  out += ", recording " + std::to_string(recorded) + (recorded == 1 ? " frame" : " frames");
  if (s.record_every != 1) out += " (every " + std::to_string(s.record_every) + ")";
  out += s.float32 ? " as float32" : " as float64";
  return out;
}

}  // namespace flexkin
