// ChainScene::DrawColliders: the colliders under the chains, in a neutral grey, from the one
// geometry of the colliders (io/collider_mesh.h).
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <utility>
#include <vector>

#include "io/collider_mesh.h"
#include "render/canvas.h"
#include "render/scene.h"

namespace flexkin::render {
namespace {

// Round parts are drawn with this many segments: a polygon a pixel from the curve at 1000 px.
constexpr int kSegments = 96;

double Cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// The convex hull of `points` (Andrew's monotone chain), in order round it.
std::vector<Eigen::Vector2d> ConvexHull(std::vector<Eigen::Vector2d> points) {
  std::sort(points.begin(), points.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (points.size() < 3) return points;
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {  // lower hull
    while (k >= 2 && Cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, t = k + 1; i > 0; --i) {  // upper hull
    while (k >= t && Cross(hull[k - 2], hull[k - 1], points[i - 1]) <= 0) --k;
    hull[k++] = points[i - 1];
  }
  hull.resize(k - 1);
  return hull;
}

void FillPolygon(cairo_t* cr, const std::vector<Eigen::Vector2d>& pixels, double ui) {
  if (pixels.size() < 3) return;
  for (size_t i = 0; i < pixels.size(); ++i) {
    i == 0 ? cairo_move_to(cr, pixels[i].x(), pixels[i].y())
           : cairo_line_to(cr, pixels[i].x(), pixels[i].y());
  }
  cairo_close_path(cr);
  SetColor(cr, kColliderFill);
  cairo_fill_preserve(cr);
  SetColor(cr, kColliderEdge);
  cairo_set_line_width(cr, 1.2 * ui);
  cairo_stroke(cr);
}

// A mesh (not convex: its hull would fill its hollows): the union of its triangles as projected,
// each turned counter-clockwise so that the nonzero rule fills the union, outlined along its
// silhouette (the edges whose two triangles face opposite ways once projected).
void FillMesh(cairo_t* cr, const ColliderMesh& mesh, const std::vector<Eigen::Vector2d>& pixels,
              double ui) {
  std::map<std::pair<int, int>, int> facing;  // per edge: +1 / -1 per triangle facing the viewer
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector2d a = pixels[t[0]], b = pixels[t[1]], c = pixels[t[2]];
    const double area = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    const int side = area >= 0.0 ? 1 : -1;
    for (int k = 0; k < 3; ++k) {
      const int i = t[k], j = t[(k + 1) % 3];
      facing[{std::min(i, j), std::max(i, j)}] += side;
    }
    cairo_move_to(cr, a.x(), a.y());
    const Eigen::Vector2d& second = side > 0 ? b : c;
    const Eigen::Vector2d& third = side > 0 ? c : b;
    cairo_line_to(cr, second.x(), second.y());
    cairo_line_to(cr, third.x(), third.y());
    cairo_close_path(cr);
  }
  cairo_set_fill_rule(cr, CAIRO_FILL_RULE_WINDING);
  SetColor(cr, kColliderFill);
  cairo_fill(cr);
  for (const auto& [edge, sum] : facing) {
    if (sum != 0) continue;
    cairo_move_to(cr, pixels[edge.first].x(), pixels[edge.first].y());
    cairo_line_to(cr, pixels[edge.second].x(), pixels[edge.second].y());
  }
  SetColor(cr, kColliderEdge);
  cairo_set_line_width(cr, 1.2 * ui);
  cairo_stroke(cr);
}

}  // namespace

void DrawColliderShapes(cairo_t* cr, int dim, const std::vector<Collider>& colliders,
                        const std::function<Eigen::Vector2d(const Eigen::Vector3d&)>& pixel,
                        const std::function<double(const Eigen::Vector3d&)>& farness,
                        const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double ui) {
  if (colliders.empty()) return;
  cairo_save(cr);
  cairo_set_dash(cr, nullptr, 0, 0.0);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  if (dim == 2) {
    for (const Collider& c : colliders) {
      std::vector<Eigen::Vector2d> pixels;
      for (const Eigen::Vector2d& p :
           OutlineOfCollider2d(c, kSegments, lo.head<2>(), hi.head<2>())) {
        pixels.push_back(pixel(Eigen::Vector3d(p.x(), p.y(), 0.0)));
      }
      FillPolygon(cr, pixels, ui);
    }
    cairo_restore(cr);
    return;
  }
  // 3D: far to near by the depth of each shape's centre (a half-space's plane first: it is the
  // ground the rest stands on).
  std::vector<std::pair<double, const Collider*>> order;
  for (const Collider& c : colliders) {
    const bool plane = c.shape == ColliderShape::kHalfSpace;
    order.emplace_back(plane ? HUGE_VAL : farness(c.pose.translation()), &c);
  }
  std::stable_sort(order.begin(), order.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  for (const auto& [depth, c] : order) {
    std::vector<Eigen::Vector2d> pixels;
    if (c->shape == ColliderShape::kHalfSpace) {
      for (const Eigen::Vector3d& q : HalfSpacePlaneInBox(*c, lo, hi)) pixels.push_back(pixel(q));
    } else if (c->shape == ColliderShape::kMesh) {
      const ColliderMesh mesh = MeshOfCollider(*c, kSegments / 2, Eigen::Vector3d::Zero(), 0.0);
      for (const Eigen::Vector3d& q : mesh.vertices) pixels.push_back(pixel(q));
      FillMesh(cr, mesh, pixels, ui);
      continue;
    } else {
      for (const Eigen::Vector3d& q :
           MeshOfCollider(*c, kSegments / 2, Eigen::Vector3d::Zero(), 0.0).vertices) {
        pixels.push_back(pixel(q));
      }
      pixels = ConvexHull(std::move(pixels));
    }
    FillPolygon(cr, pixels, ui);
  }
  cairo_restore(cr);
}

void ChainScene::DrawColliders(cairo_t* cr, const std::vector<Collider>& colliders) const {
  if (colliders.empty()) return;
  const auto pixel = [&](const Eigen::Vector3d& q) { return Pixel(q.data()); };
  const auto farness = [&](const Eigen::Vector3d& q) { return Depth(q.data()); };
  if (dim_ == 2) {
    cairo_save(cr);
    cairo_rectangle(cr, plot_.x, plot_.y, plot_.w, plot_.h);
    cairo_clip(cr);
    // A half-plane's region reaches a little beyond the frame, so that its sides are clipped
    // rather than outlined.
    const double margin = 0.05 * std::max(x1_ - x0_, y1_ - y0_);
    const Eigen::Vector3d lo(x0_ - margin, y0_ - margin, 0.0), hi(x1_ + margin, y1_ + margin, 0.0);
    DrawColliderShapes(cr, 2, colliders, pixel, farness, lo, hi, ui_);
    cairo_restore(cr);
    return;
  }
  DrawColliderShapes(cr, 3, colliders, pixel, farness, lo_, hi_, ui_);
}

std::vector<Collider> StaticColliders(const std::vector<Collider>& colliders) {
  std::vector<Collider> kept;
  for (const Collider& c : colliders) {
    if (!c.motion) kept.push_back(c);
  }
  return kept;
}

std::vector<Collider> MovingCollidersAt(const std::vector<Collider>& colliders, double time) {
  std::vector<Collider> moved;
  for (const Collider& c : colliders) {
    if (c.motion) moved.push_back(ColliderAt(c, time));
  }
  return moved;
}

}  // namespace flexkin::render
