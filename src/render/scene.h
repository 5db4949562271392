#pragma once
// The chain's recorded frames laid out in a picture: 2D as they are, 3D by an orthographic view
// from (azimuth, elevation); equal scales on every axis; the axes (2D: a framed plot, 3D: the
// back panes of the bounding box with grids and ticks); the chains drawn with depth cues.

#include <cairo.h>

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "flexkin/result_io.h"
#include "render/axes.h"
#include "render/style.h"

namespace flexkin::render {

// How to draw one chain (or one path) in ChainScene::DrawChains.
struct ChainStyle {
  Rgb color;
  double width = 1.0;  // pixels, before depth cues
  bool dashed = false;
};

class ChainScene {
 public:
  // Fits every point of every frame of `file` and its colliders (a half-space: its boundary's
  // point nearest the frames) into `area` (pixels). Angles in degrees.
  ChainScene(const ResultFile& file, const Rect& area, double ui, double azimuth, double elevation);

  int dim() const { return dim_; }
  // Pixels per data unit (every axis, and in 3D every direction of the view plane).
  double scale() const { return scale_; }
  // A point (dim values) in pixels.
  Eigen::Vector2d Pixel(const double* point) const;
  // Point i of frame f in pixels.
  Eigen::Vector2d Pixel(const ResultFile& file, int frame, int point) const;
  // 0 for the nearest corner of the bounding box to 1 for the farthest; 0 in 2D.
  double Depth(const double* point) const;
  // Height over width of what the scene must show (2D: the padded data; 3D: the projected
  // box), for choosing a picture's height.
  double aspect() const { return aspect_; }
  // The rectangle the data may cover (2D: the plot frame; 3D: the projected box).
  const Rect& plot() const { return plot_; }

  // 3D: the 8 corners of the bounding box in pixels, corner c at (c & 1 ? hi : lo) in x,
  // (c & 2) in y, (c & 4) in z. Empty in 2D.
  std::vector<Eigen::Vector2d> BoxCorners() const;

  // 2D: framed axes with ticks and "x", "y"; 3D: back panes, grids, three ticked axes.
  void DrawAxes(cairo_t* cr) const;
  // Draws the chains (each a (k by dim) row-major array of `rows` points) in one batch. 2D: each
  // a polyline, in order. 3D: all their segments sorted from far to near (painter's order),
  // the farther lighter and thinner; dashes continue along a chain.
  void DrawChains(cairo_t* cr, const std::vector<const double*>& chains,
                  const std::vector<int>& rows, const std::vector<ChainStyle>& styles) const;
  // Draws one chain's links (a (rows by dim) row-major array) as their capsules: link i, from
  // point i to i + 1, a stroke of width 2 radii[i] (data units) with round ends, in `color`
  // (3D: far to near). The view is orthographic, so that a capsule's outline is exactly that
  // stroke's. Under the chain's lines.
  void DrawCapsules(cairo_t* cr, const double* chain, int rows, const Eigen::VectorXd& radii,
                    const Rgb& color) const;
  // Draws the colliders filled in kColliderFill, outlined in kColliderEdge, within the plot
  // (render/scene_colliders.cc): 2D, the exact outline of each (a half-plane: the part of the
  // plot below its line); 3D, each finite shape's silhouette (the hull of its projected surface),
  // far to near, and a half-space's plane within the axes' box. Before the chains: under them.
  void DrawColliders(cairo_t* cr, const std::vector<Collider>& colliders) const;

 private:
  Eigen::Vector3d Lift(const double* point) const;  // 2D points get z = 0
  void DrawAxes3D(cairo_t* cr) const;

  int dim_;
  double ui_;
  Eigen::Vector3d right_, up_, toward_;  // view axes in data space (3D)
  Eigen::Vector3d lo_, hi_;              // bounding box of the data (3D: with a minimum extent)
  double scale_ = 1.0;                   // pixels per data unit
  Eigen::Vector2d origin_;               // pixel of view-plane coordinates (0, 0)
  double depth_lo_ = 0.0, depth_hi_ = 1.0;
  Rect plot_;
  double aspect_ = 1.0;
  double x0_ = 0, x1_ = 1, y0_ = 0, y1_ = 1;  // 2D axis ranges
};

// Colliders filled in kColliderFill and outlined in kColliderEdge, for any view: `pixel` maps a
// world point to pixels; in 3D the shapes are drawn in decreasing `farness` of their centres (a
// half-space first, its plane cut to the box lo..hi), each the convex hull of its projected
// surface (a mesh: the union of its triangles); in 2D (dim 2) each its exact outline, a
// half-plane's cut to the box lo..hi (x, y). ChainScene::DrawColliders and the strand figures
// draw through it.
void DrawColliderShapes(cairo_t* cr, int dim, const std::vector<Collider>& colliders,
                        const std::function<Eigen::Vector2d(const Eigen::Vector3d&)>& pixel,
                        const std::function<double(const Eigen::Vector3d&)>& farness,
                        const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double ui);

// The colliders that stay where they are (no motion), and the keyframed ones at `time` (leader
// steps; flexkin/colliders.h ColliderAt): figures draw the first once, the second per frame.
std::vector<Collider> StaticColliders(const std::vector<Collider>& colliders);
std::vector<Collider> MovingCollidersAt(const std::vector<Collider>& colliders, double time);

}  // namespace flexkin::render
