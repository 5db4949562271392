#pragma once
// Values of a parsed output document (a result file, a robot trajectory), each checked where it
// is read: the first problem is thrown as InputError naming its JSON pointer. Scenario files use
// io/json_values.h instead, which collects every problem.

#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "flexkin/error.h"

namespace flexkin::json_checked {

// The value as JSON text, cut to about 60 characters for a message.
inline std::string Show(const nlohmann::json& v) {
  std::string text = v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return text.size() > 60 ? text.substr(0, 56) + " ..." : text;
}

inline const nlohmann::json& Member(const nlohmann::json& object, const std::string& ptr,
                                    const char* key) {
  if (!object.is_object()) throw InputError(ptr, "value " + Show(object) + " is not an object");
  const auto it = object.find(key);
  if (it == object.end()) throw InputError(ptr + "/" + key, "is missing");
  return *it;
}

inline double ReadNumber(const nlohmann::json& v, const std::string& ptr) {
  if (!v.is_number() || !std::isfinite(v.get<double>())) {
    throw InputError(ptr, "value " + Show(v) + " is not valid; expected a finite number");
  }
  return v.get<double>();
}

inline int64_t ReadInteger(const nlohmann::json& v, const std::string& ptr, int64_t min) {
  if (!v.is_number_integer() || v.get<int64_t>() < min) {
    throw InputError(
        ptr, "value " + Show(v) + " is not valid; expected an integer >= " + std::to_string(min));
  }
  return v.get<int64_t>();
}

}  // namespace flexkin::json_checked
