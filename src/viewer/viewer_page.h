#pragma once

#include <string>
#include <string_view>

namespace flexkin::viewer_internal {

// The bytes of an asset compiled in by embed_assets.cmake, as text.
inline std::string_view AssetText(const unsigned char* data, size_t size) {
  return std::string_view(reinterpret_cast<const char*>(data), size);
}

// A viewer's page, cut where the viewer writes its data.
struct ViewerPage {
  std::string head;  // from <!DOCTYPE html> up to the data
  std::string data;  // the viewer's data part, with its own markers (FLEXKIN_DATA, ...) in it
  std::string tail;  // the scripts and the end of the page
};

// The page both viewers share (viewer_common.html) with one viewer's parts put in: `parts` is the
// viewer's .html (viewer.html, strands_viewer.html), whose parts (each from "<!--part NAME-->" up
// to the next such marker, surrounding white space left off) fill the shared page's slots
// ("<!--slot NAME-->"); the style slot gets one <style> element holding the shared style sheet
// (viewer_common.css) and then `css`, the script slot one <script> element holding the shared
// script (viewer_common.js) and then `js`. Every slot is filled and every part used: the assets are
// compiled in, so a mismatch is a build error, thrown as std::logic_error (the tests write both
// pages: tests/strands_viewer_test.cc), as is a style sheet or script holding "</".
ViewerPage ComposeViewerPage(std::string_view parts, std::string_view css, std::string_view js);

}  // namespace flexkin::viewer_internal
