#pragma once
// What the animations of chains (animation.cc) and of trees (tree_render.cc) share: the frames
// drawn, the even picture size, the pictures piped to ffmpeg over a background drawn once, and
// the counter in the corner.

#include <cairo.h>

#include <functional>
#include <string>
#include <vector>

#include "flexkin/render.h"
#include "render/canvas.h"

namespace flexkin::render {

// The recorded frames an animation of `num_frames` draws: every every_k-th, or with every_k 0 the
// smallest k that draws at most max_frames (SnapshotFrames).
std::vector<int> AnimationFrames(int num_frames, const AnimationOptions& options);

// The animation's picture size: the width, and the height or `auto_height(width)` where it is 0,
// each rounded up to even (H.264 in yuv420p needs even sizes).
void AnimationSize(const AnimationOptions& options, const std::function<int(int)>& auto_height,
                   int* width, int* height);

// Writes `pictures` pictures to `path` (.mp4 or .gif, WriteAnimation's rules): each `background`
// with `moment(d, picture)` drawn over it (`picture` holds the background already), shown so that a
// short run lasts min_seconds, the last held for end_pause; options.progress is called before each.
void WritePictures(const AnimationOptions& options, const Canvas& background, int pictures,
                   const std::function<void(int d, Canvas* picture)>& moment,
                   const std::string& path);

// `text` in the muted colour at the picture's bottom right corner ("step 40 of 120").
void DrawCounter(cairo_t* cr, double ui, int width, int height, const std::string& text);

}  // namespace flexkin::render
