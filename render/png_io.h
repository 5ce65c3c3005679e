#pragma once
/// PNG file output and input (libpng), with atomic writes.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/result.h"

struct libdeflate_compressor;  // <libdeflate.h>

namespace palpate {

/// Which compressor makes the zlib stream of a PNG's image data.
enum class PngCodec {
  kZlib,        ///< libpng + zlib (level, SUB filter, Z_RLE strategy)
  kLibdeflate,  ///< libdeflate's zlib compressor on rows this encoder filters itself; chunks written here
};

/// The PNG row filter (one for every row) of the libdeflate codec; the zlib codec always lets libpng use SUB.
/// Values are the filter type bytes of the PNG format.
enum class PngFilter : uint8_t {
  kNone = 0,   ///< bytes as they are
  kSub = 1,    ///< minus the same channel of the pixel to the left
  kUp = 2,     ///< minus the same byte of the row above
  kPaeth = 4,  ///< minus the Paeth predictor of left, above and upper left
};

/// Encodes RGBA8 frames as PNG files in memory, keeping its compressor and buffers from one frame to the next.
/// A frame whose alpha is 255 everywhere is stored as 8-bit RGB (read back as the same RGBA: nothing is lost, a
/// quarter less to filter and compress); any other frame as RGBA. The output is a standard PNG (signature, IHDR,
/// one IDAT, IEND, CRC-32 on every chunk) that libpng reads back bit-exact.
/// Not copyable. Thread: one thread at a time.
class PngEncoder {
 public:
  /// level: zlib 1..9 or libdeflate 1..12 (clamped); 0 = the codec's default: zlib 1, libdeflate 1 (with no row
  /// filter, on rendered frames both faster and smaller than level 2 with SUB, the default before;
  /// `palpate bench png`).
  explicit PngEncoder(PngCodec codec = PngCodec::kLibdeflate, int level = 0);
  ~PngEncoder();
  PngEncoder(const PngEncoder&) = delete;
  PngEncoder& operator=(const PngEncoder&) = delete;

  /// Encodes rows top-down (width*height*4 bytes); the PNG is in bytes() until the next call. `name` prefixes
  /// errors ("png 'x': libpng: ..."); sizes outside 1..65536 and a null image are errors.
  Status encode(int width, int height, const uint8_t* rgba, const std::string& name);
  /// The last PNG encoded (valid until the next call).
  std::span<const uint8_t> bytes() const { return {out_.data(), out_size_}; }
  /// True when the last PNG was stored as RGB (alpha 255 everywhere).
  bool last_rgb() const { return last_rgb_; }
  /// Always store RGBA, even when alpha is 255 everywhere (the format before RGB frames; for comparisons).
  void set_keep_alpha(bool keep) { keep_alpha_ = keep; }
  /// The row filter of the libdeflate codec (default kNone: rendered frames are flat colours and lines, whose
  /// repeats deflate finds as they are; a predictor turns them into noise that costs time and bytes;
  /// `palpate bench png`).
  void set_filter(PngFilter filter) { filter_ = filter; }
  /// Rows come bottom-up (as glReadPixels gives them): row 0 of the input is the bottom of the image. The
  /// file is the same as for the flipped input; saves the caller a flip pass.
  void set_bottom_up(bool bottom_up) { bottom_up_ = bottom_up; }

 private:
  Status encode_zlib(int width, int height, const uint8_t* rgba, int channels, const std::string& name);
  Status encode_libdeflate(int width, int height, const uint8_t* rgba, const std::string& name);

  PngCodec codec_;
  int level_;
  ::libdeflate_compressor* compressor_ = nullptr;
  std::vector<uint8_t> filtered_;  // libdeflate: filter byte + filtered row, per row
  std::vector<uint8_t> zero_row_;  // libdeflate: the row above the first one (zeros, width*4)
  std::vector<uint8_t> out_;       // grow-only: a frame's PNG is its first out_size_ bytes (no zero fill per frame)
  std::size_t out_size_ = 0;
  bool last_rgb_ = false;
  bool keep_alpha_ = false;
  PngFilter filter_ = PngFilter::kNone;
  bool bottom_up_ = false;
};

/// True when every alpha byte of width*height RGBA pixels is 255.
bool alpha_opaque(const uint8_t* rgba, std::size_t pixels);

/// Writes an RGBA8 PNG (rows top-down, width*height*4 bytes; RGB when alpha is 255 everywhere) with `encoder`
/// (a fresh default one when null) through an AtomicFile (path + ".tmp", renamed to path; a link or a non-regular
/// file at path is refused). Errors name the path and the cause (e.g. "png 'x/frame_00001.png': No space left on
/// device"); no file is left behind on failure.
/// Thread: any; allocates.
Status write_png(const std::string& path, int width, int height, const uint8_t* rgba, PngEncoder* encoder = nullptr);

/// An 8-bit RGBA image, rows top-down; plain data, copyable.
struct Image {
  int width = 0;              ///< pixels
  int height = 0;             ///< pixels
  std::vector<uint8_t> rgba;  ///< width*height*4 bytes
};

/// Reads a PNG (8-bit RGB/RGBA, or anything libpng can convert) back as RGBA; errors name the path and cause.
Result<Image> read_png(const std::string& path);
/// Decodes a PNG held in memory as RGBA; errors name `name` and the cause.
Result<Image> decode_png(const uint8_t* data, std::size_t size, const std::string& name);

}  // namespace palpate
