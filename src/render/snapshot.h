#pragma once
// The pieces of the snapshot figure that the animation and the tests share.

#include <cairo.h>

#include <optional>
#include <string>
#include <vector>

#include "flexkin/render.h"
#include "render/axes.h"
#include "render/checks.h"
#include "render/legend.h"
#include "render/scene.h"

namespace flexkin::render {

// The part of a width x height picture below the title that the chain scene fills.
Rect SceneArea(int dim, int width, int height);
// The title (bold) and a smaller subtitle, centred at the top.
void DrawTitle(cairo_t* cr, double ui, int width, const std::string& title,
               const std::string& subtitle);
// The leading end (point 0) of every frame: frames by dim values, row-major.
std::vector<double> LeaderPath(const ResultFile& file);
// The fixed base at (x, y): a support (a dark triangle standing on a hatched ground line), about
// 16 ui pixels wide, its apex on the point.
void DrawFixedBase(cairo_t* cr, double x, double y, double ui);
// An arrowhead at half the pixel length of `path` (rows of dim values), pointing along it.
void DrawPathArrow(cairo_t* cr, const ChainScene& scene, const std::vector<double>& path, int dim,
                   const Rgb& color, double size);
// The height of a picture `width` wide whose scene (narrowed by `reserve` ui-pixels on the
// right) shows the data at its aspect ratio (equal scales), 0.4 to 1.2 times the width.
int AutoHeight(const ResultFile& file, int width, double azimuth, double elevation, double reserve);
// The layout of a snapshot figure: what WriteSnapshotFigure draws where. Tests use it to find
// where each point was drawn.
struct SnapshotLayout {
  FigureOptions options;   // with the height chosen when it was 0
  std::vector<int> drawn;  // the frames drawn (SnapshotFrames)
  ChainScene scene;
  std::optional<Legend> legend;  // placed; none without show_legend
};
// The legend goes into the corner of the plot that covers the fewest lines if one covers none;
// otherwise beside the plot, on the right, and the scene gets narrower.
// `look` names the legend's entries (ChainLook(file) by default).
SnapshotLayout LayoutSnapshot(const ResultFile& file, const FigureOptions& options);
SnapshotLayout LayoutSnapshot(const ResultFile& file, const FigureOptions& options,
                              const Look& look);
// The snapshot figure of `file` as `look` names and marks it (WriteSnapshotFigure).
void DrawSnapshotFigure(const ResultFile& file, const Look& look, const FigureOptions& options,
                        const std::string& path);

}  // namespace flexkin::render
