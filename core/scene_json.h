#pragma once
/// A scene's JSON text parsed strictly and in time linear in its length: no NUL byte, nesting within
/// kMaxJsonNesting, no key twice in one object, a number a double holds, at most kMaxKeyframes keyframes in the
/// top-level "trajectory" (counted while parsing: a longer one is refused without being kept).

#include <string>

#include <nlohmann/json.hpp>

#include "core/result.h"

namespace palpate {

/// The JSON tree of a scene's text, or the first problem (without the file's name: the caller adds it).
Result<nlohmann::json> parse_scene_json(const std::string& text);

/// Scene text (a key, a name) safe to print on one line: control and non-ASCII bytes as \xNN, cut at 80
/// characters with "..." after.
std::string printable_scene_text(const std::string& s);

}  // namespace palpate
