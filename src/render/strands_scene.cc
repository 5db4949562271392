#include "render/strands_scene.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "io/collider_mesh.h"
#include "render/canvas.h"
#include "render/scene.h"

namespace flexkin::render {
namespace {

constexpr double kDegree = M_PI / 180.0;
// Depth layers of the painter's order and colour bands along a strand: each (side of the scalp,
// layer, band) is one cairo path, stroked once, so a frame costs a few hundred strokes however
// many strands it has.
constexpr int kLayers = 16;
constexpr int kBands = 6;
// How far the farthest strands fade toward the background.
constexpr double kHaze = 0.5;

constexpr Rgb kScalpLight{0.97, 0.94, 0.91};
constexpr Rgb kScalpMid{0.87, 0.82, 0.78};
constexpr Rgb kScalpEdge{0.62, 0.57, 0.54};

// The scalp at a pose, in world coordinates: centre, M = R diag(r^2) R^T (its shape) and
// A = M^-1 (its quadratic form: x is on it when (x - c)^T A (x - c) = 1).
struct Ellipsoid {
  Eigen::Vector3d center;
  Eigen::Matrix3d rotation, shape, form;
  Eigen::Vector3d radii;
  Eigen::Vector3d Surface(const Eigen::Vector3d& unit) const {
    return center + rotation * radii.cwiseProduct(unit);
  }
};

Ellipsoid PosedScalp(int dim, const ScalpShape& scalp, const BodyPose& pose) {
  Ellipsoid e;
  e.radii = scalp.radii;
  // A 2D scalp has no z extent; a round one keeps the classifier below well defined.
  if (dim == 2) e.radii.z() = std::max(e.radii.x(), e.radii.y());
  e.rotation = pose.rotation;
  e.center = pose.rotation * scalp.center + pose.translation;
  if (dim == 2) e.center.z() = 0.0;
  e.shape = e.rotation * e.radii.cwiseAbs2().asDiagonal() * e.rotation.transpose();
  e.form = e.rotation * e.radii.cwiseAbs2().cwiseInverse().asDiagonal() * e.rotation.transpose();
  return e;
}

// Positive on the side of the scalp that faces the viewer: the plane through the centre that
// holds the silhouette splits what the scalp hides (behind it) from what it cannot.
double FacingSide(const Ellipsoid& e, const Eigen::Vector3d& toward, const Eigen::Vector3d& q) {
  return (q - e.center).dot(e.form * toward);
}

// The projected ellipse: view-plane covariance S = P M P^T with P = [right; up].
Eigen::Matrix2d ProjectedShape(const Ellipsoid& e, const StrandsView& view) {
  Eigen::Matrix<double, 2, 3> p;
  p << view.right().transpose(), view.up().transpose();
  return p * e.shape * p.transpose();
}

// The shaded disc of the scalp, its outline, and its equator and prime meridian where they face
// the viewer (2D: a radius toward body +x), so that its turning shows.
void DrawScalp(cairo_t* cr, const StrandsView& view, const Ellipsoid& e, double ui) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(ProjectedShape(e, view));
  const Eigen::Vector2d semi = eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  if (semi.minCoeff() * view.scale() < 0.5) return;
  // Unit circle -> view plane (L) -> pixels (y down).
  const Eigen::Matrix2d l = eigen.eigenvectors() * semi.asDiagonal();
  const Eigen::Vector2d c = view.Pixel(e.center);
  const double s = view.scale();
  cairo_matrix_t m;
  cairo_matrix_init(&m, s * l(0, 0), -s * l(1, 0), s * l(0, 1), -s * l(1, 1), c.x(), c.y());
  // The light from the upper left, in the unit circle's coordinates.
  Eigen::Vector2d light = l.inverse() * (Eigen::Vector2d(-0.35, 0.42) * semi.maxCoeff());
  if (light.norm() > 0.6) light *= 0.6 / light.norm();
  cairo_save(cr);
  cairo_transform(cr, &m);
  cairo_new_path(cr);
  cairo_arc(cr, 0.0, 0.0, 1.0, 0.0, 2.0 * M_PI);
  cairo_pattern_t* shading = cairo_pattern_create_radial(light.x(), light.y(), 0.0, 0.0, 0.0, 1.0);
  cairo_pattern_add_color_stop_rgb(shading, 0.0, kScalpLight.r, kScalpLight.g, kScalpLight.b);
  cairo_pattern_add_color_stop_rgb(shading, 0.55, kScalpMid.r, kScalpMid.g, kScalpMid.b);
  cairo_pattern_add_color_stop_rgb(shading, 1.0, kScalpEdge.r, kScalpEdge.g, kScalpEdge.b);
  cairo_set_source(cr, shading);
  cairo_fill_preserve(cr);
  cairo_pattern_destroy(shading);
  cairo_restore(cr);
  SetColor(cr, Mix(kScalpEdge, kInk, 0.35));
  cairo_set_line_width(cr, 1.0 * ui);
  cairo_stroke(cr);

  SetColor(cr, Mix(kScalpEdge, kInk, 0.2), 0.55);
  cairo_set_line_width(cr, 1.1 * ui);
  if (view.dim() == 2) {
    const Eigen::Vector2d nose = view.Pixel(e.Surface(Eigen::Vector3d::UnitX()));
    cairo_move_to(cr, c.x(), c.y());
    cairo_line_to(cr, nose.x(), nose.y());
    cairo_stroke(cr);
    return;
  }
  constexpr int kSamples = 96;
  for (int circle = 0; circle < 2; ++circle) {
    bool drawing = false;
    for (int k = 0; k <= kSamples; ++k) {
      const double a = 2.0 * M_PI * k / kSamples;
      const Eigen::Vector3d unit = circle == 0 ? Eigen::Vector3d(std::cos(a), std::sin(a), 0.0)
                                               : Eigen::Vector3d(std::cos(a), 0.0, std::sin(a));
      const Eigen::Vector3d q = e.Surface(unit);
      if (FacingSide(e, view.toward(), q) <= 0.0) {
        drawing = false;
        continue;
      }
      const Eigen::Vector2d p = view.Pixel(q);
      if (drawing) {
        cairo_line_to(cr, p.x(), p.y());
      } else {
        cairo_move_to(cr, p.x(), p.y());
      }
      drawing = true;
    }
  }
  cairo_stroke(cr);
  // The body's +x ("the nose") where it faces the viewer.
  const Eigen::Vector3d nose = e.Surface(Eigen::Vector3d::UnitX());
  if (FacingSide(e, view.toward(), nose) > 0.0) {
    const Eigen::Vector2d p = view.Pixel(nose);
    Disc(cr, p.x(), p.y(), 2.6 * ui, Mix(kScalpEdge, kInk, 0.3));
  }
}

// Blends one anti-aliased segment of `width` pixels, with a round end, into an RGB24 image:
// coverage falls off linearly over the pixel at the edge, and a line thinner than a pixel is
// fainter instead. Without `start_cap` the pixels before `a` are left to the previous segment's
// end, so that the joints of a polyline are not blended twice.
void BlendSegment(unsigned char* data, int stride, int w, int h, float ax, float ay, float bx,
                  float by, float width, const int rgb[3], bool start_cap) {
  const float half = 0.5f * width, reach = half + 0.5f;
  const float peak = std::min(1.0f, width);
  const int x0 = std::max(0, static_cast<int>(std::floor(std::min(ax, bx) - reach)));
  const int x1 = std::min(w - 1, static_cast<int>(std::ceil(std::max(ax, bx) + reach)));
  const int y0 = std::max(0, static_cast<int>(std::floor(std::min(ay, by) - reach)));
  const int y1 = std::min(h - 1, static_cast<int>(std::ceil(std::max(ay, by) + reach)));
  const float dx = bx - ax, dy = by - ay, length2 = dx * dx + dy * dy;
  const float inverse = length2 > 1e-12f ? 1.0f / length2 : 0.0f;
  // Along a row, only the pixels within `reach` of the infinite line can be covered:
  // |(px - ax) dy - (py - ay) dx| <= reach |ab|.
  const float across = reach * std::sqrt(length2);
  const bool steep = std::abs(dy) > 1e-3f;
  for (int y = y0; y <= y1; ++y) {
    auto* row = reinterpret_cast<uint32_t*>(data + static_cast<size_t>(y) * stride);
    const float py = y + 0.5f;
    int from = x0, to = x1;
    if (steep) {
      const float c = (py - ay) * dx;
      const float e0 = ax + (c - across) / dy, e1 = ax + (c + across) / dy;
      from = std::max(x0, static_cast<int>(std::floor(std::min(e0, e1) - 0.5f)));
      to = std::min(x1, static_cast<int>(std::ceil(std::max(e0, e1))));
    }
    for (int x = from; x <= to; ++x) {
      const float px = x + 0.5f;
      const float t = ((px - ax) * dx + (py - ay) * dy) * inverse;
      if (!start_cap && t < 0.0f) continue;
      const float tc = std::clamp(t, 0.0f, 1.0f);
      const float ex = ax + tc * dx - px, ey = ay + tc * dy - py;
      const float coverage = std::min(peak, reach - std::sqrt(ex * ex + ey * ey));
      if (coverage <= 0.0f) continue;
      const int alpha = static_cast<int>(coverage * 256.0f);
      const uint32_t old = row[x];
      const int r = old >> 16 & 255, g = old >> 8 & 255, b = old & 255;
      row[x] = static_cast<uint32_t>((r + (((rgb[0] - r) * alpha) >> 8)) << 16 |
                                     (g + (((rgb[1] - g) * alpha) >> 8)) << 8 |
                                     (b + (((rgb[2] - b) * alpha) >> 8)));
    }
  }
}

// The polylines of `piece` (x, y pairs; NaN starts a new one) blended into `image`.
void BlendPolylines(cairo_surface_t* image, const std::vector<float>& piece, double width,
                    const Rgb& color) {
  unsigned char* data = cairo_image_surface_get_data(image);
  const int stride = cairo_image_surface_get_stride(image);
  const int w = cairo_image_surface_get_width(image), h = cairo_image_surface_get_height(image);
  const int rgb[3] = {static_cast<int>(std::lround(255 * color.r)),
                      static_cast<int>(std::lround(255 * color.g)),
                      static_cast<int>(std::lround(255 * color.b))};
  bool start = true, first = true;
  float x = 0.0f, y = 0.0f;
  for (size_t k = 0; k + 1 < piece.size(); k += 2) {
    if (std::isnan(piece[k])) {
      start = true;
      continue;
    }
    if (start) {
      start = false;
      first = true;
    } else {
      BlendSegment(data, stride, w, h, x, y, piece[k], piece[k + 1], static_cast<float>(width), rgb,
                   first);
      first = false;
    }
    x = piece[k];
    y = piece[k + 1];
  }
}

}  // namespace

Rgb StrandColor(double t) {
  static constexpr Rgb kRamp[] = {{0.15, 0.10, 0.30},
                                  {0.38, 0.12, 0.44},
                                  {0.68, 0.20, 0.42},
                                  {0.90, 0.38, 0.30},
                                  {0.97, 0.62, 0.24}};
  constexpr int n = static_cast<int>(std::size(kRamp));
  t = std::clamp(t, 0.0, 1.0) * (n - 1);
  const int i = std::min(static_cast<int>(t), n - 2);
  return Mix(kRamp[i], kRamp[i + 1], t - i);
}

StrandsView::StrandsView(int dim, double azimuth, double elevation) : dim_(dim) {
  if (dim == 2) {
    right_ = Eigen::Vector3d::UnitX();
    up_ = Eigen::Vector3d::UnitY();
    toward_ = Eigen::Vector3d::UnitZ();
    return;
  }
  const double az = azimuth * kDegree, el = elevation * kDegree;
  right_ = {-std::sin(az), std::cos(az), 0.0};
  toward_ = {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
  up_ = toward_.cross(right_);
}

Eigen::Vector3d StrandsView::Lift(const double* point) const {
  return {point[0], point[1], dim_ == 3 ? point[2] : 0.0};
}

void StrandsView::Include(const Eigen::Vector3d& q, ViewBounds* b) const {
  const Eigen::Vector2d p = Plane(q);
  const double d = Depth(q);
  b->u0 = std::min(b->u0, p.x());
  b->u1 = std::max(b->u1, p.x());
  b->v0 = std::min(b->v0, p.y());
  b->v1 = std::max(b->v1, p.y());
  b->d0 = std::min(b->d0, d);
  b->d1 = std::max(b->d1, d);
}

void StrandsView::IncludeScalp(const ScalpShape& scalp, const BodyPose& pose, ViewBounds* b) const {
  if (scalp.shape.empty()) return;
  const Ellipsoid e = PosedScalp(dim_, scalp, pose);
  const Eigen::Matrix2d s = ProjectedShape(e, *this);
  const Eigen::Vector2d c = Plane(e.center);
  const double du = std::sqrt(std::max(s(0, 0), 0.0)), dv = std::sqrt(std::max(s(1, 1), 0.0));
  const double dd = dim_ == 3 ? std::sqrt(std::max(toward_.dot(e.shape * toward_), 0.0)) : 0.0;
  b->u0 = std::min(b->u0, c.x() - du);
  b->u1 = std::max(b->u1, c.x() + du);
  b->v0 = std::min(b->v0, c.y() - dv);
  b->v1 = std::max(b->v1, c.y() + dv);
  b->d0 = std::min(b->d0, Depth(e.center) - dd);
  b->d1 = std::max(b->d1, Depth(e.center) + dd);
}

std::vector<Collider> FigureColliders(const StrandFileHeader& header, const BodyPose& pose,
                                      double time) {
  Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
  body.linear() = pose.rotation;
  body.translation() = pose.translation;
  std::vector<Collider> colliders = BodyCollidersBesideScalp(header);
  for (Collider& c : colliders) c.pose = body * c.pose;
  for (const Collider& c : header.world_colliders) colliders.push_back(ColliderAt(c, time));
  return colliders;
}

void IncludeColliders(const StrandsView& view, const std::vector<Collider>& colliders,
                      ViewBounds* bounds) {
  for (const Collider& c : colliders) {
    if (c.shape == ColliderShape::kHalfSpace) continue;
    if (view.dim() == 2) {
      const double big = 1e6;
      for (const Eigen::Vector2d& p : OutlineOfCollider2d(c, 32, Eigen::Vector2d::Constant(-big),
                                                          Eigen::Vector2d::Constant(big))) {
        view.Include(Eigen::Vector3d(p.x(), p.y(), 0.0), bounds);
      }
      continue;
    }
    for (const Eigen::Vector3d& q : MeshOfCollider(c, 16, Eigen::Vector3d::Zero(), 0.0).vertices) {
      view.Include(q, bounds);
    }
  }
}

void StrandsView::Fit(const ViewBounds& bounds, double margin, const Rect& area) {
  const double size = std::max({bounds.u1 - bounds.u0, bounds.v1 - bounds.v0, 1e-12});
  const double du = bounds.u1 - bounds.u0 + 2 * margin * size;
  const double dv = bounds.v1 - bounds.v0 + 2 * margin * size;
  scale_ = std::min(area.w / std::max(du, 1e-12), area.h / std::max(dv, 1e-12));
  const double uc = 0.5 * (bounds.u0 + bounds.u1), vc = 0.5 * (bounds.v0 + bounds.v1);
  origin_ = {area.x + area.w / 2 - uc * scale_, area.y + area.h / 2 + vc * scale_};
  d0_ = bounds.d0;
  d1_ = bounds.d1 > bounds.d0 ? bounds.d1 : bounds.d0 + 1.0;
}

Eigen::Vector2d StrandsView::Pixel(const Eigen::Vector3d& q) const {
  const Eigen::Vector2d p = Plane(q);
  return {origin_.x() + scale_ * p.x(), origin_.y() - scale_ * p.y()};
}

double StrandsView::Nearness(double depth) const {
  return std::clamp((depth - d0_) / (d1_ - d0_), 0.0, 1.0);
}

void DrawStrandsFrame(cairo_t* cr, const StrandsView& view, const StrandFileHeader& header,
                      const std::vector<int>& strands, const Points& points, const BodyPose& pose,
                      double time, const StrandsStyle& style, StrandsWork* work) {
  const bool has_scalp = !header.scalp.shape.empty();
  const Ellipsoid scalp = has_scalp ? PosedScalp(header.dim, header.scalp, pose) : Ellipsoid{};
  // FacingSide's normal, once per frame.
  const Eigen::Vector3d facing =
      has_scalp ? Eigen::Vector3d(scalp.form * view.toward()) : Eigen::Vector3d::Zero();
  std::vector<std::vector<float>>& pieces = work->pieces;
  pieces.resize(2 * kLayers * kBands);
  for (std::vector<float>& piece : pieces) piece.clear();
  constexpr float kBreak = std::numeric_limits<float>::quiet_NaN();

  std::vector<Eigen::Vector3d> q;
  std::vector<Eigen::Vector2d> p;
  for (const int i : strands) {
    const int first = static_cast<int>(header.offsets[i]);
    const int rows = static_cast<int>(header.offsets[i + 1]) - first;
    q.resize(rows);
    p.resize(rows);
    for (int r = 0; r < rows; ++r) {
      q[r] = view.Lift(points.row(first + r).data());
      p[r] = view.Pixel(q[r]);
    }
    const int links = rows - 1;
    int previous = -1;
    for (int j = 0; j < links; ++j) {
      const int band = std::min(kBands - 1, (j * kBands + kBands / 2) / links);
      const Eigen::Vector3d middle = 0.5 * (q[j] + q[j + 1]);
      const int layer =
          std::min(kLayers - 1, static_cast<int>(view.Nearness(view.Depth(middle)) * kLayers));
      const int side = has_scalp && (middle - scalp.center).dot(facing) < 0.0 ? 0 : 1;
      const int key = (side * kLayers + layer) * kBands + band;
      std::vector<float>& piece = pieces[key];
      if (key != previous) {
        piece.insert(piece.end(),
                     {kBreak, kBreak, static_cast<float>(p[j].x()), static_cast<float>(p[j].y())});
      }
      piece.push_back(static_cast<float>(p[j + 1].x()));
      piece.push_back(static_cast<float>(p[j + 1].y()));
      previous = key;
    }
  }

  // Raster pictures get the strands blended straight into their pixels: cairo's stroker takes
  // about a second for the 120,000 links of 5,000 strands, this about 50 times less.
  cairo_surface_t* target = cairo_get_target(cr);
  cairo_matrix_t ctm;
  cairo_get_matrix(cr, &ctm);
  const bool raster = cairo_surface_get_type(target) == CAIRO_SURFACE_TYPE_IMAGE &&
                      cairo_image_surface_get_format(target) == CAIRO_FORMAT_RGB24 &&
                      ctm.xx == 1.0 && ctm.yy == 1.0 && ctm.xy == 0.0 && ctm.yx == 0.0 &&
                      ctm.x0 == 0.0 && ctm.y0 == 0.0;
  cairo_save(cr);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  const std::vector<Collider> colliders = FigureColliders(header, pose, time);
  for (int side = 0; side < 2; ++side) {
    if (side == 1 && !colliders.empty()) {
      // A half-space's plane is cut to a box about the body, far wider than any picture of it.
      const double reach = 1e3 * (1.0 + (has_scalp ? header.scalp.radii.maxCoeff() : 0.0));
      const Eigen::Vector3d lo = pose.translation - Eigen::Vector3d::Constant(reach);
      const Eigen::Vector3d hi = pose.translation + Eigen::Vector3d::Constant(reach);
      DrawColliderShapes(
          cr, header.dim, colliders, [&](const Eigen::Vector3d& q) { return view.Pixel(q); },
          [&](const Eigen::Vector3d& q) { return -view.Depth(q); }, lo, hi, style.ui);
    }
    if (side == 1 && has_scalp) DrawScalp(cr, view, scalp, style.ui);
    for (int layer = 0; layer < kLayers; ++layer) {
      const double haze = kHaze * (1.0 - (layer + 0.5) / kLayers);
      for (int band = 0; band < kBands; ++band) {
        const std::vector<float>& piece = pieces[(side * kLayers + layer) * kBands + band];
        if (piece.empty()) continue;
        const double t = (band + 0.5) / kBands;
        const Rgb color = Mix(StrandColor(t), style.background, haze);
        const double width = style.root_width * (1.0 - (1.0 - style.tip_width) * t);
        if (raster) {
          cairo_surface_flush(target);
          BlendPolylines(target, piece, width, color);
          cairo_surface_mark_dirty(target);
          continue;
        }
        cairo_new_path(cr);
        bool start = true;
        for (size_t k = 0; k + 1 < piece.size(); k += 2) {
          if (std::isnan(piece[k])) {
            start = true;
          } else if (start) {
            cairo_move_to(cr, piece[k], piece[k + 1]);
            start = false;
          } else {
            cairo_line_to(cr, piece[k], piece[k + 1]);
          }
        }
        SetColor(cr, color);
        cairo_set_line_width(cr, width);
        cairo_stroke(cr);
      }
    }
  }
  cairo_restore(cr);
}

}  // namespace flexkin::render
