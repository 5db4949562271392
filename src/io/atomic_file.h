#pragma once
// Files read whole and written all-or-nothing: what every reader and writer of flexkin's files
// (results, trajectories, figures, viewer pages, glTF) shares. Private to the library, its tests,
// its components and its front ends.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <system_error>

#include "flexkin/error.h"

namespace flexkin {

// Throws `problem` as an InputError, its message ending "; nothing was written": a writer's
// refusal of its input before any byte of the file.
[[noreturn]] void ThrowNothingWritten(Problem problem);

// The whole content of the file at `path`. Throws std::system_error ("cannot read 'PATH'" and the
// system's reason) if it cannot be read.
std::string ReadTextFile(const std::string& path);

// Creates or replaces the file at `path` with what `write` puts into the stream, atomically: it
// writes a temporary file in the destination's directory, flushes, syncs and closes it, checks
// every step, and only then renames it over the destination. On any error the temporary file is
// removed and an existing destination is left untouched. Throws std::system_error ("cannot write
// 'PATH'" and the reason) for a file that cannot be written; if `write` throws, the exception
// propagates after the clean-up. A new file gets the usual mode (0666 less the process umask); a
// replaced file keeps its mode.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

// The same, piece by piece, for writers that produce a file over time (a run streaming its frames):
// the constructor creates the temporary file in the destination's directory, stream() writes to
// it (buffered), WriteAt() patches bytes already written, Commit() flushes, syncs, closes and
// renames it over the destination. Destroyed without Commit() (an exception, a failed run), the
// temporary file is removed and an existing destination is left untouched. Errors throw
// std::system_error "cannot write 'PATH'" with the system's reason.
class AtomicFile {
 public:
  explicit AtomicFile(const std::string& path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& path() const;
  // The directory of the destination ("" for the current one, else ending in '/').
  const std::string& directory() const;
  std::ostream& stream();
  // Bytes written through stream() so far: the offset of the next byte.
  uint64_t position() const;
  // Writes `size` bytes at `offset` (< position()), after flushing the stream.
  void WriteAt(uint64_t offset, const void* data, size_t size);
  // Throws the write error if a write through stream() failed; nothing otherwise.
  void Check() const;
  // The error to throw for a failure while writing: the failed write(2)'s errno if there was
  // one, else `fallback` (EIO if 0).
  std::system_error Error(int fallback = 0) const;
  void Commit();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// A scratch file in `directory` ("" or ending in '/'), unlinked at once (removed when closed),
// for data that is copied into an output later: Write appends with a buffer, CopyTo flushes and
// hands everything written to `write` in pieces. Errors throw std::system_error naming `what`.
class ScratchFile {
 public:
  ScratchFile(const std::string& directory, const std::string& what);
  ~ScratchFile();
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  void Write(const void* data, size_t size);
  uint64_t size() const { return size_; }
  void CopyTo(const std::function<void(const char* data, size_t size)>& write);

 private:
  void Drain();
  int fd_ = -1;
  std::string what_;
  std::string buffer_;
  uint64_t size_ = 0;
};

}  // namespace flexkin
