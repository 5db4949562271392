#include "flexkin/vocabulary.h"

#include <algorithm>

namespace flexkin {

std::string QuotedList(const std::vector<std::string>& names) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i) {
    out += (i == 0 ? "\"" : (i + 1 == names.size() ? "\" or \"" : "\", \"")) + names[i];
  }
  return names.empty() ? out : out + "\"";
}

size_t EditDistance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1] ? 1 : 0)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

Problem UnknownName(const std::string& field, const char* kind, std::string_view name,
                    const std::vector<std::string>& names) {
  const std::string expected = QuotedList(names);
  std::string message =
      "unknown " + std::string(kind) + " \"" + std::string(name) + "\"; expected " + expected;
  for (const std::string& candidate : names) {
    if (EditDistance(name, candidate) <= 2) {
      message += " (did you mean \"" + candidate + "\"?)";
      break;
    }
  }
  return Problem(field, std::move(message), "\"" + std::string(name) + "\"", expected);
}

}  // namespace flexkin
