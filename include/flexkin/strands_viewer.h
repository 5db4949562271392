#pragma once

#include <string>

#include "flexkin/error.h"
#include "flexkin/strand_file.h"

namespace flexkin {

// The viewer for many strands (hair, fur): one self-contained HTML page per strand file
// (docs/viewer.md, "Many strands"). The page draws every strand with WebGL2 in one draw call, or,
// where WebGL runs in software and the links are many, with its own line drawing in JavaScript; its
// script and style sheet are compiled into the library and the frames are embedded compactly:
// each coordinate as a 16-bit code within the frame's bounding box, delta-coded over frames,
// zlib-compressed and base64-encoded. It opens offline and fetches nothing. Library target
// flexkin_viewer.

struct StrandsViewerOptions {
  // Page title and heading. Empty: the file's name, or "flexkin strands" if it has none.
  std::string title;
  // Wall time in seconds for one play-through of all frames at speed 1x (the speed control
  // scales it). 0: the motion's own duration (its last time less its first, or frames / fps),
  // so 1x is real time. Else > 0, at most 86400.
  double playback_seconds = 0.0;
  // Start playing as soon as the page is open.
  bool autoplay = true;
  // Start again from the first frame after the last one; otherwise stop at the last one.
  bool loop = true;
  // Initial 3D view: azimuth of the direction from the strands to the eye about the z axis from
  // the x axis, degrees (any finite value), and its elevation above the x-y plane, degrees in
  // [-90, 90]. Unused in 2D.
  double azimuth = -60.0;
  double elevation = 20.0;
  // Frames embedded, at most: the file's frames evenly subsampled, the first and the last always
  // among them. >= 1. 10,000 strands of 32 links take about 0.2 to 1 MB per frame in the page
  // (depending on how much they move) and 2.6 MB per frame of browser memory.
  int max_frames = 120;
  // Strands embedded, at most: 0 for all, else an evenly spaced subset of the file's strands.
  int max_strands = 0;
  // Largest page, in megabytes (1e6 bytes), > 0: WriteStrandsViewerHtml refuses a page that would
  // be larger (naming max_frames and the estimated size) rather than write a page no browser opens.
  double max_megabytes = 200.0;
  // Largest memory the page's decoded frames take in the browser, in megabytes (8 bytes per point
  // per frame), > 0; checked the same way.
  double max_memory_megabytes = 1024.0;

  // Every problem (empty if valid), each naming its member ("max_frames").
  Problems Validate() const;
};

// Writes the viewer page for the strand file `reader` has open to `path`, atomically (written whole
// or not at all, an existing file is left untouched on any error), reading the frames once, in
// order, one at a time (`reader` must not have read any). Throws InputError for invalid options
// ("options.<name>"), a page over the size limits ("options.max_frames", with the estimated size),
// or data that cannot be shown: dim not 2 or 3 ("dim"), no frames ("frames"), a non-finite number
// ("frames[3].points[2][1]", "frames[0].pose", "scalp.radii", "report.max_length_error"). Throws
// std::system_error if the file cannot be written or the strand file cannot be read.
void WriteStrandsViewerHtml(StrandFileReader* reader, const StrandsViewerOptions& options,
                            const std::string& path);

namespace internal {
// The same with options Draw (flexkin/draw.h) has checked: not checked again.
void WriteStrandsViewerHtml(StrandFileReader* reader, const StrandsViewerOptions& options,
                            const std::string& path);
}  // namespace internal

}  // namespace flexkin
