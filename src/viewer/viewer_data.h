#pragma once

#include <string>

#include "viewer/viewer.h"

namespace flexkin::viewer_internal {

// The data the viewer page shows, as one line of JSON (layout in viewer.js, loadData): the
// result's frames as one flat array of coordinates, per-frame steps and link-length errors, the
// metrics and the page options. Strings have '<', '>' and '&' escaped as \u003c and so on, so the
// text can sit inside a <script> element without closing it. Throws InputError as
// WriteViewerHtml (src/viewer/viewer.h) for a result that cannot be shown; `options` must be
// valid.
std::string ViewerDataJson(const ResultFile& result, const ViewerOptions& options);

}  // namespace flexkin::viewer_internal
