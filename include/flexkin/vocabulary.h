#pragma once
// The one vocabulary: every enumerated choice of flexkin (methods, objective terms, joint kinds,
// fixed-base solvers, plots, output formats, ...) is named once, next to its enum, in a table of
// NamedValue entries, and the parsers, writers, readers, the command-line help, the messages and
// the tests of the docs' tables all read that table. Adding a choice is one line there.
//
//   template <> struct Vocabulary<Method> {
//     static constexpr const char* kKind = "method";
//     static constexpr NamedValue<Method> kEntries[] = {{Method::kTractrix, "tractrix", "..."}};
//   };
//   NameOf(Method::kTractrix)                 -> "tractrix"
//   ParseName<Method>("ftl", "--method")      -> Method::kFollowTheLeader, or throws InputError
//   QuotedNames<Method>()                     -> "\"tractrix\", \"ftl\", ... or \"overall\""

#include <string>
#include <string_view>
#include <vector>

#include "flexkin/error.h"

namespace flexkin {

// One entry of a vocabulary.
template <typename Enum>
struct NamedValue {
  Enum value;
  const char* name;     // in files, on the command line and in messages
  const char* summary;  // one line for the command-line help and the docs' tables
};

// Specialized next to each enum, with kKind (the word for one choice, "method") and kEntries.
template <typename Enum>
struct Vocabulary;

// The name of `value` ("?" for a value outside the table, which a valid enum never is).
template <typename Enum>
const char* NameOf(Enum value) {
  for (const auto& entry : Vocabulary<Enum>::kEntries) {
    if (entry.value == value) return entry.name;
  }
  return "?";
}

// The entry of `name`, or null.
template <typename Enum>
const NamedValue<Enum>* FindName(std::string_view name) {
  for (const auto& entry : Vocabulary<Enum>::kEntries) {
    if (name == entry.name) return &entry;
  }
  return nullptr;
}

// Every name, in the table's order.
template <typename Enum>
std::vector<std::string> NamesOf() {
  std::vector<std::string> names;
  for (const auto& entry : Vocabulary<Enum>::kEntries) names.emplace_back(entry.name);
  return names;
}

// "\"a\", \"b\" or \"c\"": the names quoted and listed for a message.
std::string QuotedList(const std::vector<std::string>& names);

template <typename Enum>
std::string QuotedNames() {
  return QuotedList(NamesOf<Enum>());
}

// The problem with a name that is not in a vocabulary: field `field`, message
//   unknown method "fabrik"; expected "tractrix", "ftl", ... or "overall"
// with " (did you mean ...?)" for a near miss.
Problem UnknownName(const std::string& field, const char* kind, std::string_view name,
                    const std::vector<std::string>& names);

// The enumerator named `name`; throws InputError (UnknownName) naming `field` otherwise.
template <typename Enum>
Enum ParseName(std::string_view name, const std::string& field) {
  if (const NamedValue<Enum>* entry = FindName<Enum>(name)) return entry->value;
  throw InputError(UnknownName(field, Vocabulary<Enum>::kKind, name, NamesOf<Enum>()));
}

// Levenshtein distance, to suggest the intended name or key for a typo.
size_t EditDistance(std::string_view a, std::string_view b);

}  // namespace flexkin
