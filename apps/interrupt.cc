#include "interrupt.h"

#include <signal.h>

#include <csignal>
#include <string>

#include "flexkin/result_io.h"

namespace flexkin::cli {
namespace {

volatile std::sig_atomic_t g_signal = 0;
std::string g_writing;

extern "C" void OnSignal(int signal) { g_signal = signal; }

}  // namespace

void InstallInterruptHandlers() {
  struct sigaction action = {};
  action.sa_handler = OnSignal;
  sigemptyset(&action.sa_mask);
  // Restarted system calls: the loops notice the signal at their next check, and no read or
  // write fails half way for it. Reset after the first: a second signal ends the process.
  action.sa_flags = SA_RESTART | SA_RESETHAND;
  for (int signal : {SIGINT, SIGTERM}) ::sigaction(signal, &action, nullptr);
  // Up to the rename that puts a finished output in place.
  SetBeforeOutputCommit(&ThrowIfInterrupted);
}

int InterruptSignal() { return g_signal; }

void ThrowIfInterrupted() {
  if (g_signal != 0) throw Interrupted();
}

void Writing(const std::string& paths) {
  ThrowIfInterrupted();
  g_writing = paths;
}

std::string InterruptMessage() {
  const int signal = g_signal;
  std::string message =
      std::string("interrupted by ") + (signal == SIGINT    ? "SIGINT"
                                        : signal == SIGTERM ? "SIGTERM"
                                                            : "signal " + std::to_string(signal));
  if (!g_writing.empty()) message += "; nothing was written to " + g_writing;
  return message;
}

}  // namespace flexkin::cli
