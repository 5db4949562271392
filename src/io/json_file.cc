// JSON text in, with the location of a syntax error and the pointer of an overflowing number
// (src/io/json_file.h): what result, scenario and robot scenario files share.
#include "io/json_file.h"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "io/atomic_file.h"

namespace flexkin {
namespace {

using json = nlohmann::json;

// Builds the document from SAX events like nlohmann's own parser, but keeps the path to the
// value being read so that an overflowing number (1e999) can be reported by its JSON pointer.
class DomBuilder {
 public:
  explicit DomBuilder(json* root) : root_(root) {}

  bool null() { return Put(nullptr); }
  bool boolean(bool value) { return Put(value); }
  bool number_integer(json::number_integer_t value) { return Put(value); }
  bool number_unsigned(json::number_unsigned_t value) { return Put(value); }
  bool number_float(json::number_float_t value, const json::string_t&) { return Put(value); }
  bool string(json::string_t& value) { return Put(std::move(value)); }
  bool binary(json::binary_t& value) { return Put(json::binary(std::move(value))); }
  bool start_object(std::size_t) { return Open(json::object(), false); }
  // A key seen twice in one object is refused: the later value would silently replace the
  // earlier one ("links": 25, "links": 30 read as 30).
  bool key(json::string_t& key) {
    Frame& frame = stack_.back();
    const bool repeated = frame.value->contains(key);
    frame.key = key;
    if (repeated) duplicate_pointer_ = Pointer();
    return !repeated;
  }
  bool end_object() { return Close(); }
  bool start_array(std::size_t) { return Open(json::array(), true); }
  bool end_array() { return Close(); }
  bool parse_error(std::size_t position, const std::string& last_token,
                   const json::exception& error) {
    error_position_ = position;
    error_token_ = last_token;
    error_id_ = error.id;
    error_what_ = error.what();
    error_pointer_ = Pointer();
    return false;
  }

  // Throws the InputError that describes the parse error; `text` is the parsed text.
  [[noreturn]] void Throw(const std::string& text) const;

 private:
  struct Frame {
    json* value;  // the open object or array
    bool is_array;
    std::string key;   // objects: the last key read
    size_t count = 0;  // arrays: elements started so far
  };

  json* Add(json value) {
    if (stack_.empty()) {
      *root_ = std::move(value);
      return root_;
    }
    Frame& frame = stack_.back();
    if (frame.is_array) {
      ++frame.count;
      frame.value->push_back(std::move(value));
      return &frame.value->back();
    }
    json& slot = (*frame.value)[frame.key];
    slot = std::move(value);
    return &slot;
  }
  bool Put(json value) {
    Add(std::move(value));
    return true;
  }
  // The open container stays the last element of its parent until it is closed, so the pointer
  // to it stays valid while its parent grows no further.
  bool Open(json value, bool is_array) {
    json* container = Add(std::move(value));
    stack_.push_back({container, is_array, "", 0});
    return true;
  }
  bool Close() {
    stack_.pop_back();
    return true;
  }
  // The JSON pointer of the value being read: open containers use the element in progress
  // (count - 1); the innermost one the next element (count).
  std::string Pointer() const {
    std::string out;
    for (size_t f = 0; f < stack_.size(); ++f) {
      const Frame& frame = stack_[f];
      const bool innermost = f + 1 == stack_.size();
      if (frame.is_array) {
        out += "/" + std::to_string(innermost ? frame.count : frame.count - 1);
      } else {
        out += "/";
        for (char c : frame.key) {
          out += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
        }
      }
    }
    return out;
  }

  json* root_;
  std::vector<Frame> stack_;
  std::string duplicate_pointer_;  // the pointer of a repeated key, once one is read
  size_t error_position_ = 0;
  std::string error_token_, error_what_, error_pointer_;
  int error_id_ = 0;
};

// "line L, column C" of byte `offset` of `text`, both 1-based.
std::string LineColumn(const std::string& text, size_t offset) {
  offset = std::min(offset, text.size());
  size_t line = 1, line_start = 0;
  for (size_t i = 0; i < offset; ++i) {
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(offset - line_start + 1);
}

void DomBuilder::Throw(const std::string& text) const {
  if (!duplicate_pointer_.empty()) {
    const std::string& key = stack_.back().key;
    throw InputError(duplicate_pointer_, "key \"" + key +
                                             "\" appears more than once in the same object; "
                                             "give each key once (a later value would replace "
                                             "the earlier one)");
  }
  if (error_id_ == 406) {  // a number literal too large for a double
    const size_t start =
        error_position_ >= error_token_.size() ? error_position_ - error_token_.size() : 0;
    throw InputError(error_pointer_, "number " + error_token_ + " (" + LineColumn(text, start) +
                                         ") is too large for a double; expected a finite "
                                         "number, |x| < 1.8e308");
  }
  // nlohmann's message is "[json.exception.parse_error.101] parse error at line L, column C:
  // <reason>"; keep the reason, with our own line and column of the last character read.
  std::string reason = error_what_;
  const size_t column = reason.find("column ");
  const size_t colon = reason.find(": ", column == std::string::npos ? 0 : column);
  if (colon != std::string::npos) reason = reason.substr(colon + 2);
  throw InputError("", LineColumn(text, error_position_ > 0 ? error_position_ - 1 : 0) +
                           ": invalid JSON: " + reason);
}

}  // namespace

json ParseJsonText(const std::string& text) {
  json root;
  DomBuilder builder(&root);
  if (!json::sax_parse(text, &builder)) builder.Throw(text);
  return root;
}

json ReadJsonFile(const std::string& path) { return ParseJsonText(ReadTextFile(path)); }

}  // namespace flexkin
