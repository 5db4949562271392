#pragma once
// A cairo drawing surface of one of the image formats, written to memory and then to a file
// all-or-nothing, and the text and line helpers every picture uses.

#include <cairo.h>

#include <string>

#include "flexkin/render.h"
#include "render/style.h"

namespace flexkin::render {

class Canvas {
 public:
  // A white canvas of `width` x `height` pixels. Raster canvases (kPng, and the animation's) are
  // RGB24 image surfaces; SVG and PDF are recorded into memory.
  Canvas(ImageFormat format, int width, int height);
  ~Canvas();
  Canvas(const Canvas&) = delete;
  Canvas& operator=(const Canvas&) = delete;

  cairo_t* cr() const { return cr_; }
  cairo_surface_t* surface() const { return surface_; }
  int width() const { return width_; }
  int height() const { return height_; }
  // Size of text, lines and markers relative to a 960 x 720 picture: pictures of other sizes
  // keep their proportions. 0.7 to 3.
  double ui() const { return ui_; }

  // Fills the canvas white.
  void Clear();
  // Finishes the drawing and returns the file's bytes (SVG, PDF or PNG). Throws
  // std::runtime_error if cairo reports an error.
  std::string Finish();
  // Image surfaces: the pixels, `stride` bytes per row, one native-endian 32-bit word per pixel
  // (0xXXRRGGBB). Flushes pending drawing first.
  const unsigned char* Pixels();
  int Stride() const;

 private:
  ImageFormat format_;
  int width_, height_;
  double ui_;
  std::string bytes_;  // what a vector surface has written
  cairo_surface_t* surface_ = nullptr;
  cairo_t* cr_ = nullptr;
};

// Finishes `canvas` and writes it to `path`, atomically (WriteFileAtomically).
void SaveCanvas(Canvas* canvas, const std::string& path);

// The size of text, lines and markers of a width x height picture relative to 960 x 720
// (pictures wider than 4:3 get the size of a 4:3 one as wide).
double UiScale(int width, int height);

enum class Align { kStart, kCenter, kEnd };

struct TextStyle {
  double size = 13.0;  // font size in pixels (before ui scaling: the caller scales)
  Rgb color = kInk;
  bool bold = false;
  Align halign = Align::kStart;
  Align valign = Align::kCenter;  // kStart = top, kEnd = baseline-bottom
  double angle = 0.0;             // radians, counter-clockwise on screen
};

// Draws `text` (UTF-8) anchored at (x, y) pixels. Returns its width in pixels.
double DrawText(cairo_t* cr, double x, double y, const std::string& text, const TextStyle& style);
// The width of `text` in pixels, as DrawText would draw it.
double TextWidth(cairo_t* cr, const std::string& text, const TextStyle& style);

void SetColor(cairo_t* cr, const Rgb& color, double alpha = 1.0);
// Strokes a straight segment.
void Line(cairo_t* cr, double x0, double y0, double x1, double y1, const Rgb& color, double width);
// A filled disc, optionally outlined.
void Disc(cairo_t* cr, double x, double y, double radius, const Rgb& fill);
void Ring(cairo_t* cr, double x, double y, double radius, const Rgb& color, double width);

}  // namespace flexkin::render
