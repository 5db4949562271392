// The scenario parser's sections: the curve, the leader's motion and the run options.

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "flexkin/curves.h"
#include "flexkin/error.h"
#include "flexkin/leader.h"
#include "flexkin/propagate.h"
#include "io/scenario_parser.h"

namespace flexkin::scenario_internal {

std::optional<Chain> Parser::ParseCurve(const json& v, const std::string& ptr) {
  const std::string expected =
      "an object: {\"points\": [[x, y], ...]} or {\"shape\": \"line\"|\"parabola\"|\"arc\"|"
      "\"helix\", ...}";
  if (!ExpectObject(v, ptr, expected)) return std::nullopt;
  const bool has_points = v.contains("points"), has_shape = v.contains("shape");
  if (has_points == has_shape) {
    Add(ptr, std::string(has_points ? "has both \"points\" and \"shape\""
                                    : "has neither \"points\" nor \"shape\"") +
                 "; expected " + expected);
    return std::nullopt;
  }
  if (has_shape) return ParseShape(v, ptr);
  CheckKeys(v, ptr, {"points"});
  const auto points = PointList(v["points"], ptr + "/points", 0, 2);
  if (!points) return std::nullopt;
  bool ok = true;
  for (Eigen::Index i = 1; i < points->rows(); ++i) {
    if (points->row(i) == points->row(i - 1)) {
      Add(ptr + "/points/" + std::to_string(i),
          "value " + ShowJson(v["points"][i]) + " equals point " + std::to_string(i - 1) +
              ", so link " + std::to_string(i) +
              " would have zero length; consecutive points must differ");
      ok = false;
    }
  }
  if (!ok) return std::nullopt;
  try {
    return MakeChain(*points);
  } catch (const InputError& e) {  // e.g. a link too long to represent
    Add(ptr + "/points", e.what());
    return std::nullopt;
  }
}

std::optional<Chain> Parser::ParseShape(const json& v, const std::string& ptr) {
  const std::vector<std::string> shapes = {"line", "parabola", "arc", "helix"};
  const auto shape = Choice(v["shape"], ptr + "/shape", shapes);
  if (!shape) return std::nullopt;
  std::vector<std::string> keys = {"shape", "links", "link_length"};
  if (*shape == "line") keys.insert(keys.end(), {"start", "direction"});
  if (*shape == "parabola") keys.insert(keys.end(), {"a", "side"});
  if (*shape == "arc") keys.insert(keys.end(), {"radius", "center", "start_angle", "turn"});
  if (*shape == "helix") {
    keys.insert(keys.end(), {"radius", "pitch", "center", "start_angle", "turn"});
  }
  CheckKeys(v, ptr, keys);

  const size_t before = problems.size();
  const auto integer_links = [this](const json& x, const std::string& p) {
    const auto n = Integer(x, p, 1, kMaxGeneratedLinks);
    return n ? std::optional<int>(static_cast<int>(*n)) : std::nullopt;
  };
  const auto positive = [this](const json& x, const std::string& p) {
    return Number(x, p, Range::kPositive);
  };
  const auto any = [this](const json& x, const std::string& p) {
    return Number(x, p, Range::kAny);
  };
  const auto vector_of = [this](int dim) {
    return [this, dim](const json& x, const std::string& p) { return Vector(x, p, dim); };
  };
  const auto clockwise = [this](const json& x, const std::string& p) {
    const auto turn = Choice(x, p, NamesOf<CurveTurn>());
    return turn ? std::optional<bool>(*turn == NameOf(CurveTurn::kCw)) : std::nullopt;
  };
  const auto side = [this](const json& x, const std::string& p) {
    const auto name = Choice(x, p, NamesOf<CurveSide>());
    return name ? std::optional<int>(*name == NameOf(CurveSide::kPlusX) ? 1 : -1) : std::nullopt;
  };
  int links = 1;
  double link_length = 1.0;
  Require(v, ptr, "links", "an integer >= 1 (the number of links)", integer_links, &links);
  Require(v, ptr, "link_length", "a finite number > 0 (the length of every link)", positive,
          &link_length);

  std::optional<Points> points;
  if (*shape == "line") {
    LineDef def;
    Optional(v, ptr, "start", vector_of(0), &def.start);
    // "direction" must match a valid "start"; without one it sets the dimension itself.
    const bool has_start = v.contains("start") && problems.size() == before;
    const int dim = has_start ? static_cast<int>(def.start.size()) : 0;
    def.direction = Eigen::VectorXd::Unit(has_start ? dim : 2, 0);
    Optional(v, ptr, "direction", vector_of(dim), &def.direction);
    if (!v.contains("start")) def.start = Eigen::VectorXd::Zero(def.direction.size());
    points = Generate(def, links, link_length, MakeLine, ptr, before);
  } else if (*shape == "parabola") {
    ParabolaDef def;
    Require(v, ptr, "a", "a finite number (y = a x^2)", any, &def.a);
    Optional(v, ptr, "side", side, &def.side);
    points = Generate(def, links, link_length, MakeParabola, ptr, before);
  } else if (*shape == "arc") {
    ArcDef def;
    Require(v, ptr, "radius", "a finite number > 0", positive, &def.radius);
    Optional(v, ptr, "center", vector_of(2), &def.center);
    Optional(v, ptr, "start_angle", any, &def.start_angle);
    Optional(v, ptr, "turn", clockwise, &def.clockwise);
    points = Generate(def, links, link_length, MakeArc, ptr, before);
  } else {
    HelixDef def;
    Require(v, ptr, "radius", "a finite number > 0", positive, &def.radius);
    Require(v, ptr, "pitch", "a finite number (rise along z per turn)", any, &def.pitch);
    Optional(v, ptr, "center", vector_of(3), &def.center);
    Optional(v, ptr, "start_angle", any, &def.start_angle);
    Optional(v, ptr, "turn", clockwise, &def.clockwise);
    points = Generate(def, links, link_length, MakeHelix, ptr, before);
  }
  if (!points) return std::nullopt;
  try {
    return MakeEqualLinkChain(*points, link_length);
  } catch (const InputError& e) {
    Add(ptr, e.what());
    return std::nullopt;
  }
}

std::optional<Points> Parser::ParseLeader(const json& v, const std::string& ptr, const Chain* chain,
                                          RunOptions* options) {
  const std::string expected =
      "an object: {\"path\": [[x, y], ...]}, {\"path\": [...], \"max_step\": s} or "
      "{\"pull\": [dx, dy], \"steps\": n}";
  if (!ExpectObject(v, ptr, expected)) return std::nullopt;
  CheckKeys(v, ptr, {"path", "pull", "steps", "max_step", "closed", "substeps"});
  if (const json* s = Find(v, "substeps")) {
    if (const auto n = Integer(*s, ptr + "/substeps", 1, kMaxCount)) {
      options->substeps = static_cast<int>(*n);
    }
  }
  const bool has_path = v.contains("path"), has_pull = v.contains("pull");
  if (has_path == has_pull) {
    Add(ptr, std::string(has_path ? "has both \"path\" and \"pull\""
                                  : "has neither \"path\" nor \"pull\"") +
                 "; expected " + expected);
    return std::nullopt;
  }
  const int dim = chain != nullptr ? chain->dim() : 0;
  const size_t before = problems.size();
  Points steps;
  if (has_pull) {
    if (v.contains("max_step")) {
      Add(ptr + "/max_step", "is only valid with \"path\"; use \"steps\" to split a \"pull\"");
    }
    if (v.contains("closed")) {
      Add(ptr + "/closed",
          "is only valid with \"path\"; give the way back as a \"path\" ending at the start");
    }
    int64_t count = 1;
    if (const json* s = Find(v, "steps")) {
      if (const auto n = Integer(*s, ptr + "/steps", 1, kMaxLeaderSteps)) count = *n;
    }
    const auto pull = Vector(v["pull"], ptr + "/pull", dim);
    if (problems.size() != before || chain == nullptr) return std::nullopt;
    steps = SplitPull(chain->points.row(0).transpose(), *pull, count);
  } else {
    if (v.contains("steps")) {
      Add(ptr + "/steps", "is only valid with \"pull\"; use \"max_step\" to resample a \"path\"");
    }
    std::optional<double> max_step;
    if (const json* s = Find(v, "max_step")) {
      max_step = Number(*s, ptr + "/max_step", Range::kPositive);
    }
    bool closed = false;
    if (const json* c = Find(v, "closed")) {
      if (c->is_boolean()) {
        closed = c->get<bool>();
      } else {
        TypeProblem(*c, ptr + "/closed", "true or false");
      }
    }
    auto path = PointList(v["path"], ptr + "/path", dim, 1);
    if (problems.size() != before || chain == nullptr) return std::nullopt;
    if (closed) {  // back to the start, exactly, as the last target
      const Points open = std::move(*path);
      path.emplace(open.rows() + 1, open.cols());
      path->topRows(open.rows()) = open;
      path->bottomRows(1) = chain->points.row(0);
    }
    if (!max_step) return path;
    try {
      steps = ResamplePath(chain->points.row(0).transpose(), *path, *max_step);
    } catch (const InputError& e) {  // too many steps
      Problem p = e.problem();
      p.field = ptr + FieldToPointer(p.field);
      problems.push_back(std::move(p));
      return std::nullopt;
    }
    if (steps.rows() == 0) {
      Add(ptr + "/path", "every target equals the start " +
                             ShowJson(json(std::vector<double>(
                                 chain->points.row(0).data(), chain->points.row(0).data() + dim))) +
                             ", so there is no leader step; expected a path that moves");
      return std::nullopt;
    }
  }
  return steps;
}

void Parser::ParseOptions(const json& root, RunOptions* options) {
  if (const json* m = Find(root, "method")) {
    if (const auto name = String(*m, "/method")) {
      if (const NamedValue<Method>* entry = FindName<Method>(*name)) {
        options->method = entry->value;
      } else {
        problems.push_back(
            UnknownName("/method", Vocabulary<Method>::kKind, *name, NamesOf<Method>()));
      }
    }
  }
  // The overall method's metric and solver.
  for (const char* key : {"objective", "solver"}) {
    if (Find(root, key) != nullptr && options->method != Method::kOverall) {
      Add(std::string("/") + key, std::string("is used only with \"method\": \"overall\"; ") +
                                      "remove it or set the method to \"overall\"");
    }
  }
  if (const json* o = Find(root, "objective")) {
    if (ExpectObject(*o, "/objective",
                     "an object of term weights, e.g. {\"squared\": 1, \"rotation\": 0.5}")) {
      ObjectiveWeights& w = options->overall.weights;
      CheckKeys(*o, "/objective", NamesOf<ObjectiveTerm>());
      // Only the terms listed count: {"rotation": 1} is the rotation metric alone.
      for (const auto& [term, name, summary] : Vocabulary<ObjectiveTerm>::kEntries) {
        w[term] = 0.0;
        Optional(
            *o, "/objective", name,
            [&](const json& v, const std::string& p) { return Number(v, p, Range::kNonNegative); },
            &w[term]);
      }
    }
  }
  if (const json* v = Find(root, "solver")) {
    if (ExpectObject(*v, "/solver",
                     "an object {\"max_iterations\": n, \"constraint_tolerance\": t, "
                     "\"optimality_tolerance\": t}")) {
      CheckKeys(*v, "/solver", {"max_iterations", "constraint_tolerance", "optimality_tolerance"});
      OverallOptions& o = options->overall;
      Optional(
          *v, "/solver", "constraint_tolerance",
          [&](const json& x, const std::string& p) { return Number(x, p, Range::kPositive); },
          &o.constraint_tolerance);
      Optional(
          *v, "/solver", "optimality_tolerance",
          [&](const json& x, const std::string& p) { return Number(x, p, Range::kPositive); },
          &o.optimality_tolerance);
      if (const json* m = Find(*v, "max_iterations")) {
        if (const auto n = Integer(*m, "/solver/max_iterations", 1, 1000000)) {
          o.max_iterations = static_cast<int>(*n);
        }
      }
    }
  }
  if (const json* r = Find(root, "record")) {
    if (ExpectObject(*r, "/record", "an object {\"every\": n, \"link_angles\": true|false}")) {
      CheckKeys(*r, "/record", {"every", "link_angles"});
      if (const json* e = Find(*r, "every")) {
        if (const auto n = Integer(*e, "/record/every", 1, kMaxCount)) {
          options->record_every = static_cast<int>(*n);
        }
      }
      if (const json* a = Find(*r, "link_angles")) {
        if (a->is_boolean()) {
          options->link_angles = a->get<bool>();
        } else {
          TypeProblem(*a, "/record/link_angles", "true or false");
        }
      }
    }
  }
  if (const json* a = Find(root, "accuracy")) {
    if (ExpectObject(*a, "/accuracy", "an object {\"tolerance\": t, \"max_substeps\": n}")) {
      CheckKeys(*a, "/accuracy", {"tolerance", "max_substeps"});
      if (const json* t = Find(*a, "tolerance")) {
        if (const auto x = Number(*t, "/accuracy/tolerance", Range::kNonNegative)) {
          options->tolerance = *x;
        }
      }
      if (const json* m = Find(*a, "max_substeps")) {
        if (const auto n = Integer(*m, "/accuracy/max_substeps", 1, kMaxCount)) {
          options->max_substeps = static_cast<int>(*n);
        }
      }
    }
  }
}

}  // namespace flexkin::scenario_internal
