#include "render/ffmpeg_pipe.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "flexkin/error.h"

extern char** environ;

namespace flexkin::render {
namespace {

// The last `lines` lines of `text`, without a trailing newline.
std::string Tail(std::string text, int lines) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  size_t start = text.size();
  for (int k = 0; k < lines && start > 0; ++k) {
    const size_t newline = text.rfind('\n', start - 1);
    start = newline == std::string::npos ? 0 : newline;
  }
  return text.substr(start == 0 ? 0 : start + 1);
}

// The errno of a failed write of the video that ffmpeg's failure `why` reports (the reasons a
// disk refuses a file, as strerror words them, or SIGXFSZ: the file size limit); 0 for any
// other failure (a missing codec, bad input).
int WriteErrorOf(const std::string& why) {
  if (why.find("killed by signal " + std::to_string(SIGXFSZ)) != std::string::npos) return EFBIG;
  for (const int e : {EFBIG, ENOSPC, EDQUOT, EIO, EROFS, EACCES, EPERM}) {
    if (why.find(std::strerror(e)) != std::string::npos) return e;
  }
  return 0;
}

}  // namespace

FfmpegPipe::FfmpegPipe(const std::string& program, const std::vector<std::string>& args) {
  int sockets[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sockets) != 0) {
    throw std::runtime_error(std::string("cannot start ffmpeg: socketpair: ") +
                             std::strerror(errno));
  }
  std::string error_path =
      (std::filesystem::temp_directory_path() / "flexkin-ffmpeg-XXXXXX").string();
  errors_ = ::mkostemp(error_path.data(), O_CLOEXEC);
  if (errors_ < 0) {
    const int e = errno;
    ::close(sockets[0]);
    ::close(sockets[1]);
    throw std::runtime_error("cannot start ffmpeg: temporary file in " +
                             std::filesystem::temp_directory_path().string() + ": " +
                             std::strerror(e));
  }
  ::unlink(error_path.c_str());

  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(program.c_str()));
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, sockets[1], STDIN_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, errors_, STDERR_FILENO);
  const int status =
      ::posix_spawnp(&pid_, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(sockets[1]);
  input_ = sockets[0];
  if (status != 0) {
    pid_ = -1;
    ::close(input_);
    ::close(errors_);
    input_ = errors_ = -1;
    throw std::runtime_error("cannot run ffmpeg (\"" + program + "\"): " + std::strerror(status) +
                             "; install it (Debian: apt-get install ffmpeg) or name the program "
                             "to use");
  }
}

FfmpegPipe::~FfmpegPipe() {
  if (input_ >= 0) ::close(input_);
  if (pid_ > 0) {
    ::kill(pid_, SIGKILL);
    int status;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
  }
  if (errors_ >= 0) ::close(errors_);
}

bool FfmpegPipe::Write(const void* data, size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::send(input_, p, size, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;  // EPIPE or ECONNRESET: ffmpeg has exited
    }
    p += n;
    size -= static_cast<size_t>(n);
  }
  return true;
}

std::string FfmpegPipe::Finish() {
  ::close(input_);
  input_ = -1;
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0) {
    if (errno != EINTR) {
      pid_ = -1;
      return std::string("waiting for ffmpeg: ") + std::strerror(errno);
    }
  }
  pid_ = -1;
  std::string text;
  char buf[4096];
  ::lseek(errors_, 0, SEEK_SET);
  for (ssize_t n; (n = ::read(errors_, buf, sizeof buf)) > 0;)
    text.append(buf, static_cast<size_t>(n));
  text = Tail(text, 4);
  // Some ffmpeg versions exit with status 0 after failing to write the trailer, saying so (only
  // errors are printed): a write error it reports is a failure whatever the status.
  const bool exited_well = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (exited_well && WriteErrorOf(text) == 0) return "";
  std::string why = !WIFEXITED(status) ? "killed by signal " + std::to_string(WTERMSIG(status))
                    : exited_well      ? "a write error"
                                       : "exit status " + std::to_string(WEXITSTATUS(status));
  return text.empty() ? why : why + ": " + text;
}

VideoFormat VideoFormatFromPath(const std::string& path) {
  const size_t dot = path.rfind('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (ext == ".mp4") return VideoFormat::kMp4;
  if (ext == ".gif") return VideoFormat::kGif;
  throw InputError("path",
                   "\"" + path + "\" has no known animation extension; expected .mp4 or .gif");
}

// Raw frames in: cairo's RGB24 words are bytes B, G, R, unused on a little-endian machine.
// -xerror: a failed write ends ffmpeg with a non-zero status (without it ffmpeg 5 exits with 0
// after failing to write an MP4's trailer, leaving a truncated file).
std::vector<std::string> FfmpegArgs(VideoFormat format, int width, int height, int fps, int crf,
                                    const std::string& output) {
  const uint32_t probe = 1;
  const bool little_endian = *reinterpret_cast<const unsigned char*>(&probe) == 1;
  std::vector<std::string> args = {
      "-hide_banner", "-loglevel",
      "error",        "-nostdin",
      "-f",           "rawvideo",
      "-pix_fmt",     little_endian ? "bgr0" : "0rgb",
      "-s",           std::to_string(width) + "x" + std::to_string(height),
      "-framerate",   std::to_string(fps),
      "-i",           "pipe:0",
      "-an",          "-xerror"};
  if (format == VideoFormat::kMp4) {
    args.insert(args.end(), {"-c:v", "libx264", "-preset", "medium", "-crf", std::to_string(crf),
                             "-pix_fmt", "yuv420p", "-movflags", "+faststart", "-f", "mp4"});
  } else {
    // One palette for the whole animation, made from all its frames.
    args.insert(args.end(),
                {"-filter_complex",
                 "split[a][b];[a]palettegen=stats_mode=full[p];[b][p]paletteuse=dither=sierra2_4a",
                 "-loop", "0", "-f", "gif"});
  }
  args.insert(args.end(), {"-y", output});
  return args;
}

std::string TemporaryNextTo(const std::string& path) {
  const size_t slash = path.rfind('/');
  const std::string dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  std::string temp = dir + "." + name + ".tmp-XXXXXX";
  const int fd = ::mkstemp(temp.data());
  if (fd < 0)
    throw std::system_error(errno, std::generic_category(), "cannot write '" + path + "'");
  ::close(fd);
  return temp;
}

void Publish(const std::string& temp, const std::string& path) {
  struct stat st;
  mode_t mode;
  if (::stat(path.c_str(), &st) == 0) {
    mode = st.st_mode & 07777;
  } else {
    const mode_t mask = ::umask(0);
    ::umask(mask);
    mode = 0666 & ~mask;
  }
  if (::chmod(temp.c_str(), mode) != 0 || ::rename(temp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    ::unlink(temp.c_str());
    throw std::system_error(e, std::generic_category(), "cannot write '" + path + "'");
  }
}

void WriteVideo(const std::string& program, VideoFormat format, int width, int height, int fps,
                int crf, const std::string& path, const std::function<bool(VideoPicture*)>& next) {
  const std::string temp = TemporaryNextTo(path);
  std::string failure;
  try {
    FfmpegPipe ffmpeg(program, FfmpegArgs(format, width, height, fps, crf, temp));
    VideoPicture picture;
    while (failure.empty() && next(&picture)) {
      for (int c = 0; c < picture.copies && failure.empty(); ++c) {
        for (int y = 0; y < height && failure.empty(); ++y) {
          if (!ffmpeg.Write(picture.pixels + static_cast<size_t>(y) * picture.stride,
                            4 * static_cast<size_t>(width))) {
            failure = "stopped reading";
          }
        }
      }
    }
    const std::string status = ffmpeg.Finish();
    if (!status.empty()) failure = status;
  } catch (...) {
    ::unlink(temp.c_str());
    throw;
  }
  if (!failure.empty()) {
    ::unlink(temp.c_str());
    // A video that could not be written is an I/O error like any file's, in one line: the
    // reason is the system's, ffmpeg's own words are left out.
    if (const int e = WriteErrorOf(failure); e != 0) {
      throw std::system_error(e, std::generic_category(),
                              "cannot write '" + path + "' (ffmpeg \"" + program +
                                  "\": " + failure.substr(0, failure.find(':')) + ")");
    }
    throw std::runtime_error("ffmpeg (\"" + program + "\") failed writing '" + path +
                             "': " + failure);
  }
  Publish(temp, path);
}

}  // namespace flexkin::render
