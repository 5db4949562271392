#include "render/ffmpeg_pipe.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

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
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "";
  std::string text;
  char buf[4096];
  ::lseek(errors_, 0, SEEK_SET);
  for (ssize_t n; (n = ::read(errors_, buf, sizeof buf)) > 0;)
    text.append(buf, static_cast<size_t>(n));
  std::string why = WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                                      : "killed by signal " + std::to_string(WTERMSIG(status));
  text = Tail(text, 4);
  return text.empty() ? why : why + ": " + text;
}

}  // namespace flexkin::render
