#pragma once
// The command line's limit on the size of its outputs (--max-output-size), shared by `run` and
// `robot`: outputs whose estimated size is over the limit are refused before the run.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <cstdio>
#include <string>

#include "flexkin/error.h"

namespace flexkin::cli {

inline constexpr uint64_t kDefaultMaxOutputSize = uint64_t{4} << 30;  // 4 GiB
inline constexpr const char* kMaxOutputSizeOption = "--max-output-size";

// "500M", "20G", "1.5G", "4096", "64K", "2T" (binary multiples: K = 1024; an optional "B" or "iB"
// after the letter), "0" for no limit. Throws InputError naming --max-output-size.
inline uint64_t ParseByteSize(const std::string& text) {
  const auto fail = [&]() -> uint64_t {
    throw InputError(Problem::Invalid(kMaxOutputSizeOption, "\"" + text + "\"",
                                      "a size in bytes, or with a suffix K, M, G or T (binary "
                                      "multiples), e.g. 500M or 20G; 0 for no limit"));
  };
  size_t pos = 0;
  while (pos < text.size() && ((text[pos] >= '0' && text[pos] <= '9') || text[pos] == '.')) ++pos;
  if (pos == 0) return fail();
  double value = 0;
  try {
    size_t used = 0;
    value = std::stod(text.substr(0, pos), &used);
    if (used != pos) return fail();
  } catch (const std::exception&) {
    return fail();
  }
  std::string suffix = text.substr(pos);
  for (char& c : suffix) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  double scale = 1;
  if (!suffix.empty() && suffix != "B") {
    const std::string letters = "KMGT";
    const size_t k = letters.find(suffix[0]);
    const std::string rest = suffix.substr(1);
    if (k == std::string::npos || !(rest.empty() || rest == "B" || rest == "IB")) return fail();
    for (size_t i = 0; i <= k; ++i) scale *= 1024;
  }
  const double bytes = value * scale;
  if (!(bytes < 1.8e19)) return fail();
  return static_cast<uint64_t>(bytes);
}

// "12.3 KiB", "4 GiB", "512 bytes".
inline std::string FormatBytes(uint64_t bytes) {
  const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  double value = static_cast<double>(bytes);
  int unit = 0;
  while (value >= 1024 && unit < 6) {
    value /= 1024;
    ++unit;
  }
  char buffer[32];
  if (unit == 0) {
    std::snprintf(buffer, sizeof buffer, "%llu bytes", static_cast<unsigned long long>(bytes));
  } else {
    std::snprintf(buffer, sizeof buffer, value < 10 ? "%.1f %s" : "%.0f %s", value, units[unit]);
  }
  return buffer;
}

// A --max-output-size value that admits `bytes`: whole MiB or GiB, rounded up.
inline std::string SizeOptionFor(uint64_t bytes) {
  const uint64_t mib = uint64_t{1} << 20, gib = uint64_t{1} << 30;
  if (bytes >= gib) return std::to_string((bytes + gib - 1) / gib) + "G";
  return std::to_string((bytes + mib - 1) / mib) + "M";
}

// Adds --max-output-size to `command`, storing its text in `value`.
inline void AddMaxOutputSizeOption(CLI::App* command, std::string* value) {
  command->add_option(kMaxOutputSizeOption, *value,
                      "Refuse, before running, an output whose estimated size is over this: "
                      "bytes or with a suffix K, M, G, T (binary), e.g. 500M, 20G; 0 = no limit "
                      "(default 4G)");
}

}  // namespace flexkin::cli
