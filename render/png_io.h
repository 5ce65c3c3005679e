#pragma once
/// PNG file output and input (libpng), with atomic writes.

#include <cstdint>
#include <string>
#include <vector>

#include "core/result.h"

namespace palpate {

/// Writes an RGBA8 PNG (rows top-down, width*height*4 bytes) with fast settings (compression level 1, SUB
/// filter, Z_RLE strategy) through an AtomicFile (path + ".tmp", renamed to path; a link or a non-regular file at
/// path is refused). Errors name the path and the cause (e.g. "png 'x/frame_00001.png': No space left on
/// device"); no file is left behind on failure.
/// Thread: any; allocates.
Status write_png(const std::string& path, int width, int height, const uint8_t* rgba);

/// An 8-bit RGBA image, rows top-down; plain data, copyable.
struct Image {
  int width = 0;              ///< pixels
  int height = 0;             ///< pixels
  std::vector<uint8_t> rgba;  ///< width*height*4 bytes
};

/// Reads a PNG (8-bit RGB/RGBA, or anything libpng can convert) back as RGBA; errors name the path and cause.
Result<Image> read_png(const std::string& path);

}  // namespace palpate
