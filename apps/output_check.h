#pragma once
// The command line's early check of its outputs, shared by `run` and `robot`.

#include <sys/stat.h>

#include <cerrno>
#include <string>
#include <system_error>

namespace flexkin::cli {

// Fails early, before a possibly long run, if an output's directory does not exist (or is not a
// directory), so that no output is written when another cannot be. Throws std::system_error
// "cannot write 'PATH'" with the system's reason.
inline void CheckOutputDirectory(const std::string& path) {
  const size_t slash = path.rfind('/');
  const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash + 1);
  struct stat st;
  if (::stat(dir.c_str(), &st) != 0) {
    throw std::system_error(errno, std::generic_category(), "cannot write '" + path + "'");
  }
  if (!S_ISDIR(st.st_mode)) {
    throw std::system_error(ENOTDIR, std::generic_category(), "cannot write '" + path + "'");
  }
}

}  // namespace flexkin::cli
