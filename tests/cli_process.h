#pragma once
// The command line (FLEXKIN_CLI) as a child process that a test controls: started with fork and
// exec in a directory, optionally under a file size limit (RLIMIT_FSIZE, with SIGXFSZ ignored so
// that a write past it fails with EFBIG, as a full disk would fail it), its standard output and
// error read through pipes (so that the limit does not cut them), signalled and waited for with
// a timeout. Shared by failed_write_test and interrupt_test.

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace flexkin::test_util {

// The command line under test and the example scenarios (compile definitions of every test).
inline const std::string kCli = FLEXKIN_CLI;
inline const std::string kExamples = std::string(FLEXKIN_SOURCE_DIR) + "/examples/";

class CliProcess {
 public:
  // Starts `cli ARGS` in `dir`; `file_size_limit` > 0 sets RLIMIT_FSIZE in the child.
  CliProcess(const std::string& cli, const std::string& dir, const std::vector<std::string>& args,
             uint64_t file_size_limit = 0) {
    int out[2], err[2];
    if (::pipe2(out, O_CLOEXEC) != 0 || ::pipe2(err, O_CLOEXEC) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(out[1], STDOUT_FILENO);
      ::dup2(err[1], STDERR_FILENO);
      if (::chdir(dir.c_str()) != 0) ::_exit(120);
      if (file_size_limit > 0) {
        ::signal(SIGXFSZ, SIG_IGN);  // inherited through exec, by ffmpeg too
        rlimit limit;
        ::getrlimit(RLIMIT_FSIZE, &limit);
        limit.rlim_cur = file_size_limit;
        if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(121);
      }
      std::vector<char*> argv = {const_cast<char*>(cli.c_str())};
      for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv(cli.c_str(), argv.data());
      ::_exit(122);
    }
    ::close(out[1]);
    ::close(err[1]);
    out_fd_ = out[0];
    err_fd_ = err[0];
    started_ = std::chrono::steady_clock::now();
  }
  ~CliProcess() {
    if (pid_ > 0 && !exited_) {
      ::kill(pid_, SIGKILL);
      Wait(10.0);
    }
    if (out_fd_ >= 0) ::close(out_fd_);
    if (err_fd_ >= 0) ::close(err_fd_);
  }
  CliProcess(const CliProcess&) = delete;
  CliProcess& operator=(const CliProcess&) = delete;

  pid_t pid() const { return pid_; }
  bool started() const { return pid_ > 0; }
  void Signal(int signal) const { ::kill(pid_, signal); }

  // Waits up to `seconds` for the process to exit, reading its output meanwhile; true if it did.
  bool Wait(double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!exited_) {
      Drain(5);
      int status = 0;
      const pid_t r = ::waitpid(pid_, &status, WNOHANG);
      if (r == pid_) {
        exited_ = true;
        status_ = status;
        break;
      }
      if (r < 0 || std::chrono::steady_clock::now() > end) break;
    }
    if (exited_) {
      while (Drain(0)) {
      }
    }
    return exited_;
  }

  // The wait status (valid once Wait returned true).
  int status() const { return status_; }
  // The exit code, or -1 if the process did not exit normally (a signal ended it).
  int exit_code() const { return WIFEXITED(status_) ? WEXITSTATUS(status_) : -1; }
  const std::string& out() const { return out_; }
  const std::string& err() const { return err_; }
  double seconds_since_start() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  }

 private:
  // Reads what is there on the pipes, waiting at most `ms` for it; true if anything was read.
  bool Drain(int ms) {
    pollfd fds[2] = {{out_fd_, POLLIN, 0}, {err_fd_, POLLIN, 0}};
    if (::poll(fds, 2, ms) <= 0) return false;
    bool any = false;
    char buffer[4096];
    for (int i = 0; i < 2; ++i) {
      if ((fds[i].revents & (POLLIN | POLLHUP)) == 0) continue;
      const ssize_t n = ::read(fds[i].fd, buffer, sizeof buffer);
      if (n > 0) {
        (i == 0 ? out_ : err_).append(buffer, static_cast<size_t>(n));
        any = true;
      }
    }
    return any;
  }

  pid_t pid_ = -1;
  int out_fd_ = -1, err_fd_ = -1;
  bool exited_ = false;
  int status_ = 0;
  std::string out_, err_;
  std::chrono::steady_clock::time_point started_;
};

// The names in `dir` that look like a writer's temporary files (".NAME.tmp-XXXXXX", or any
// other name starting with '.'): none may be left after a command.
inline std::vector<std::string> TemporaryFilesIn(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name[0] == '.' || name.find(".tmp") != std::string::npos) names.push_back(name);
  }
  return names;
}

// The processes (other than this one) whose command line mentions `text`: an ffmpeg left
// running after the command that started it, say.
inline std::vector<pid_t> ProcessesMentioning(const std::string& text) {
  std::vector<pid_t> found;
  for (const auto& e : std::filesystem::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    const pid_t pid = static_cast<pid_t>(std::stol(name));
    if (pid == ::getpid()) continue;
    std::ifstream in(e.path() / "cmdline", std::ios::binary);
    std::string cmdline((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (cmdline.find(text) != std::string::npos) found.push_back(pid);
  }
  return found;
}

}  // namespace flexkin::test_util
