#pragma once
/// Input files (scenes, replay logs, meshes): only regular files of bounded size are read, so a device, a FIFO
/// or a huge file is refused before anything is allocated for it.

#include <cstdint>
#include <string>

#include "core/result.h"

namespace palpate {

/// Checks that `path` is a readable regular file of 1..max_bytes bytes and returns its size. Opened without
/// blocking (a FIFO never hangs). Errors: "<what> '<path>': file not found", "... is a directory", "... is not a
/// regular file (a device, FIFO or socket)", "... file is empty", "... 600000000 bytes, more than the limit of
/// 67108864".
Result<int64_t> check_input_file(const std::string& path, const std::string& what, int64_t max_bytes);

/// Reads a whole input file after the checks of check_input_file(); errors as there, plus read errors.
Result<std::string> read_input_file(const std::string& path, const std::string& what, int64_t max_bytes);

}  // namespace palpate
