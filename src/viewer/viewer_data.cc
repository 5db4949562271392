#include "viewer_data.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/propagate.h"
#include "io/collider_mesh.h"
#include "io/colliders_json.h"

namespace flexkin::viewer_internal {

void CheckResult(const ResultFile& file, const ViewerOptions& options) {
  ThrowIfAny(ValidateResult(file));
  const Eigen::Index n = file.result.lengths.size();
  for (size_t i = 0; i < options.trail_points.size(); ++i) {
    if (options.trail_points[i] > n) {
      throw InputError("trail_points[" + std::to_string(i) + "]",
                       std::to_string(options.trail_points[i]) + " is not valid; the result has " +
                           "points 0 to " + std::to_string(n));
    }
  }
}

namespace {

// Appends `x` with `digits` significant digits (JSON number syntax; x is finite).
void AppendNumber(double x, int digits, std::string* out) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, x);
  out->append(buffer);
}

// Appends `x` so that it reads back exactly, in the fewest of 15 or 17 digits.
void AppendExact(double x, std::string* out) { out->append(FormatNumber(x)); }

void AppendString(const std::string& s, std::string* out) {
  out->push_back('"');
  for (const char c : s) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out->push_back('\\');
      out->push_back(c);
    } else if (u < 0x20 || c == '<' || c == '>' || c == '&') {
      char buffer[8];
      std::snprintf(buffer, sizeof buffer, "\\u%04x", u);
      out->append(buffer);
    } else {
      out->push_back(c);
    }
  }
  out->push_back('"');
}

void AppendKey(const char* key, std::string* out) {
  if (out->back() != '{') out->push_back(',');
  AppendString(key, out);
  out->push_back(':');
}

void AppendExactArray(const Eigen::VectorXd& v, std::string* out) {
  out->push_back('[');
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (i > 0) out->push_back(',');
    AppendExact(v[i], out);
  }
  out->push_back(']');
}

// Largest |(|x_b - x_a| - L_k)| / L_k of one frame over its links k (from point a[k] to b[k]:
// a chain's from k to k + 1, a tree's from a point's parent to it), from the unrounded
// coordinates. Links that slide (`sliding`, per link, if given: a robot tree's prismatic joints)
// are left out.
double FrameLengthError(const Points& p, const Eigen::VectorXd& lengths, const std::vector<int>& a,
                        const std::vector<int>& b, const std::vector<char>& sliding = {}) {
  double worst = 0.0;
  for (size_t k = 0; k < a.size(); ++k) {
    if (k < sliding.size() && sliding[k]) continue;
    const double d = (p.row(b[k]) - p.row(a[k])).norm();
    worst = std::max(worst, std::abs(d - lengths[k]) / lengths[k]);
  }
  return worst;
}

void AppendInts(const std::vector<int>& v, std::string* out) {
  out->push_back('[');
  for (size_t i = 0; i < v.size(); ++i) {
    if (i > 0) out->push_back(',');
    *out += std::to_string(v[i]);
  }
  out->push_back(']');
}

// The colliders: each in its scenario form (io/colliders_json.h) with "bounds" (the box the view
// must hold: lo then hi, 3 numbers each; a half-space's is its boundary's point nearest the
// motion) and "points", what the page fills the convex hull of once projected: in 2D the outline
// of the collider, in 3D points of its surface. A half-space is cut to the cube about the scene
// 1.2 times its largest extent across: in front of the perspective camera (viewer.js, 3 radii of
// the scene away).
void AppendColliders(const ResultFile& file, int digits, std::string* out) {
  Eigen::Vector3d lo, hi;
  BoundsOfMotion(file, &lo, &hi);
  const Eigen::Vector3d center = 0.5 * (lo + hi);
  const size_t num_frames = file.result.frames.size();
  for (const Collider& c : file.colliders) {
    ExtendByColliderOverFrames(c, file, file.dim, center, &lo, &hi);
  }
  const double half = 0.6 * std::max((hi - lo).maxCoeff(), 1e-3 * file.result.lengths.sum());
  const Eigen::Vector3d mid = 0.5 * (lo + hi);
  Eigen::Vector3d big_lo = mid - Eigen::Vector3d::Constant(half);
  Eigen::Vector3d big_hi = mid + Eigen::Vector3d::Constant(half);
  if (file.dim == 2) big_lo.z() = big_hi.z() = 0.0;
  const auto numbers = [&](const auto& values) {
    out->push_back('[');
    for (size_t i = 0; i < values.size(); ++i) {
      if (i > 0) out->push_back(',');
      AppendNumber(values[i], digits, out);
    }
    out->push_back(']');
  };
  AppendKey("colliders", out);
  out->push_back('[');
  for (size_t k = 0; k < file.colliders.size(); ++k) {
    const Collider& given = file.colliders[k];
    if (k > 0) out->push_back(',');
    AppendColliderJson(given, file.dim, out);
    out->pop_back();  // its '}': the page's keys follow
    // A keyframed collider's points are where it is at frame 0; "moves" carries them to each
    // frame: 12 numbers a frame, the rotation (row by row) and the translation of
    // M(t_f) M(t_0)^-1, M(t) its motion's pose at time t (frame f's step).
    const Collider c = given.motion && num_frames > 0
                           ? ColliderAt(given, double(file.result.frames[0].step))
                           : given;
    if (given.motion) {
      std::vector<double> moves;
      moves.reserve(12 * num_frames);
      for (const Eigen::Isometry3d& t : MovesFromFirstFrame(given, file)) {
        for (int i = 0; i < 3; ++i) {
          for (int j = 0; j < 3; ++j) moves.push_back(t.linear()(i, j));
        }
        for (int i = 0; i < 3; ++i) moves.push_back(t.translation()[i]);
      }
      out->append(",\"moves\":");
      numbers(moves);
    }
    Eigen::Vector3d c_lo = Eigen::Vector3d::Constant(HUGE_VAL), c_hi = -c_lo;
    ExtendByColliderOverFrames(given, file, 3, center, &c_lo, &c_hi);
    if (file.dim == 2) c_lo.z() = c_hi.z() = 0.0;
    out->append(",\"bounds\":");
    numbers(std::vector<double>{c_lo.x(), c_lo.y(), c_lo.z(), c_hi.x(), c_hi.y(), c_hi.z()});
    std::vector<double> points;
    if (file.dim == 2) {
      for (const Eigen::Vector2d& p :
           OutlineOfCollider2d(c, 64, big_lo.head<2>(), big_hi.head<2>())) {
        points.insert(points.end(), {p.x(), p.y()});
      }
    } else {
      const std::vector<Eigen::Vector3d> surface =
          c.shape == ColliderShape::kHalfSpace ? HalfSpacePlaneInBox(c, big_lo, big_hi)
                                               : MeshOfCollider(c, 32, center, 0.0).vertices;
      for (const Eigen::Vector3d& p : surface) points.insert(points.end(), {p.x(), p.y(), p.z()});
    }
    out->append(",\"points\":");
    numbers(points);
    out->push_back('}');
  }
  out->push_back(']');
}

}  // namespace

std::vector<int> TreeLinkPoints(const TreeResultFile& tree) {
  std::vector<int> points;
  for (size_t i = 0; i < tree.parents.size(); ++i) {
    if (tree.parents[i] >= 0) points.push_back(static_cast<int>(i));
  }
  return points;
}

std::vector<char> TreeSlidingLinks(const TreeResultFile& tree) {
  std::vector<char> slides(tree.parents.size(), 0);
  for (const int i : tree.sliding) slides[i] = 1;
  std::vector<char> links;
  for (const int i : TreeLinkPoints(tree)) links.push_back(slides[i]);
  return links;
}

ResultFile TreeAsViewerResult(const TreeResultFile& tree) {
  ResultFile file;
  file.dim = tree.dim;
  file.scenario_name = tree.name;
  RunResult& r = file.result;
  r.method = tree.method;
  const std::vector<int> ends = TreeLinkPoints(tree);
  const std::vector<char> sliding = TreeSlidingLinks(tree);
  std::vector<int> starts;
  for (const int i : ends) starts.push_back(tree.parents[i]);
  const Points& first = tree.frames.front();
  r.lengths.resize(static_cast<Eigen::Index>(ends.size()));
  for (size_t k = 0; k < ends.size(); ++k) {
    r.lengths[k] = (first.row(ends[k]) - first.row(tree.parents[ends[k]])).norm();
    if (sliding[k]) {
      for (const Points& p : tree.frames) {
        r.lengths[k] =
            std::max(r.lengths[k], (p.row(ends[k]) - p.row(tree.parents[ends[k]])).norm());
      }
      r.lengths[k] = std::max(r.lengths[k], std::numeric_limits<double>::min());
    }
  }
  const size_t frames = tree.frames.size();
  r.num_steps = static_cast<int64_t>(frames) - 1;
  Metrics& m = r.metrics;
  m.path_length = Eigen::VectorXd::Zero(first.rows());
  m.l2_per_step = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(frames - 1));
  m.l2_weighted_per_step = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(frames - 1));
  for (size_t f = 0; f < frames; ++f) {
    r.frames.Add(static_cast<int64_t>(f), tree.frames[f]);
    m.max_relative_length_error =
        std::max(m.max_relative_length_error,
                 FrameLengthError(tree.frames[f], r.lengths, starts, ends, sliding));
    if (f == 0) continue;
    const Eigen::VectorXd moved = (tree.frames[f] - tree.frames[f - 1]).rowwise().norm();
    m.path_length += moved;
    m.l2_per_step[f - 1] = moved.sum();
  }
  m.l2_total = m.l2_per_step.sum();
  return file;
}

std::string ViewerDataJson(const ResultFile& file, const ViewerOptions& options,
                           const RobotTrajectoryFile* robot, const TreeResultFile* tree) {
  const RunResult& r = file.result;
  const size_t num_frames = r.frames.size();
  std::string out = "{";
  out.reserve(num_frames * r.frames[0].points.size() * (options.digits + 8) + 4096);

  AppendKey("title", &out);
  AppendString(!options.title.empty()        ? options.title
               : !file.scenario_name.empty() ? file.scenario_name
                                             : std::string("flexkin result"),
               &out);
  AppendKey("scenario", &out);
  AppendString(file.scenario_name, &out);
  AppendKey("method", &out);
  AppendString(robot != nullptr ? robot->method
               : tree != nullptr && tree->robot
                   ? "joint-space Gauss-Newton (" + std::to_string(tree->joints.size()) + " joints)"
                   : std::string(MethodName(r.method)),
               &out);
  if (robot != nullptr) {
    AppendKey("robot", &out);
    out.push_back('{');
    AppendKey("links", &out);
    out += std::to_string(robot->link_lengths.size());
    AppendKey("targets", &out);
    out += std::to_string(robot->targets.rows());
    AppendKey("unreached", &out);
    out += std::to_string(robot->unreached);
    AppendKey("max_ee_error", &out);
    AppendExact(robot->max_ee_error, &out);
    out.push_back('}');
  }
  // Link k from point a[k] to point b[k].
  std::vector<int> link_a, link_b;
  std::vector<char> sliding;  // per link: it slides (a robot tree's prismatic joint)
  if (tree != nullptr) {
    link_b = TreeLinkPoints(*tree);
    sliding = TreeSlidingLinks(*tree);
    for (const int c : link_b) link_a.push_back(tree->parents[c]);
    AppendKey("tree", &out);
    out.push_back('{');
    AppendKey("parents", &out);
    AppendInts(tree->parents, &out);
    AppendKey("link_points", &out);
    AppendInts(link_b, &out);
    AppendKey("targets", &out);
    AppendInts(tree->targets, &out);
    AppendKey("fixed", &out);
    AppendInts(tree->fixed, &out);
    AppendKey("not_reached", &out);
    out += std::to_string(std::count(tree->reached.begin(), tree->reached.end(), char(0)));
    // The pointing goals: each one's target index and the points it looked at, frames 1 to F-1
    // (dim numbers a frame).
    AppendKey("looks", &out);
    out.push_back('[');
    bool first_look = true;
    for (size_t k = 0; k < tree->looks.size() && !tree->goals.empty(); ++k) {
      if (!tree->looks[k]) continue;
      if (!first_look) out.push_back(',');
      first_look = false;
      out += "{\"target\":" + std::to_string(k) + ",\"goals\":[";
      for (size_t f = 0; f < tree->goals.size(); ++f) {
        for (Eigen::Index c = 0; c < tree->goals[f].cols(); ++c) {
          if (f > 0 || c > 0) out.push_back(',');
          AppendNumber(tree->goals[f](static_cast<Eigen::Index>(k), c), options.digits, &out);
        }
      }
      out += "]}";
    }
    out.push_back(']');
    out.push_back('}');
  } else {
    for (Eigen::Index k = 0; k < r.lengths.size(); ++k) {
      link_a.push_back(static_cast<int>(k));
      link_b.push_back(static_cast<int>(k + 1));
    }
  }
  AppendKey("dim", &out);
  out += std::to_string(file.dim);
  AppendKey("num_links", &out);
  out += std::to_string(r.lengths.size());
  AppendKey("num_steps", &out);
  out += std::to_string(r.num_steps);
  AppendKey("substeps", &out);
  out += std::to_string(r.accuracy.substeps);
  AppendKey("seconds", &out);
  AppendExact(r.seconds, &out);
  AppendKey("link_lengths", &out);
  AppendExactArray(r.lengths, &out);

  // Per frame: the leader step, then the largest relative link-length error.
  AppendKey("steps", &out);
  out.push_back('[');
  for (size_t f = 0; f < num_frames; ++f) {
    if (f > 0) out.push_back(',');
    out += std::to_string(r.frames[f].step);
  }
  out.push_back(']');
  AppendKey("frame_length_error", &out);
  out.push_back('[');
  for (size_t f = 0; f < num_frames; ++f) {
    if (f > 0) out.push_back(',');
    AppendNumber(FrameLengthError(r.frames[f].points, r.lengths, link_a, link_b, sliding), 3, &out);
  }
  out.push_back(']');
  // Frame after frame, point after point (leading end first), coordinate after coordinate.
  AppendKey("positions", &out);
  out.push_back('[');
  bool first = true;
  for (const Frame& frame : r.frames) {
    const Points& p = frame.points;
    for (Eigen::Index i = 0; i < p.size(); ++i) {
      if (!first) out.push_back(',');
      first = false;
      AppendNumber(p.data()[i], options.digits, &out);  // row-major: point after point
    }
  }
  out.push_back(']');
  // The links' capsules, one radius per link (link i from point i to point i + 1), if any.
  if (file.link_radii.size() > 0) {
    AppendKey("link_radii", &out);
    out.push_back('[');
    for (Eigen::Index i = 0; i < file.link_radii.size(); ++i) {
      if (i > 0) out.push_back(',');
      AppendNumber(file.link_radii[i], options.digits, &out);
    }
    out.push_back(']');
  }
  if (!file.colliders.empty()) AppendColliders(file, options.digits, &out);

  const Metrics& m = r.metrics;
  AppendKey("metrics", &out);
  out.push_back('{');
  AppendKey("l2_total", &out);
  AppendExact(m.l2_total, &out);
  AppendKey("l2_weighted_total", &out);
  AppendExact(m.l2_weighted_total, &out);
  AppendKey("max_relative_length_error", &out);
  AppendExact(m.max_relative_length_error, &out);
  AppendKey("path_length", &out);
  AppendExactArray(m.path_length, &out);
  AppendKey("l2_per_step", &out);
  AppendExactArray(m.l2_per_step, &out);
  out.push_back('}');

  const AccuracyReport& a = r.accuracy;
  AppendKey("accuracy", &out);
  out.push_back('{');
  AppendKey("enabled", &out);
  out += a.enabled ? "true" : "false";
  AppendKey("tolerance", &out);
  AppendExact(a.tolerance, &out);
  AppendKey("estimated_error", &out);
  AppendExact(a.estimated_error, &out);
  AppendKey("met", &out);
  out += a.met ? "true" : "false";
  out.push_back('}');
  AppendKey("overall_failures", &out);
  out += std::to_string(r.overall.failures);

  AppendKey("options", &out);
  out.push_back('{');
  AppendKey("playback_seconds", &out);
  AppendExact(options.playback_seconds, &out);
  AppendKey("autoplay", &out);
  out += options.autoplay ? "true" : "false";
  AppendKey("loop", &out);
  out += options.loop ? "true" : "false";
  AppendKey("show_leader_path", &out);
  out += options.show_leader_path ? "true" : "false";
  AppendKey("trail_points", &out);
  out.push_back('[');
  for (size_t i = 0; i < options.trail_points.size(); ++i) {
    if (i > 0) out.push_back(',');
    out += std::to_string(options.trail_points[i]);
  }
  out.push_back(']');
  AppendKey("azimuth", &out);
  AppendExact(options.azimuth, &out);
  AppendKey("elevation", &out);
  AppendExact(options.elevation, &out);
  AppendKey("perspective", &out);
  out += options.perspective ? "true" : "false";
  out.push_back('}');
  out.push_back('}');
  // Strings are escaped and numbers have no '<': nothing can close the <script> element.
  assert(out.find("</") == std::string::npos);
  return out;
}

}  // namespace flexkin::viewer_internal
