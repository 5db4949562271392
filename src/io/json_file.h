#pragma once
// JSON text in, the one way every file reader of flexkin parses it. Private: the public headers
// take text or paths and are free of nlohmann types; the library, its tests, its components and
// its front ends include this one.

#include <nlohmann/json.hpp>
#include <string>

#include "io/atomic_file.h"

namespace flexkin {

// Parses JSON text. Throws InputError: for a syntax error with an empty field and a message that
// starts "line L, column C: " and gives the reason; for a number too large for a double (1e999)
// with the JSON pointer of the value as field.
nlohmann::json ParseJsonText(const std::string& text);

// Reads and parses the file at `path`; throws std::system_error if it cannot be read and
// InputError as ParseJsonText.
nlohmann::json ReadJsonFile(const std::string& path);

// The top-level "format" string of the JSON file at `path`, read only as far as that key's value;
// "" where there is none, the file is not JSON or cannot be read (trajectory_reader.cc).
std::string JsonFileFormat(const std::string& path);

}  // namespace flexkin
