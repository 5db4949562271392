#pragma once
// The pieces of the snapshot figure that the animation and the tests share.

#include <cairo.h>

#include <string>
#include <vector>

#include "flexkin/render.h"
#include "render/axes.h"
#include "render/scene.h"

namespace flexkin::render {

// The part of a width x height picture below the title that the chain scene fills.
Rect SceneArea(int dim, int width, int height);
// The title (bold) and a smaller subtitle, centred at the top.
void DrawTitle(cairo_t* cr, double ui, int width, const std::string& title,
               const std::string& subtitle);
// The leading end (point 0) of every frame: frames by dim values, row-major.
std::vector<double> LeaderPath(const ResultFile& file);
// An arrowhead at half the pixel length of `path` (rows of dim values), pointing along it.
void DrawPathArrow(cairo_t* cr, const ChainScene& scene, const std::vector<double>& path, int dim,
                   const Rgb& color, double size);
// The height of a figure `width` pixels wide whose scene shows the data at its aspect ratio,
// between 0.4 and 1.2 times the width.
int AutoHeight(const ResultFile& file, const FigureOptions& options);
// The scene a figure with `options` draws in: tests use it to find where each point was drawn.
// `options.height` must be resolved (not 0).
ChainScene MakeSnapshotScene(const ResultFile& file, const FigureOptions& options);

}  // namespace flexkin::render
