#pragma once
// A JSON file a command or writer left on disk (summary.json, bench output), and a text file a test writes.

#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

namespace palpate::test {

/// The file's JSON; a discarded value (is_discarded()) when it is absent or not whole JSON.
inline nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in, nullptr, false);
}

/// Writes `text` to `path` as it is (binary mode), replacing the file.
inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

}  // namespace palpate::test
