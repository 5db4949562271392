#pragma once
// A PNG file's pixels for the tests of pictures (render_test, strands_render_test,
// tree_draw_test), read with cairo: for programs that link flexkin_render.

#include <cairo.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace flexkin::render_test {

// A PNG file's pixels, read with cairo (empty if it cannot be read).
struct Image {
  int width = 0, height = 0;
  std::vector<uint32_t> pixels;  // 0xXXRRGGBB

  // (red, green, blue) of the pixel at (x, y), 0 to 255 each.
  std::array<int, 3> Rgb(int x, int y) const {
    const uint32_t p = pixels[static_cast<size_t>(y) * width + x];
    return {static_cast<int>((p >> 16) & 255), static_cast<int>((p >> 8) & 255),
            static_cast<int>(p & 255)};
  }
};

inline Image ReadPng(const std::string& path) {
  Image image;
  cairo_surface_t* s = cairo_image_surface_create_from_png(path.c_str());
  if (cairo_surface_status(s) == CAIRO_STATUS_SUCCESS) {
    cairo_surface_flush(s);
    image.width = cairo_image_surface_get_width(s);
    image.height = cairo_image_surface_get_height(s);
    const unsigned char* data = cairo_image_surface_get_data(s);
    const int stride = cairo_image_surface_get_stride(s);
    for (int y = 0; y < image.height; ++y) {
      const auto* row = reinterpret_cast<const uint32_t*>(data + static_cast<size_t>(y) * stride);
      image.pixels.insert(image.pixels.end(), row, row + image.width);
    }
  }
  cairo_surface_destroy(s);
  return image;
}

}  // namespace flexkin::render_test
