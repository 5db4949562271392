#pragma once
// Files read whole and written all-or-nothing: what every reader and writer of flexkin's files
// (results, trajectories, figures, viewer pages, glTF) shares. Private to the library, its tests,
// its components and its front ends.

#include <functional>
#include <iosfwd>
#include <string>

namespace flexkin {

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

}  // namespace flexkin
