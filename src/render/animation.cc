// WriteAnimation: the frames drawn with cairo, piped raw into ffmpeg, which writes an MP4 (H.264)
// or a GIF to a temporary file that is renamed over the destination only on success.
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/render.h"
#include "render/canvas.h"
#include "render/checks.h"
#include "render/ffmpeg_pipe.h"
#include "render/scene.h"
#include "render/snapshot.h"
#include "render/video.h"

namespace flexkin {
namespace {

using render::ChainScene;

// What stays the same in every picture: title, axes, the whole leader path faintly, the
// initial configuration.
void DrawBackground(render::Canvas* canvas, const ChainScene& scene, const ResultFile& file,
                    const render::Look& look, const std::string& title) {
  cairo_t* cr = canvas->cr();
  const double ui = canvas->ui();
  render::DrawTitle(cr, ui, canvas->width(), render::MainTitle(file, title), look.summary);
  scene.DrawAxes(cr);
  scene.DrawColliders(cr, render::StaticColliders(file.colliders));  // moving ones: DrawMoment
  const std::vector<double> leader = render::LeaderPath(file);
  const int num_frames = static_cast<int>(file.result.frames.size());
  scene.DrawChains(cr, {leader.data()}, {num_frames},
                   {{render::Mix(render::kLeaderPath, render::kWhite, 0.65), 1.2 * ui, true}});
  const Points& first = file.result.frames.front().points;
  scene.DrawChains(cr, {first.data()}, {static_cast<int>(first.rows())},
                   {{render::Mix(render::kInitial, render::kWhite, 0.55), 1.6 * ui, true}});
  if (look.fixed_tail) {  // the base stays where it is bolted: drawn once
    const Eigen::Vector2d base = scene.Pixel(first.row(first.rows() - 1).data());
    render::DrawFixedBase(cr, base.x(), base.y(), ui);
  }
}

// The moving parts of drawn frame `d` (recorded frame drawn[d]): the leader's path so far,
// a few earlier drawn frames fading out, the current configuration and the step counter.
void DrawMoment(render::Canvas* canvas, const ChainScene& scene, const ResultFile& file,
                const std::vector<int>& drawn, size_t d) {
  cairo_t* cr = canvas->cr();
  const double ui = canvas->ui();
  const Frames& frames = file.result.frames;
  const int f = drawn[d];
  const int rows = static_cast<int>(frames[f].points.rows());
  if (AnyMoves(file.colliders)) {
    scene.DrawColliders(cr, render::MovingCollidersAt(file.colliders, double(frames[f].step)));
  }
  if (f > 0) {
    std::vector<double> path;
    for (int g = 0; g <= f; ++g) {
      for (int k = 0; k < file.dim; ++k) path.push_back(frames[g].points(0, k));
    }
    scene.DrawChains(cr, {path.data()}, {f + 1}, {{render::kLeaderPath, 1.8 * ui, false}});
  }
  constexpr int kGhosts = 4;
  std::vector<const double*> chains;
  std::vector<int> chain_rows;
  std::vector<render::ChainStyle> styles;
  for (int g = kGhosts; g >= 1; --g) {
    if (d < static_cast<size_t>(g)) continue;
    chains.push_back(frames[drawn[d - g]].points.data());
    chain_rows.push_back(rows);
    styles.push_back({render::FadeColor(0.15 + 0.6 * (kGhosts - g) / kGhosts), 1.2 * ui, false});
  }
  if (file.link_radii.size() > 0) {
    scene.DrawCapsules(cr, frames[f].points.data(), rows, file.link_radii,
                       render::Mix(render::kFinal, render::kWhite, 0.72));
  }
  chains.push_back(frames[f].points.data());
  chain_rows.push_back(rows);
  styles.push_back({render::kFinal, 2.6 * ui, false});
  scene.DrawChains(cr, chains, chain_rows, styles);
  if (rows <= 41) {
    for (int i = 1; i < rows; ++i) {
      const Eigen::Vector2d p = scene.Pixel(file, f, i);
      render::Disc(cr, p.x(), p.y(), 2.2 * ui, render::kFinal);
    }
  }
  const Eigen::Vector2d head = scene.Pixel(file, f, 0);
  render::Disc(cr, head.x(), head.y(), 4.2 * ui, render::kFinal);
  render::DrawCounter(
      cr, ui, canvas->width(), canvas->height(),
      "step " + std::to_string(frames[f].step) + " of " + std::to_string(file.result.num_steps));
}

void DrawAnimation(const ResultFile& file, const render::Look& look,
                   const AnimationOptions& options, const std::string& path) {
  int width = 0, height = 0;
  render::AnimationSize(
      options,
      [&](int w) { return render::AutoHeight(file, w, options.azimuth, options.elevation, 0.0); },
      &width, &height);
  const std::vector<int> drawn =
      render::AnimationFrames(static_cast<int>(file.result.frames.size()), options);
  const double ui = render::UiScale(width, height);
  const ChainScene scene(file, render::SceneArea(file.dim, width, height), ui, options.azimuth,
                         options.elevation);
  render::Canvas background(ImageFormat::kPng, width, height);
  DrawBackground(&background, scene, file, look, options.title);
  render::WritePictures(
      options, background, static_cast<int>(drawn.size()),
      [&](int d, render::Canvas* picture) {
        DrawMoment(picture, scene, file, drawn, static_cast<size_t>(d));
      },
      path);
}

}  // namespace

void WriteAnimation(const ResultFile& file, const AnimationOptions& options,
                    const std::string& path) {
  ThrowIfAny(options.Validate());
  render::CheckDrawable(file);
  internal::WriteAnimation({file}, options, path);
}

void WriteAnimation(const RobotTrajectoryFile& trajectory, const AnimationOptions& options,
                    const std::string& path) {
  ThrowIfAny(options.Validate());
  const ResultFile result = RobotTrajectoryAsResult(trajectory);
  render::CheckDrawable(result);
  internal::WriteAnimation({result, &trajectory}, options, path);
}

namespace render {

std::vector<int> AnimationFrames(int num_frames, const AnimationOptions& options) {
  const int every_k =
      options.every_k > 0
          ? options.every_k
          : std::max(1, (num_frames - 1 + options.max_frames - 2) / (options.max_frames - 1));
  return SnapshotFrames(num_frames, every_k);
}

void AnimationSize(const AnimationOptions& options, const std::function<int(int)>& auto_height,
                   int* width, int* height) {
  *width = options.width + options.width % 2;
  *height = options.height != 0 ? options.height : auto_height(*width);
  *height += *height % 2;
}

void WritePictures(const AnimationOptions& options, const Canvas& background, int pictures,
                   const std::function<void(int d, Canvas* picture)>& moment,
                   const std::string& path) {
  const VideoFormat format = VideoFormatFromPath(path);
  const int width = background.width(), height = background.height();
  cairo_surface_flush(background.surface());
  Canvas picture(ImageFormat::kPng, width, height);
  // Video frames per picture, so that short runs last min_seconds; the last one also holds
  // for end_pause.
  const int repeat =
      std::max(1, static_cast<int>(std::ceil(options.min_seconds * options.fps / pictures - 1e-9)));
  const int pause = static_cast<int>(std::lround(options.end_pause * options.fps));
  int d = 0;
  WriteVideo(options.ffmpeg, format, width, height, options.fps, options.crf, path,
             [&](VideoPicture* out) {
               if (d == pictures) return false;
               if (options.progress) options.progress(d, pictures);
               cairo_t* cr = picture.cr();
               cairo_set_source_surface(cr, background.surface(), 0, 0);
               cairo_paint(cr);
               moment(d, &picture);
               out->pixels = picture.Pixels();
               out->stride = picture.Stride();
               out->copies = repeat + (d == pictures - 1 ? pause : 0);
               ++d;
               return true;
             });
}

void DrawCounter(cairo_t* cr, double ui, int width, int height, const std::string& text) {
  TextStyle counter;
  counter.size = 12 * ui;
  counter.halign = Align::kEnd;
  counter.valign = Align::kEnd;
  counter.color = kMuted;
  DrawText(cr, width - 10 * ui, height - 8 * ui, text, counter);
}

}  // namespace render

void internal::WriteAnimation(const CheckedDrawing& drawing, const AnimationOptions& options,
                              const std::string& path) {
  DrawAnimation(drawing.result, render::LookOf(drawing), options, path);
}

}  // namespace flexkin
