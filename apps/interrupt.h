#pragma once
// SIGINT and SIGTERM on the command line: the handler only records the signal; the long loops
// (a run's progress, a robot's steps, a groom's frames, a render's pictures) check it and throw
// Interrupted, which unwinds through the writers so that their temporary files are removed and
// an ffmpeg child is killed and reaped; main then exits with 128 + the signal's number.

#include <exception>
#include <string>

namespace flexkin::cli {

// Thrown by ThrowIfInterrupted once a signal has arrived.
class Interrupted : public std::exception {
 public:
  const char* what() const noexcept override { return "interrupted"; }
};

// Installs the handlers of SIGINT and SIGTERM. A second signal of the same kind ends the
// process at once (the handler is reset after the first).
void InstallInterruptHandlers();
// The signal that arrived (SIGINT or SIGTERM), 0 if none.
int InterruptSignal();
// Throws Interrupted if a signal has arrived.
void ThrowIfInterrupted();
// Before writing an output: throws Interrupted if a signal has arrived, else names the output
// for the message on interruption ("nothing was written to PATHS").
void Writing(const std::string& paths);
// The message printed on interruption, without the "flexkin: " prefix.
std::string InterruptMessage();

}  // namespace flexkin::cli
