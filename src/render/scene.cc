#include "render/scene.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "io/collider_mesh.h"
#include "render/canvas.h"

namespace flexkin::render {
namespace {

constexpr double kDegree = M_PI / 180.0;

void SetDash(cairo_t* cr, bool dashed, double ui, double offset) {
  if (!dashed) {
    cairo_set_dash(cr, nullptr, 0, 0.0);
    return;
  }
  const double pattern[] = {7.0 * ui, 4.5 * ui};
  cairo_set_dash(cr, pattern, 2, offset);
}

}  // namespace

ChainScene::ChainScene(const ResultFile& file, const Rect& area, double ui, double azimuth,
                       double elevation)
    : dim_(file.dim), ui_(ui) {
  lo_.setConstant(INFINITY);
  hi_.setConstant(-INFINITY);
  for (const Frame& frame : file.result.frames) {
    for (Eigen::Index i = 0; i < frame.points.rows(); ++i) {
      const Eigen::Vector3d q = Lift(frame.points.row(i).data());
      lo_ = lo_.cwiseMin(q);
      hi_ = hi_.cwiseMax(q);
    }
  }
  const Eigen::Vector3d center = 0.5 * (lo_ + hi_);
  for (const Collider& collider : file.colliders) {
    ExtendByColliderOverFrames(collider, file, dim_, center, &lo_, &hi_);
  }
  const double extent = std::max((hi_ - lo_).maxCoeff(), 1e-12);

  if (dim_ == 2) {
    // Equal scales: the data, padded by 5%, fills the frame in one direction; the other
    // direction's range is widened to fill it too.
    const double pad = 0.05 * extent;
    const double dx = hi_.x() - lo_.x() + 2 * pad, dy = hi_.y() - lo_.y() + 2 * pad;
    aspect_ = dy / dx;
    scale_ = std::min(area.w / dx, area.h / dy);
    const double cx = 0.5 * (lo_.x() + hi_.x()), cy = 0.5 * (lo_.y() + hi_.y());
    x0_ = cx - area.w / (2 * scale_);
    x1_ = cx + area.w / (2 * scale_);
    y0_ = cy - area.h / (2 * scale_);
    y1_ = cy + area.h / (2 * scale_);
    origin_ = {area.x - x0_ * scale_, area.bottom() + y0_ * scale_};
    plot_ = area;
    return;
  }

  // 3D: a flat direction of the data still gets a box of 15% of the largest extent, so that
  // the panes show.
  for (int a = 0; a < 3; ++a) {
    const double grow = std::max(0.0, 0.15 * extent - (hi_[a] - lo_[a])) / 2 + 0.02 * extent;
    lo_[a] -= grow;
    hi_[a] += grow;
  }
  const double az = azimuth * kDegree, el = elevation * kDegree;
  right_ = {-std::sin(az), std::cos(az), 0.0};
  toward_ = {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
  up_ = toward_.cross(right_);
  double u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
  depth_lo_ = INFINITY;
  depth_hi_ = -INFINITY;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d q(c & 1 ? hi_.x() : lo_.x(), c & 2 ? hi_.y() : lo_.y(),
                            c & 4 ? hi_.z() : lo_.z());
    u0 = std::min(u0, q.dot(right_));
    u1 = std::max(u1, q.dot(right_));
    v0 = std::min(v0, q.dot(up_));
    v1 = std::max(v1, q.dot(up_));
    depth_lo_ = std::min(depth_lo_, q.dot(toward_));
    depth_hi_ = std::max(depth_hi_, q.dot(toward_));
  }
  // Room for the tick labels and axis names around the projected box.
  const double margin = 58.0 * ui;
  const Rect inner{area.x + margin, area.y + 0.5 * margin, area.w - 2 * margin,
                   area.h - 1.5 * margin};
  aspect_ = (v1 - v0) / (u1 - u0);
  scale_ = std::min(inner.w / (u1 - u0), inner.h / (v1 - v0));
  const double cx = inner.x + inner.w / 2, cy = inner.y + inner.h / 2;
  origin_ = {cx - scale_ * (u0 + u1) / 2, cy + scale_ * (v0 + v1) / 2};
  plot_ = {origin_.x() + scale_ * u0, origin_.y() - scale_ * v1, scale_ * (u1 - u0),
           scale_ * (v1 - v0)};
}

Eigen::Vector3d ChainScene::Lift(const double* p) const {
  return {p[0], p[1], dim_ == 3 ? p[2] : 0.0};
}

Eigen::Vector2d ChainScene::Pixel(const double* point) const {
  const Eigen::Vector3d q = Lift(point);
  const double u = dim_ == 2 ? q.x() : q.dot(right_);
  const double v = dim_ == 2 ? q.y() : q.dot(up_);
  return {origin_.x() + scale_ * u, origin_.y() - scale_ * v};
}

Eigen::Vector2d ChainScene::Pixel(const ResultFile& file, int frame, int point) const {
  return Pixel(file.result.frames[frame].points.row(point).data());
}

double ChainScene::Depth(const double* point) const {
  if (dim_ == 2) return 0.0;
  return std::clamp((depth_hi_ - Lift(point).dot(toward_)) / (depth_hi_ - depth_lo_), 0.0, 1.0);
}

std::vector<Eigen::Vector2d> ChainScene::BoxCorners() const {
  std::vector<Eigen::Vector2d> corners;
  for (int c = 0; dim_ == 3 && c < 8; ++c) {
    const Eigen::Vector3d q(c & 1 ? hi_.x() : lo_.x(), c & 2 ? hi_.y() : lo_.y(),
                            c & 4 ? hi_.z() : lo_.z());
    corners.push_back(Pixel(q.data()));
  }
  return corners;
}

void ChainScene::DrawAxes(cairo_t* cr) const {
  if (dim_ == 3) {
    DrawAxes3D(cr);
    return;
  }
  Axes(plot_, x0_, x1_, y0_, y1_).Draw(cr, ui_, "x", "y");
}

void ChainScene::DrawAxes3D(cairo_t* cr) const {
  const Eigen::Vector3d back(toward_.x() > 0 ? lo_.x() : hi_.x(),
                             toward_.y() > 0 ? lo_.y() : hi_.y(),
                             toward_.z() > 0 ? lo_.z() : hi_.z());
  const Eigen::Vector3d front = lo_ + hi_ - back;
  auto px = [&](const Eigen::Vector3d& q) { return Pixel(q.data()); };
  std::vector<double> ticks[3];
  for (int a = 0; a < 3; ++a) ticks[a] = NiceTicks(lo_[a], hi_[a], 5);

  // The three back panes (the planes through `back`), filled light, with grid lines.
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    Eigen::Vector3d q = back;
    const double corners[4][2] = {
        {lo_[b], lo_[c]}, {hi_[b], lo_[c]}, {hi_[b], hi_[c]}, {lo_[b], hi_[c]}};
    for (int k = 0; k < 4; ++k) {
      q[b] = corners[k][0];
      q[c] = corners[k][1];
      const Eigen::Vector2d p = px(q);
      k == 0 ? cairo_move_to(cr, p.x(), p.y()) : cairo_line_to(cr, p.x(), p.y());
    }
    cairo_close_path(cr);
    SetColor(cr, {0.965, 0.965, 0.970});
    cairo_fill_preserve(cr);
    SetColor(cr, {0.80, 0.80, 0.80});
    cairo_set_line_width(cr, 0.8 * ui_);
    cairo_stroke(cr);
    for (int g : {b, c}) {
      const int h = g == b ? c : b;
      for (double t : ticks[g]) {
        Eigen::Vector3d p0 = back, p1 = back;
        p0[g] = p1[g] = t;
        p0[h] = lo_[h];
        p1[h] = hi_[h];
        const Eigen::Vector2d a0 = px(p0), a1 = px(p1);
        Line(cr, a0.x(), a0.y(), a1.x(), a1.y(), {0.86, 0.86, 0.87}, 0.8 * ui_);
      }
    }
  }

  // The ticked axes: x and y along the front edges of the back z pane, z along the vertical
  // edge that is more to the left of the two side corners.
  Eigen::Vector3d x_edge(0, front.y(), back.z()), y_edge(front.x(), 0, back.z());
  Eigen::Vector3d z_a(front.x(), back.y(), 0), z_b(back.x(), front.y(), 0);
  const Eigen::Vector3d z_edge = px(z_a).x() <= px(z_b).x() ? z_a : z_b;
  const Eigen::Vector3d edges[3] = {x_edge, y_edge, z_edge};
  const Eigen::Vector2d center = px(0.5 * (lo_ + hi_));
  static const char* kNames[3] = {"x", "y", "z"};
  TextStyle label;
  label.size = 11 * ui_;
  label.color = kMuted;
  label.halign = Align::kCenter;
  label.valign = Align::kCenter;
  for (int a = 0; a < 3; ++a) {
    Eigen::Vector3d e0 = edges[a], e1 = edges[a];
    e0[a] = lo_[a];
    e1[a] = hi_[a];
    const Eigen::Vector2d p0 = px(e0), p1 = px(e1);
    if ((p1 - p0).norm() < 12 * ui_) continue;  // seen end-on
    Line(cr, p0.x(), p0.y(), p1.x(), p1.y(), kInk, 1.0 * ui_);
    // Outward: away from the box's centre, perpendicular to the edge on screen.
    Eigen::Vector2d along = (p1 - p0).normalized(), out(-along.y(), along.x());
    if (out.dot(0.5 * (p0 + p1) - center) < 0) out = -out;
    const double step = ticks[a].size() > 1 ? ticks[a][1] - ticks[a][0] : 1.0;
    double reach = 0.0;
    for (double t : ticks[a]) {
      Eigen::Vector3d q = edges[a];
      q[a] = t;
      const Eigen::Vector2d p = px(q), tip = p + 5 * ui_ * out;
      Line(cr, p.x(), p.y(), tip.x(), tip.y(), kInk, 1.0 * ui_);
      const std::string text = TickLabel(t, step);
      const double half =
          0.5 * (std::abs(out.x()) * TextWidth(cr, text, label) + std::abs(out.y()) * label.size);
      const Eigen::Vector2d at = tip + (4 * ui_ + half) * out;
      DrawText(cr, at.x(), at.y(), text, label);
      reach = std::max(reach, 4 * ui_ + 2 * half);
    }
    TextStyle name = label;
    name.size = 13 * ui_;
    name.color = kInk;
    const Eigen::Vector2d at = 0.5 * (p0 + p1) + (5 * ui_ + reach + 12 * ui_) * out;
    DrawText(cr, at.x(), at.y(), kNames[a], name);
  }
}

void ChainScene::DrawCapsules(cairo_t* cr, const double* chain, int rows,
                              const Eigen::VectorXd& radii, const Rgb& color) const {
  std::vector<std::pair<double, int>> order;  // (depth, link), far first
  for (int j = 0; j + 1 < rows && j < radii.size(); ++j) {
    if (radii[j] > 0.0) {
      const double* p = chain + dim_ * j;
      order.emplace_back(-0.5 * (Depth(p) + Depth(p + dim_)), j);
    }
  }
  std::stable_sort(order.begin(), order.end());
  cairo_save(cr);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  SetColor(cr, color);
  for (const auto& [depth, j] : order) {
    const Eigen::Vector2d a = Pixel(chain + dim_ * j), b = Pixel(chain + dim_ * (j + 1));
    cairo_move_to(cr, a.x(), a.y());
    cairo_line_to(cr, b.x(), b.y());
    cairo_set_line_width(cr, 2.0 * radii[j] * scale_);
    cairo_stroke(cr);
  }
  cairo_restore(cr);
}

void ChainScene::DrawChains(cairo_t* cr, const std::vector<const double*>& chains,
                            const std::vector<int>& rows,
                            const std::vector<ChainStyle>& styles) const {
  cairo_save(cr);
  if (dim_ == 2) {
    for (size_t c = 0; c < chains.size(); ++c) {
      for (int j = 0; j < rows[c]; ++j) {
        const Eigen::Vector2d p = Pixel(chains[c] + 2 * j);
        j == 0 ? cairo_move_to(cr, p.x(), p.y()) : cairo_line_to(cr, p.x(), p.y());
      }
      SetColor(cr, styles[c].color);
      cairo_set_line_width(cr, styles[c].width);
      SetDash(cr, styles[c].dashed, ui_, 0.0);
      cairo_stroke(cr);
    }
    cairo_restore(cr);
    return;
  }
  struct Segment {
    Eigen::Vector2d a, b;
    double depth, dash_offset;
    size_t chain;
  };
  std::vector<Segment> segments;
  for (size_t c = 0; c < chains.size(); ++c) {
    double run = 0.0;
    for (int j = 0; j + 1 < rows[c]; ++j) {
      const double* p = chains[c] + 3 * j;
      const Segment s{Pixel(p), Pixel(p + 3), 0.5 * (Depth(p) + Depth(p + 3)), run, c};
      run += (s.b - s.a).norm();
      segments.push_back(s);
    }
  }
  std::stable_sort(segments.begin(), segments.end(),
                   [](const Segment& x, const Segment& y) { return x.depth > y.depth; });
  for (const Segment& s : segments) {
    const ChainStyle& style = styles[s.chain];
    cairo_move_to(cr, s.a.x(), s.a.y());
    cairo_line_to(cr, s.b.x(), s.b.y());
    SetColor(cr, Mix(style.color, kWhite, 0.55 * s.depth));
    cairo_set_line_width(cr, style.width * (1.0 - 0.4 * s.depth));
    SetDash(cr, style.dashed, ui_, s.dash_offset);
    cairo_stroke(cr);
  }
  cairo_restore(cr);
}

}  // namespace flexkin::render
