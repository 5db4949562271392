#include "flexkin/error.h"

#include <cstdio>
#include <cstdlib>

namespace flexkin {

std::string FormatNumber(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.15g", x);
  if (std::strtod(buf, nullptr) != x) std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

}  // namespace flexkin
