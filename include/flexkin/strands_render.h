#pragma once
// Pictures of a strand file (include/flexkin/strand_file.h, docs/rendering.md "Strand files"):
// a snapshot figure of every strand at a few moments of the run, side by side (SVG, PNG, PDF),
// and an animation (MP4, GIF). Both read the file frame by frame: at most the few frames of the
// figure are held, never the run.
//
// The strands are seen by an orthographic view from (azimuth, elevation) (2D files: as they
// are), the scalp (sphere or ellipsoid, moved by each frame's body pose) shaded, with its
// equator and prime meridian so that its turning shows. Each strand is coloured from its root
// (dark) to its tip (light) and thins toward the tip; farther strands fade into the background.
// Drawing is in painter's order: the pieces of strand on the hidden side of the scalp first, far
// to near, then the scalp, then the rest, far to near.
//
// Errors: InputError for an invalid option (field: the member's name, e.g. "max_strands"), a
// file that cannot be drawn (field "frames" for none, "frames[f].points[i][k]" for a non-finite
// point, "frames[f].pose" for a non-finite pose, "scalp.radii" for a scalp without size);
// std::system_error for a file that cannot be written; std::runtime_error when ffmpeg is missing
// or fails. Every writer is all-or-nothing: an existing destination is left untouched on error.

#include <cstdint>
#include <functional>
#include <string>

#include "flexkin/error.h"
#include "flexkin/strand_file.h"

namespace flexkin {

struct StrandsRenderOptions {
  // Size in pixels (SVG px; PDF points), 64 to 8192; 0 = automatic. Width: figure 420 per
  // panel, animation 960. Height: from the projected extent of the strands, 0.3 to 1.5 times
  // the width (the animation's is rounded up to even, as H.264 in yuv420p needs).
  int width = 0;
  int height = 0;
  // Figure: panels side by side, 1 to 8: the first frame, the moments the body moves fastest
  // (one in each equal stretch of the run between), and the last frame. 1 = the last frame
  // only. Typical: 4.
  int panels = 4;
  // 3D view (orthographic): azimuth in degrees about the z axis from the +x axis (any value);
  // elevation in degrees above the x-y plane, -90 to 90. 2D files are drawn as they are.
  double azimuth = -60.0;
  double elevation = 20.0;
  // The title's first line; "" = the run's name (or "flexkin strands" without one). A second,
  // smaller line gives the method, strands, links and frames.
  std::string title;
  // Draw at most this many strands, spread evenly over the file's (strand i * S / max_strands);
  // 0 = all. Typical: 0, or 2000 for a quick look at a big groom.
  int max_strands = 0;
  // Width of a strand at its root in pixels, 0.1 to 20; it thins to 45% at the tip. 0 =
  // automatic: thinner the more strands are drawn (about 1.8 px for 300 strands, 0.9 for 5,000
  // in a 960 px picture).
  double line_width = 0.0;

  // Animation only.
  // Frames per second of the video, 1 to 120; 0 = real time: the file's fps over every_k.
  int fps = 0;
  // Draw recorded frames 0, k, 2k, ... and the last one. 0 = automatic: the smallest k that
  // draws at most `max_frames` frames.
  int every_k = 0;
  // Upper bound of the pictures when every_k = 0, >= 2. Typical: 300.
  int max_frames = 300;
  // The last picture is held this long at the end, in seconds, 0 to 60. Typical: 1.
  double end_pause = 1.0;
  // The ffmpeg program: a name looked up in PATH or a path.
  std::string ffmpeg = "ffmpeg";
  // H.264 constant rate factor for MP4, 0 (lossless) to 51. Typical: 20.
  int crf = 20;
  // Called before each picture of an animation is drawn (done of total pictures) and, for a
  // figure, after each frame read (done of total frames); empty = none. It may throw to stop the
  // writing, as AnimationOptions::progress.
  std::function<void(int64_t done, int64_t total)> progress;

  // Every problem (empty if valid), each naming its member ("max_strands").
  Problems Validate() const;
};

// Writes the snapshot figure of the strands read from `reader` to `path` (.svg, .png or .pdf,
// by extension). Reads every frame with reader->Next: give it a reader that has read none.
void RenderStrandsSnapshot(StrandFileReader* reader, const StrandsRenderOptions& options,
                           const std::string& path);

// Writes the animation of the strands read from `reader` to `path`: ".mp4" (H.264, yuv420p) or
// ".gif", by extension. Each frame is drawn as it is read and piped raw into ffmpeg, which writes
// a temporary file renamed over `path` only on success. Give it a reader that has read none.
void RenderStrandsAnimation(StrandFileReader* reader, const StrandsRenderOptions& options,
                            const std::string& path);

namespace internal {
// The same with options Draw (flexkin/draw.h) has checked: not checked again.
void RenderStrandsSnapshot(StrandFileReader* reader, const StrandsRenderOptions& options,
                           const std::string& path);
void RenderStrandsAnimation(StrandFileReader* reader, const StrandsRenderOptions& options,
                            const std::string& path);
}  // namespace internal

}  // namespace flexkin
