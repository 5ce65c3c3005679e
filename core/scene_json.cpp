// Scene JSON text to a tree (core/scene_json.h).
#include "core/scene_json.h"

#include <cstdint>
#include <cstdio>
#include <set>
#include <vector>

#include "core/limits.h"

namespace palpate {
namespace {

using Json = nlohmann::json;

// Builds the JSON tree from the parser's events, in time linear in the text (nlohmann's callback parser scans
// the whole parent array after every object, quadratic in a long trajectory), and on the way notes the first
// key that appears twice in one object (nlohmann keeps the last silently: "duplicate key 'lattice.level'") and
// counts the top-level trajectory's keyframes, keeping none past kMaxKeyframes (the rest are only counted).
class StrictJsonBuilder {
 public:
  using number_integer_t = Json::number_integer_t;
  using number_unsigned_t = Json::number_unsigned_t;
  using number_float_t = Json::number_float_t;
  using string_t = Json::string_t;
  using binary_t = Json::binary_t;

  Json root;
  std::string duplicate;      // "duplicate key '<path>'", or empty
  std::string syntax_error;   // the parser's message for invalid JSON, or empty
  std::size_t keyframes = 0;  // elements of the top-level "trajectory" array, kept or not

  bool null() { return add(Json(nullptr), false, false); }
  bool boolean(bool v) { return add(Json(v), false, false); }
  bool number_integer(number_integer_t v) { return add(Json(v), false, false); }
  bool number_unsigned(number_unsigned_t v) { return add(Json(v), false, false); }
  bool number_float(number_float_t v, const string_t& /*text*/) { return add(Json(v), false, false); }
  bool string(string_t& v) { return add(Json(std::move(v)), false, false); }
  bool binary(binary_t& v) { return add(Json::binary(std::move(v)), false, false); }
  bool start_object(std::size_t /*elements*/) { return add(Json::object(), true, true); }
  bool start_array(std::size_t /*elements*/) { return add(Json::array(), true, false); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }
  bool key(string_t& k) {
    Level& top = stack_.back();
    if (!top.keys.insert(k).second && duplicate.empty())
      duplicate = "duplicate key '" + printable_scene_text(top.path.empty() ? k : top.path + "." + k) + "'";
    last_key_ = std::move(k);
    return true;
  }
  bool parse_error(std::size_t /*position*/, const std::string& /*last_token*/, const Json::exception& e) {
    syntax_error = e.what();
    return false;
  }

 private:
  struct Level {
    Json* value = nullptr;  // null: counted, not kept
    std::set<std::string> keys;
    std::string path;  // key path of this object or array
    bool object = false;
    bool trajectory = false;
  };

  // places a value in the open object or array (or as the root), and opens it if it is one
  bool add(Json&& v, bool opens, bool object) {
    Json* slot = nullptr;
    std::string path;
    bool trajectory = false;
    if (stack_.empty()) {
      root = std::move(v);
      slot = &root;
    } else {
      Level& top = stack_.back();
      path = top.path;
      if (top.object) {
        path += (path.empty() ? "" : ".") + last_key_;
        trajectory = opens && !object && stack_.size() == 1 && last_key_ == "trajectory";
        if (top.value) slot = &((*top.value)[last_key_] = std::move(v));
      } else {
        path += "[]";
        const bool kept = !top.trajectory || ++keyframes <= static_cast<std::size_t>(kMaxKeyframes);
        if (top.value && kept) {
          top.value->push_back(std::move(v));
          slot = &top.value->back();
        }
      }
    }
    if (opens) stack_.push_back({slot, {}, std::move(path), object, trajectory});
    return true;
  }

  bool close() {
    stack_.pop_back();
    return true;
  }

  std::vector<Level> stack_;
  std::string last_key_;
};

// Where JSON text first nests arrays and objects deeper than `limit` (its line), else 0. Brackets inside strings
// do not count. The parser's key paths would otherwise cost memory quadratic in the depth.
int64_t json_too_deep(const std::string& text, int limit) {
  int depth = 0;
  int64_t line = 1;
  bool in_string = false, escaped = false;
  for (const char c : text) {
    if (c == '\n') ++line;
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > limit) return line;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return 0;
}

}  // namespace

std::string printable_scene_text(const std::string& s) {
  std::string out;
  for (unsigned char c : s.substr(0, 80)) {
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    }
  }
  return s.size() > 80 ? out + "..." : out;
}

Result<Json> parse_scene_json(const std::string& text) {
  // the JSON parser stops at a NUL byte as at the end of the text: whatever follows would be ignored unread
  if (const std::size_t nul = text.find('\0'); nul != std::string::npos)
    return make_error("NUL byte at offset ", std::to_string(nul), ": not a JSON text");
  if (const int64_t line = json_too_deep(text, kMaxJsonNesting); line > 0)
    return make_error("JSON nested deeper than the limit of ", std::to_string(kMaxJsonNesting), " levels (line ",
                      std::to_string(line), ")");
  StrictJsonBuilder built;
  // a parse_error, or an out_of_range for a number no double holds (1e400), arrives as the builder's syntax_error
  if (!Json::sax_parse(text, &built) || !built.syntax_error.empty())
    return make_error("invalid JSON: ", built.syntax_error.empty() ? std::string("not parsed") : built.syntax_error);
  if (!built.duplicate.empty()) return make_error(built.duplicate);
  if (built.keyframes > static_cast<std::size_t>(kMaxKeyframes))
    return make_error("trajectory: ", std::to_string(built.keyframes), " keyframes, more than the limit of ",
                      std::to_string(kMaxKeyframes));
  return std::move(built.root);
}

}  // namespace palpate
