#pragma once
// The checks that a scenario reader and its JSON Schema (docs/schema/) accept the same keys: the
// keys a reader accepts at a place of a document, read from its unknown-key message, and the keys
// a schema object lists.

#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "flexkin/error.h"
#include "test_util.h"

namespace flexkin::test_util {

// The keys `validate` (a reader's problems for a document's text) accepts at `pointer` of `doc`.
inline std::set<std::string> AcceptedKeys(
    nlohmann::json doc, const std::string& pointer,
    const std::function<Problems(const std::string&)>& validate) {
  doc[nlohmann::json::json_pointer(pointer)]["zzz_unknown"] = 1;
  for (const Problem& p : validate(doc.dump())) {
    if (p.field != pointer + "/zzz_unknown") continue;
    return KeysOfUnknownKeyMessage(p.message);
  }
  ADD_FAILURE() << "no unknown-key problem at " << pointer;
  return {};
}

// The "properties" of a schema object.
inline std::set<std::string> SchemaKeys(const nlohmann::json& object_schema) {
  std::set<std::string> keys;
  for (const auto& item : object_schema["properties"].items()) keys.insert(item.key());
  return keys;
}

}  // namespace flexkin::test_util
