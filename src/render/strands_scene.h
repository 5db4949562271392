#pragma once
// Strands and their scalp in a picture: the orthographic view, its fit to a rectangle, and the
// drawing of one frame in painter's order with the scalp between the hidden and the visible
// pieces of strand. Used by RenderStrandsSnapshot and RenderStrandsAnimation.

#include <cairo.h>

#include <Eigen/Core>
#include <vector>

#include "flexkin/colliders.h"
#include "flexkin/strand_file.h"
#include "render/axes.h"
#include "render/style.h"

namespace flexkin::render {

// The colour of a strand at t = 0 (root) to 1 (tip): deep indigo through plum and rose to amber.
Rgb StrandColor(double t);

// Projected extent: view-plane coordinates (u right, v up) and depth (toward the viewer).
struct ViewBounds {
  double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300, d0 = 1e300, d1 = -1e300;
  bool empty() const { return u0 > u1; }
};

class StrandsView {
 public:
  // 3D: seen from (azimuth, elevation) in degrees; 2D: x right, y up.
  StrandsView(int dim, double azimuth, double elevation);

  int dim() const { return dim_; }
  // A point of dim values as a 3D point (2D: z = 0).
  Eigen::Vector3d Lift(const double* point) const;
  Eigen::Vector2d Plane(const Eigen::Vector3d& q) const { return {q.dot(right_), q.dot(up_)}; }
  double Depth(const Eigen::Vector3d& q) const { return q.dot(toward_); }
  const Eigen::Vector3d& right() const { return right_; }
  const Eigen::Vector3d& up() const { return up_; }
  const Eigen::Vector3d& toward() const { return toward_; }

  // Grows `bounds` by the point / by the scalp of `header` at `pose` (its projected ellipse).
  void Include(const Eigen::Vector3d& q, ViewBounds* bounds) const;
  void IncludeScalp(const ScalpShape& scalp, const BodyPose& pose, ViewBounds* bounds) const;

  // Fits `bounds`, grown by `margin` of its larger side on every side, centred into `area`
  // (pixels) with equal scales. Until then, Pixel is the identity on view-plane coordinates.
  void Fit(const ViewBounds& bounds, double margin, const Rect& area);
  Eigen::Vector2d Pixel(const Eigen::Vector3d& q) const;
  double scale() const { return scale_; }  // pixels per unit of length
  // 0 for the far end of the fitted depth range to 1 for the near end (clamped).
  double Nearness(double depth) const;

 private:
  int dim_;
  Eigen::Vector3d right_, up_, toward_;
  double scale_ = 1.0;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();  // pixel of view-plane (0, 0)
  double d0_ = 0.0, d1_ = 1.0;
};

// Reused between frames: the pieces of strand sorted into depth layers and colour bands.
struct StrandsWork {
  std::vector<std::vector<float>> pieces;  // per (side, layer, band): x, y pairs; NaN = new piece
};

struct StrandsStyle {
  double root_width = 1.0;  // pixels
  double tip_width = 0.45;  // fraction of root_width at the tip
  double ui = 1.0;          // size of the scalp's outline and lines
  Rgb background = kWhite;  // what far strands fade toward
};

// The colliders a strand figure draws beside the scalp, at the body pose `pose` and the time
// `time` (seconds): the body colliders placed by the pose (all but the scalp's own, which the
// scalp's shading shows) and the world colliders (keyframed ones where their motion has them).
std::vector<Collider> FigureColliders(const StrandFileHeader& header, const BodyPose& pose,
                                      double time);

// Grows `bounds` by the surfaces of `colliders` (not half-spaces, which have no end).
void IncludeColliders(const StrandsView& view, const std::vector<Collider>& colliders,
                      ViewBounds* bounds);

// Draws one frame: `points` (P by dim, the file's layout) of the strands `strands` (indices
// into header.offsets), the scalp of `header` at `pose`, and its other colliders
// (FigureColliders), in the collider grey after the pieces of strand on the hidden side of the
// scalp and before the scalp.
void DrawStrandsFrame(cairo_t* cr, const StrandsView& view, const StrandFileHeader& header,
                      const std::vector<int>& strands, const Points& points, const BodyPose& pose,
                      double time, const StrandsStyle& style, StrandsWork* work);

}  // namespace flexkin::render
