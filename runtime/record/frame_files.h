#pragma once
/// The frame files of a recording (FOLDER/frames/frame_N.png), listed in frame order: by the number N, never by
/// the text of the name (frame_100000 comes after frame_99999), each one a regular file, none missing.

#include <cstdint>
#include <string>
#include <vector>

#include "core/result.h"

namespace palpate {

/// One frame file. Plain data.
struct FrameFile {
  int64_t number = 0;  ///< N of frame_N.png
  std::string path;    ///< the file
};

/// Frame numbers above this are refused (the PNG writer numbers frames with an int).
inline constexpr int64_t kMaxFrameNumber = 2'147'483'647;

/// The frame_*.png files of `frames_dir` in numeric order. Errors name the folder and the file: a name whose N is
/// not a decimal number in 0..kMaxFrameNumber, a file that is not a regular file (a FIFO, a device, a folder), no
/// frame at all, and a gap (the numbers must run 0, 1, 2, ... without a hole: a missing frame would shift every
/// later one).
Result<std::vector<FrameFile>> list_frame_files(const std::string& frames_dir);

/// Width and height from a PNG file's IHDR, read without decoding anything; errors name the path.
Result<std::pair<int64_t, int64_t>> png_size(const std::string& path);

}  // namespace palpate
