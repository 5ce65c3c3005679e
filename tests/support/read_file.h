#pragma once
// The whole of a file as text: what a command, writer or test left on disk, compared byte for byte.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace palpate::test {

/// The file's bytes, unchanged (binary mode); "" when it is absent or cannot be read.
inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace palpate::test
