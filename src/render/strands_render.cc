// RenderStrandsSnapshot and RenderStrandsAnimation: strand files read frame by frame, drawn with
// the scene of strands_scene.h; the figure through SaveCanvas, the animation piped into ffmpeg.
#include "flexkin/strands_render.h"

#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "flexkin/render.h"
#include "render/canvas.h"
#include "render/checks.h"
#include "render/ffmpeg_pipe.h"
#include "render/snapshot.h"
#include "render/strands_scene.h"

namespace flexkin {
namespace {

using render::StrandsView;
using render::ViewBounds;

// 0 (automatic) or a value in [lo, hi].
void CheckAutoRange(const char* field, double value, double lo, double hi, bool integer,
                    Problems* problems) {
  if (value == 0.0) return;
  Problems range;
  render::CheckRange(field, value, lo, hi, integer, &range);
  for (Problem& p : range) {
    p.expected = "0 (automatic) or " + p.expected;
    p.message = p.value + " is not valid; expected " + p.expected;
    problems->push_back(p);
  }
}

// 1234567 -> "1,234,567".
std::string Thousands(long long n) {
  std::string digits = std::to_string(n), out;
  for (size_t k = 0; k < digits.size(); ++k) {
    if (k > 0 && (digits.size() - k) % 3 == 0) out += ',';
    out += digits[k];
  }
  return out;
}

std::string Seconds(double t) {
  char text[32];
  std::snprintf(text, sizeof text, "t = %.2f s", t);
  return text;
}

// Angle of the rotation a b^T in degrees.
double AngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const double c = ((a * b.transpose()).trace() - 1.0) / 2.0;
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / M_PI;
}

// What every picture of a file needs: the header's checks, the strands drawn, the titles.
struct Drawing {
  const StrandFileHeader* header = nullptr;
  std::vector<int> strands;  // indices of the strands drawn
  std::string title, subtitle;
  int num_frames = 0;
};

// `options` valid (checked by the caller, once).
Drawing Prepare(const StrandFileReader& reader, const StrandsRenderOptions& options) {
  Drawing d;
  const StrandFileHeader& h = reader.header();
  d.header = &h;
  d.num_frames = static_cast<int>(h.num_frames);
  const int s = h.num_strands();
  if (d.num_frames < 1 || s < 1) throw InputError("frames", "no frames; nothing to draw");
  if (h.dim != 2 && h.dim != 3)
    throw InputError("dim", std::to_string(h.dim) + " is not valid; expected 2 or 3");
  if (!h.scalp.shape.empty()) {
    const Eigen::Vector3d r = h.scalp.radii.head(3);
    const bool ok = r.allFinite() && r.head(h.dim).minCoeff() > 0.0 &&
                    (h.dim == 2 || r.z() > 0.0) && h.scalp.center.allFinite();
    if (!ok) throw InputError("scalp.radii", "the scalp needs finite, positive radii");
  }
  const std::vector<StrandFrame>& info = reader.frame_info();
  for (size_t f = 0; f < info.size(); ++f) {
    if (!info[f].pose.rotation.allFinite() || !info[f].pose.translation.allFinite())
      throw InputError("frames[" + std::to_string(f) + "].pose", "not finite");
  }
  const int drawn = options.max_strands > 0 ? std::min(options.max_strands, s) : s;
  for (int k = 0; k < drawn; ++k) {
    d.strands.push_back(static_cast<int>(static_cast<long long>(k) * s / drawn));
  }
  d.title = !options.title.empty() ? options.title : !h.name.empty() ? h.name : "flexkin strands";
  int min_links = 1 << 30, max_links = 0;
  for (int i = 0; i < s; ++i) {
    const int n = static_cast<int>(h.offsets[i + 1] - h.offsets[i] - 1);
    min_links = std::min(min_links, n);
    max_links = std::max(max_links, n);
  }
  char fps[32];
  std::snprintf(fps, sizeof fps, "%g", h.fps);
  d.subtitle = StrandMotionName(h) + " \u00b7 " + Thousands(s) + (s == 1 ? " strand" : " strands");
  if (drawn < s) d.subtitle += " (" + Thousands(drawn) + " drawn)";
  d.subtitle += " \u00b7 " + std::to_string(min_links) +
                (min_links == max_links ? "" : "\u2013" + std::to_string(max_links)) +
                (max_links == 1 ? " link" : " links") + " \u00b7 " + Thousands(d.num_frames) +
                (d.num_frames == 1 ? " frame" : " frames") + " at " + fps + " fps";
  return d;
}

// Throws InputError naming the first non-finite coordinate of a drawn strand of frame `f`.
void CheckFinite(const Drawing& d, int f, const Points& points) {
  for (const int i : d.strands) {
    for (int64_t r = d.header->offsets[i]; r < d.header->offsets[i + 1]; ++r) {
      for (int k = 0; k < d.header->dim; ++k) {
        if (!std::isfinite(points(r, k))) {
          throw InputError("frames[" + std::to_string(f) + "].points[" + std::to_string(r) + "][" +
                               std::to_string(k) + "]",
                           "not finite");
        }
      }
    }
  }
}

void IncludeFrame(const Drawing& d, const StrandsView& view, const Points& points,
                  const BodyPose& pose, double time, ViewBounds* bounds) {
  for (const int i : d.strands) {
    for (int64_t r = d.header->offsets[i]; r < d.header->offsets[i + 1]; ++r) {
      view.Include(view.Lift(points.row(r).data()), bounds);
    }
  }
  view.IncludeScalp(d.header->scalp, pose, bounds);
  render::IncludeColliders(view, render::FigureColliders(*d.header, pose, time), bounds);
}

render::StrandsStyle StyleFor(const Drawing& d, const StrandsRenderOptions& options, double ui) {
  render::StrandsStyle style;
  style.ui = ui;
  style.root_width =
      options.line_width > 0.0
          ? options.line_width
          : ui * std::clamp(1.8 * std::pow(300.0 / d.strands.size(), 0.25), 0.6, 2.4);
  return style;
}

// The frames of the figure's panels: the first, the last, and between them one moment of each of
// the most telling motions of the body. The run is cut into motions where the body rests or its
// rotation (or, without one, its translation) changes direction; a motion's moment is its frame
// of the largest speed times the distance moved since the motion began (late in a sustained
// turn, when the strands trail most). Motions are taken by that score, a motion about an axis
// already shown counting a quarter (so a nod gets in beside the turns), and drawn in time order.
std::vector<int> PanelFrames(const std::vector<StrandFrame>& info, int panels) {
  const int n = static_cast<int>(info.size());
  if (panels == 1 || n == 1) return {n - 1};
  if (panels == 2 || n == 2) return {0, n - 1};
  struct Motion {
    int best = -1;
    double score = 0.0;
    Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  };
  std::vector<Motion> motions;
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  double moved = 0.0;
  for (int f = 1; f + 1 < n; ++f) {
    const Eigen::AngleAxisd turn(info[f].pose.rotation * info[f - 1].pose.rotation.transpose());
    Eigen::Vector3d velocity = turn.axis() * turn.angle() * 180.0 / M_PI;
    if (velocity.norm() < 1e-9) velocity = info[f].pose.translation - info[f - 1].pose.translation;
    const double speed = velocity.norm();
    if (speed < 1e-9) {
      previous.setZero();
      continue;
    }
    const Eigen::Vector3d axis = velocity / speed;
    if (previous.isZero() || axis.dot(previous) < 0.7) {
      motions.emplace_back();
      moved = 0.0;
    }
    previous = axis;
    moved += speed;
    if (speed * moved > motions.back().score) motions.back() = {f, speed * moved, axis};
  }
  std::vector<int> frames = {0, n - 1};
  std::vector<Eigen::Vector3d> shown;
  std::vector<bool> taken(motions.size(), false);
  for (int p = 0; p < panels - 2; ++p) {
    int pick = -1;
    double best = 0.0;
    for (size_t m = 0; m < motions.size(); ++m) {
      if (taken[m]) continue;
      bool seen = false;
      for (const Eigen::Vector3d& a : shown) seen |= std::abs(a.dot(motions[m].axis)) > 0.7;
      const double score = motions[m].score * (seen ? 0.25 : 1.0);
      if (score > best) {
        best = score;
        pick = static_cast<int>(m);
      }
    }
    if (pick < 0) {  // fewer motions than panels: evenly spaced frames
      frames.push_back(static_cast<int>(static_cast<long long>(p + 1) * (n - 1) / (panels - 1)));
      continue;
    }
    taken[pick] = true;
    shown.push_back(motions[pick].axis);
    frames.push_back(motions[pick].best);
  }
  std::sort(frames.begin(), frames.end());
  frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  return frames;
}

}  // namespace

Problems StrandsRenderOptions::Validate() const {
  Problems problems;
  CheckAutoRange("width", width, 64, 8192, true, &problems);
  CheckAutoRange("height", height, 64, 8192, true, &problems);
  render::CheckRange("panels", panels, 1, 8, true, &problems);
  if (!std::isfinite(azimuth)) {
    problems.emplace_back("azimuth", FormatNumber(azimuth) + " is not valid; expected a number",
                          FormatNumber(azimuth), "a number");
  }
  render::CheckRange("elevation", elevation, -90, 90, false, &problems);
  render::CheckRange("max_strands", max_strands, 0, 1e9, true, &problems);
  CheckAutoRange("line_width", line_width, 0.1, 20, false, &problems);
  CheckAutoRange("fps", fps, 1, 120, true, &problems);
  render::CheckRange("every_k", every_k, 0, 1e9, true, &problems);
  render::CheckRange("max_frames", max_frames, 2, 1e9, true, &problems);
  render::CheckRange("end_pause", end_pause, 0, 60, false, &problems);
  render::CheckRange("crf", crf, 0, 51, true, &problems);
  if (ffmpeg.empty()) {
    problems.emplace_back("ffmpeg", "\"\" is not valid; expected a program name or path", "",
                          "a program name or path");
  }
  return problems;
}

void RenderStrandsSnapshot(StrandFileReader* reader, const StrandsRenderOptions& options,
                           const std::string& path) {
  ThrowIfAny(options.Validate());
  internal::RenderStrandsSnapshot(reader, options, path);
}

void RenderStrandsAnimation(StrandFileReader* reader, const StrandsRenderOptions& options,
                            const std::string& path) {
  ThrowIfAny(options.Validate());
  internal::RenderStrandsAnimation(reader, options, path);
}

void internal::RenderStrandsSnapshot(StrandFileReader* reader, const StrandsRenderOptions& options,
                                     const std::string& path) {
  const ImageFormat format = ImageFormatFromPath(path);
  const Drawing d = Prepare(*reader, options);
  const std::vector<StrandFrame>& info = reader->frame_info();
  const std::vector<int> panels = PanelFrames(info, std::min(options.panels, d.num_frames));
  const int n = static_cast<int>(panels.size());

  // Read the run, keeping the panels' frames.
  std::vector<StrandFrame> kept(n);
  StrandFrame frame;
  for (int f = 0, next = 0; next < n && reader->Next(&frame); ++f) {
    if (options.progress) options.progress(f, d.num_frames);
    if (f != panels[next]) continue;
    CheckFinite(d, f, frame.points);
    kept[next++] = frame;
  }
  if (kept.back().points.rows() == 0)
    throw InputError("frames", "the file ended before frame " + std::to_string(panels.back()));

  StrandsView view(d.header->dim, options.azimuth, options.elevation);
  ViewBounds bounds;
  for (const StrandFrame& k : kept) IncludeFrame(d, view, k.points, k.pose, k.time, &bounds);
  constexpr double kMargin = 0.03;

  // A row of panels under the title, each with its time below it.
  const int width = options.width != 0 ? options.width : std::clamp(420 * n, 640, 8192);
  const double panel_w = static_cast<double>(width) / n;
  const double ui = std::min(render::UiScale(width, 0), 1.25);
  const double top = 66 * ui, bottom = 30 * ui, pad = 6 * ui;
  int height = options.height;
  if (height == 0) {
    const double size = std::max(bounds.u1 - bounds.u0, bounds.v1 - bounds.v0);
    const double aspect = (bounds.v1 - bounds.v0 + 2 * kMargin * size) /
                          std::max(bounds.u1 - bounds.u0 + 2 * kMargin * size, 1e-12);
    height = static_cast<int>(std::lround(top + bottom + (panel_w - 2 * pad) * aspect));
    height = std::clamp(height, std::max(64, static_cast<int>(0.2 * width)),
                        std::min(8192, static_cast<int>(1.5 * width)));
  }
  render::Canvas canvas(format, width, height);
  cairo_t* cr = canvas.cr();
  render::DrawTitle(cr, ui, width, d.title, d.subtitle);
  const double panel_ui = render::UiScale(static_cast<int>(panel_w), height);
  const render::StrandsStyle style = StyleFor(d, options, panel_ui);
  render::StrandsWork work;
  render::TextStyle label;
  label.size = 12 * ui;
  label.color = render::kMuted;
  label.halign = render::Align::kCenter;
  label.valign = render::Align::kEnd;
  for (int p = 0; p < n; ++p) {
    const render::Rect area{p * panel_w + pad, top, panel_w - 2 * pad, height - top - bottom};
    view.Fit(bounds, kMargin, area);
    DrawStrandsFrame(cr, view, *d.header, d.strands, kept[p].points, kept[p].pose, kept[p].time,
                     style, &work);
    std::string text = Seconds(kept[p].time);
    const double angle = AngleBetween(kept[p].pose.rotation, info.front().pose.rotation);
    if (panels[p] > 0 && angle >= 0.5) {
      char turned[48];
      std::snprintf(turned, sizeof turned, " \u00b7 turned %.0f\u00b0", angle);
      text += turned;
    }
    render::DrawText(cr, area.x + area.w / 2, height - 10 * ui, text, label);
    if (p > 0) render::Line(cr, p * panel_w, top, p * panel_w, height - 8 * ui, render::kGrid, 1.0);
  }
  render::SaveCanvas(&canvas, path);
}

void internal::RenderStrandsAnimation(StrandFileReader* reader, const StrandsRenderOptions& options,
                                      const std::string& path) {
  const render::VideoFormat video = render::VideoFormatFromPath(path);
  const Drawing d = Prepare(*reader, options);
  const std::vector<StrandFrame>& info = reader->frame_info();
  const int num_frames = d.num_frames;
  const int every_k =
      options.every_k > 0
          ? options.every_k
          : std::max(1, (num_frames - 1 + options.max_frames - 2) / (options.max_frames - 1));
  const std::vector<int> drawn = SnapshotFrames(num_frames, every_k);
  const int fps = options.fps > 0
                      ? options.fps
                      : std::clamp(static_cast<int>(std::lround(d.header->fps / every_k)), 1, 120);

  StrandFrame frame;
  if (!reader->Next(&frame)) throw InputError("frames", "no frames; nothing to draw");
  CheckFinite(d, 0, frame.points);
  // The fit holds for the whole video: the first frame moved rigidly with the body to every
  // drawn pose (strands that trail stay near that), and the scalp at each.
  StrandsView view(d.header->dim, options.azimuth, options.elevation);
  ViewBounds bounds;
  const BodyPose& rest = frame.pose;
  std::vector<Eigen::Vector3d> sample;
  for (const int i : d.strands) {
    const int64_t a = d.header->offsets[i], b = d.header->offsets[i + 1] - 1;
    for (const int64_t r : {a, (a + b) / 2, b}) {
      sample.push_back(rest.rotation.transpose() *
                       (view.Lift(frame.points.row(r).data()) - rest.translation));
    }
  }
  for (const int f : drawn) {
    const BodyPose& pose = info[f].pose;
    for (const Eigen::Vector3d& q : sample)
      view.Include(pose.rotation * q + pose.translation, &bounds);
    view.IncludeScalp(d.header->scalp, pose, &bounds);
    render::IncludeColliders(view, render::FigureColliders(*d.header, pose, info[f].time), &bounds);
  }
  constexpr double kMargin = 0.06;
  const int width = (options.width != 0 ? options.width : 960) + (options.width % 2);
  const double ui = render::UiScale(width, 0);
  const double top = 66 * ui, bottom = 8 * ui;
  int height = options.height;
  if (height == 0) {
    const double size = std::max(bounds.u1 - bounds.u0, bounds.v1 - bounds.v0);
    const double aspect = (bounds.v1 - bounds.v0 + 2 * kMargin * size) /
                          std::max(bounds.u1 - bounds.u0 + 2 * kMargin * size, 1e-12);
    height = static_cast<int>(std::lround(top + bottom + (width - 16 * ui) * aspect));
    height = std::clamp(height, static_cast<int>(0.3 * width), static_cast<int>(1.5 * width));
  }
  height = std::clamp(height + height % 2, 64, 8192);
  view.Fit(bounds, kMargin, {8 * ui, top, width - 16 * ui, height - top - bottom});
  const render::StrandsStyle style = StyleFor(d, options, render::UiScale(width, height));

  render::Canvas background(ImageFormat::kPng, width, height);
  render::DrawTitle(background.cr(), ui, width, d.title, d.subtitle);
  cairo_surface_flush(background.surface());
  render::Canvas picture(ImageFormat::kPng, width, height);
  render::StrandsWork work;
  render::TextStyle counter;
  counter.size = 12 * ui;
  counter.halign = render::Align::kEnd;
  counter.valign = render::Align::kEnd;
  counter.color = render::kMuted;

  const int pause = static_cast<int>(std::lround(options.end_pause * fps));
  int f = 0;
  size_t k = 0;
  render::WriteVideo(
      options.ffmpeg, video, width, height, fps, options.crf, path, [&](render::VideoPicture* out) {
        if (k == drawn.size()) return false;
        if (options.progress)
          options.progress(static_cast<int64_t>(k), static_cast<int64_t>(drawn.size()));
        while (f < drawn[k]) {
          if (!reader->Next(&frame))
            throw InputError("frames", "the file ended before frame " + std::to_string(drawn[k]));
          ++f;
        }
        if (f > 0) CheckFinite(d, f, frame.points);
        cairo_t* cr = picture.cr();
        cairo_set_source_surface(cr, background.surface(), 0, 0);
        cairo_paint(cr);
        DrawStrandsFrame(cr, view, *d.header, d.strands, frame.points, frame.pose, frame.time,
                         style, &work);
        render::DrawText(cr, width - 10 * ui, height - 8 * ui, Seconds(frame.time), counter);
        out->pixels = picture.Pixels();
        out->stride = picture.Stride();
        out->copies = 1 + (k + 1 == drawn.size() ? pause : 0);
        ++k;
        return true;
      });
}

}  // namespace flexkin
