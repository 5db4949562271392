#pragma once
// An ffmpeg process fed raw video frames on its standard input, and the pieces every animation
// writer shares: the format by extension, ffmpeg's command line, the temporary file and its
// renaming into place.

#include <sys/types.h>

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace flexkin::render {

class FfmpegPipe {
 public:
  // Starts `program` (looked up in PATH unless it contains a '/') with `args`. Its standard
  // input is a socket this object writes to (a socket, not a pipe, so that writing after ffmpeg
  // has died returns EPIPE instead of raising SIGPIPE in the caller); its standard output goes
  // to /dev/null and its standard error to an unlinked temporary file read by Finish. Throws
  // std::runtime_error if the program cannot be started (e.g. not installed).
  FfmpegPipe(const std::string& program, const std::vector<std::string>& args);
  // Kills and reaps the process if Finish was not called.
  ~FfmpegPipe();
  FfmpegPipe(const FfmpegPipe&) = delete;
  FfmpegPipe& operator=(const FfmpegPipe&) = delete;

  // Writes `size` bytes to ffmpeg's input; false if ffmpeg stopped reading (it failed).
  bool Write(const void* data, size_t size);
  // Closes ffmpeg's input and waits for it. "" if it exited with status 0 and reported no write
  // error, otherwise the reason: the exit status or signal and the last lines ffmpeg wrote to
  // its standard error.
  std::string Finish();

 private:
  pid_t pid_ = -1;
  int input_ = -1;   // our end of ffmpeg's standard input
  int errors_ = -1;  // the temporary file holding ffmpeg's standard error
};

enum class VideoFormat { kMp4, kGif };

// ".mp4" or ".gif" (case-insensitive); InputError (field "path") for any other extension.
VideoFormat VideoFormatFromPath(const std::string& path);
// The ffmpeg command line: raw frames of width x height in (cairo's RGB24 words), the video out
// to `output` (MP4: H.264 at `crf`, yuv420p; GIF: one palette made from all frames, looping).
std::vector<std::string> FfmpegArgs(VideoFormat format, int width, int height, int fps, int crf,
                                    const std::string& output);
// A temporary file next to `path` (".NAME.tmp-XXXXXX"), created empty. Throws std::system_error.
std::string TemporaryNextTo(const std::string& path);
// Gives `temp` the mode `path` has, or 0666 less the umask for a new file, and renames it over
// `path`; on failure removes `temp` and throws std::system_error.
void Publish(const std::string& temp, const std::string& path);

// One picture of a video: `height` rows of 4 x width bytes (cairo's RGB24 words), `stride` bytes
// apart, shown for `copies` video frames.
struct VideoPicture {
  const unsigned char* pixels = nullptr;
  int stride = 0;
  int copies = 1;
};

// Writes the video `path` through ffmpeg (`program`), picture by picture: `next(&picture)` draws
// the next one and returns false after the last. The video goes to a temporary file next to
// `path` and is renamed into place only when ffmpeg has finished well; on any failure the
// temporary file is removed, an exception from `next` propagates, and a failing ffmpeg throws
// std::runtime_error naming the program, the path and ffmpeg's reason, or std::system_error
// ("cannot write 'PATH'" and the reason) when ffmpeg failed writing the video (no space, the file
// size limit).
void WriteVideo(const std::string& program, VideoFormat format, int width, int height, int fps,
                int crf, const std::string& path, const std::function<bool(VideoPicture*)>& next);

}  // namespace flexkin::render
