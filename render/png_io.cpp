#include "render/png_io.h"

#include "core/atomic_file.h"

#include <libdeflate.h>
#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>

namespace palpate {

namespace {

constexpr int kMaxSizePx = 1 << 16;

// State shared with libpng's callbacks; plain data so longjmp over it is safe. Output goes into a buffer sized
// beforehand for the worst case, so the callback never allocates.
struct PngWriteState {
  uint8_t* data = nullptr;
  std::size_t size = 0;
  std::size_t capacity = 0;
  char message[256] = {};  // libpng's error text
};

void on_png_error(png_structp png, png_const_charp message) {
  auto* state = static_cast<PngWriteState*>(png_get_error_ptr(png));
  std::snprintf(state->message, sizeof state->message, "%s", message);
  png_longjmp(png, 1);
}

void on_png_warning(png_structp, png_const_charp) {}

void on_png_write(png_structp png, png_bytep data, png_size_t length) {
  auto* state = static_cast<PngWriteState*>(png_get_io_ptr(png));
  if (length > state->capacity - state->size) png_error(png, "encoded image larger than its buffer");
  std::memcpy(state->data + state->size, data, length);
  state->size += length;
}

void on_png_flush(png_structp) {}

// Encodes the image into state's buffer; false on failure with state's message set. channels 3: the fourth
// byte of each pixel is dropped by libpng (png_set_filler). Only plain data lives in this frame, because
// libpng reports errors with longjmp.
bool encode_with_libpng(PngWriteState* state, int width, int height, const uint8_t* rgba, int channels, int level,
                        bool bottom_up) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, state, on_png_error, on_png_warning);
  if (png == nullptr) {
    std::snprintf(state->message, sizeof state->message, "png_create_write_struct failed");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    std::snprintf(state->message, sizeof state->message, "png_create_info_struct failed");
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_set_write_fn(png, state, on_png_write, on_png_flush);
  png_set_compression_level(png, level);
  png_set_compression_strategy(png, Z_RLE);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_BASE, PNG_FILTER_TYPE_BASE);
  png_write_info(png, info);
  if (channels == 3) png_set_filler(png, 0, PNG_FILLER_AFTER);  // rows hold RGBA; the file gets RGB
  const std::size_t row_bytes = static_cast<std::size_t>(width) * 4;
  for (int y = 0; y < height; ++y) {
    png_write_row(png, rgba + static_cast<std::size_t>(bottom_up ? height - 1 - y : y) * row_bytes);
  }
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

void put_u32(uint8_t* p, uint32_t v) {
  p[0] = static_cast<uint8_t>(v >> 24);
  p[1] = static_cast<uint8_t>(v >> 16);
  p[2] = static_cast<uint8_t>(v >> 8);
  p[3] = static_cast<uint8_t>(v);
}

// Completes the chunk whose length field starts at p (type and `length` data bytes already in place): length
// and the CRC-32 of type + data. Returns the position after the chunk.
uint8_t* close_chunk(uint8_t* p, uint32_t length) {
  put_u32(p, length);
  put_u32(p + 8 + length, libdeflate_crc32(0, p + 4, 4 + static_cast<std::size_t>(length)));
  return p + 12 + length;
}

// The Paeth predictor (PNG specification, filter type 4): whichever of a (left), b (above) and c (upper left)
// is nearest to a + b - c, ties in that order.
inline uint8_t paeth(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return static_cast<uint8_t>(a);
  return static_cast<uint8_t>(pb <= pc ? b : c);
}

// Filters one row of w RGBA pixels into dst: the filter type byte, then w*C filtered bytes (C = 3 drops the
// alpha byte). `above` is the row above (zeros for the first row). Returns whether every alpha byte of the row
// is 255.
template <PngFilter F, int C>
bool filter_row_as(const uint8_t* row, const uint8_t* above, std::size_t w, uint8_t* dst) {
  *dst++ = static_cast<uint8_t>(F);
  uint8_t all = 0xff;
  for (std::size_t x = 0; x < w; ++x, row += 4, above += 4, dst += C) {
    for (int c = 0; c < C; ++c) {
      uint8_t predicted = 0;
      if constexpr (F == PngFilter::kSub) predicted = x > 0 ? row[c - 4] : 0;
      if constexpr (F == PngFilter::kUp) predicted = above[c];
      if constexpr (F == PngFilter::kPaeth) predicted = x > 0 ? paeth(row[c - 4], above[c], above[c - 4]) : above[c];
      dst[c] = static_cast<uint8_t>(row[c] - predicted);
    }
    all &= row[3];
  }
  return all == 0xff;
}

template <int C>
bool filter_row_channels(PngFilter filter, const uint8_t* row, const uint8_t* above, std::size_t w, uint8_t* dst) {
  switch (filter) {
    case PngFilter::kNone: return filter_row_as<PngFilter::kNone, C>(row, above, w, dst);
    case PngFilter::kSub: return filter_row_as<PngFilter::kSub, C>(row, above, w, dst);
    case PngFilter::kUp: return filter_row_as<PngFilter::kUp, C>(row, above, w, dst);
    case PngFilter::kPaeth: return filter_row_as<PngFilter::kPaeth, C>(row, above, w, dst);
  }
  return filter_row_as<PngFilter::kUp, C>(row, above, w, dst);
}

bool filter_row(PngFilter filter, int channels, const uint8_t* row, const uint8_t* above, std::size_t w, uint8_t* dst) {
  return channels == 3 ? filter_row_channels<3>(filter, row, above, w, dst)
                       : filter_row_channels<4>(filter, row, above, w, dst);
}

constexpr uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
constexpr std::size_t kIhdrChunk = 12 + 13;
constexpr std::size_t kIendChunk = 12;

}  // namespace

bool alpha_opaque(const uint8_t* rgba, std::size_t pixels) {
  // whole pixels at a time: AND of the alpha bytes, checked once per row-sized block
  uint8_t all = 0xff;
  for (std::size_t i = 0; i < pixels; ++i) {
    all &= rgba[4 * i + 3];
    if ((i & 1023) == 1023 && all != 0xff) return false;
  }
  return all == 0xff;
}

PngEncoder::PngEncoder(PngCodec codec, int level) : codec_(codec) {
  if (codec_ == PngCodec::kLibdeflate) {
    level_ = level == 0 ? 1 : std::clamp(level, 1, 12);
    compressor_ = libdeflate_alloc_compressor(level_);
  } else {
    level_ = level == 0 ? 1 : std::clamp(level, 1, 9);
  }
}

PngEncoder::~PngEncoder() {
  if (compressor_ != nullptr) libdeflate_free_compressor(compressor_);
}

Status PngEncoder::encode(int width, int height, const uint8_t* rgba, const std::string& name) {
  if (width < 1 || height < 1 || width > kMaxSizePx || height > kMaxSizePx) {
    return make_error("png '", name, "': size ", std::to_string(width), "x", std::to_string(height), " outside 1..",
                      std::to_string(kMaxSizePx));
  }
  if (rgba == nullptr) return make_error("png '", name, "': no pixel data");
  if (codec_ == PngCodec::kLibdeflate) return encode_libdeflate(width, height, rgba, name);
  last_rgb_ = !keep_alpha_ && alpha_opaque(rgba, static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  return encode_zlib(width, height, rgba, last_rgb_ ? 3 : 4, name);
}

Status PngEncoder::encode_zlib(int width, int height, const uint8_t* rgba, int channels, const std::string& name) {
  // worst case: the filtered rows stored uncompressed (zlib adds 5 bytes per 16 KiB block), plus the chunks
  const std::size_t raw = static_cast<std::size_t>(height) * (1 + static_cast<std::size_t>(width) * channels);
  out_size_ = 0;
  if (out_.size() < raw + raw / 1000 + 4096) out_.resize(raw + raw / 1000 + 4096);
  PngWriteState state;
  state.data = out_.data();
  state.capacity = out_.size();
  if (!encode_with_libpng(&state, width, height, rgba, channels, level_, bottom_up_))
    return make_error("png '", name, "': libpng: ", state.message);
  out_size_ = state.size;
  return Ok{};
}

Status PngEncoder::encode_libdeflate(int width, int height, const uint8_t* rgba, const std::string& name) {
  if (compressor_ == nullptr) return make_error("png '", name, "': libdeflate: no compressor (out of memory)");
  const auto w = static_cast<std::size_t>(width);
  const std::size_t row_bytes = w * 4;
  if (filtered_.size() < static_cast<std::size_t>(height) * (1 + row_bytes))
    filtered_.resize(static_cast<std::size_t>(height) * (1 + row_bytes));
  if (zero_row_.size() != row_bytes) zero_row_.assign(row_bytes, 0);
  auto source_row = [&](int y) {
    return rgba + static_cast<std::size_t>(bottom_up_ ? height - 1 - y : y) * row_bytes;
  };
  // filters every row with `channels` bytes per pixel; RGB (3) stops at the first row that is not opaque
  auto filter_rows = [&](int channels) {
    const std::size_t stride = 1 + w * static_cast<std::size_t>(channels);
    for (int y = 0; y < height; ++y) {
      const bool opaque = filter_row(filter_, channels, source_row(y), y > 0 ? source_row(y - 1) : zero_row_.data(),
                                     w, filtered_.data() + static_cast<std::size_t>(y) * stride);
      if (!opaque && channels == 3) return false;
    }
    return true;
  };
  // opaque frames are filtered as RGB straight away, the alpha bytes checked in the same pass; a frame found
  // translucent is filtered again as RGBA
  int channels = 3;
  if (keep_alpha_ || !filter_rows(3)) {
    channels = 4;
    filter_rows(4);
  }
  last_rgb_ = channels == 3;
  const std::size_t filtered_size = static_cast<std::size_t>(height) * (1 + w * static_cast<std::size_t>(channels));
  const std::size_t bound = libdeflate_zlib_compress_bound(compressor_, filtered_size);
  out_size_ = 0;
  if (out_.size() < sizeof kSignature + kIhdrChunk + 12 + bound + kIendChunk)
    out_.resize(sizeof kSignature + kIhdrChunk + 12 + bound + kIendChunk);
  uint8_t* p = out_.data();
  std::memcpy(p, kSignature, sizeof kSignature);
  p += sizeof kSignature;
  // IHDR: width, height, bit depth 8, colour type 2 (RGB) or 6 (RGBA), deflate, adaptive filtering, no interlace
  std::memcpy(p + 4, "IHDR", 4);
  put_u32(p + 8, static_cast<uint32_t>(width));
  put_u32(p + 12, static_cast<uint32_t>(height));
  const uint8_t ihdr_tail[5] = {8, static_cast<uint8_t>(channels == 3 ? 2 : 6), 0, 0, 0};
  std::memcpy(p + 16, ihdr_tail, sizeof ihdr_tail);
  p = close_chunk(p, 13);
  // one IDAT holding the whole zlib stream
  std::memcpy(p + 4, "IDAT", 4);
  const std::size_t z = libdeflate_zlib_compress(compressor_, filtered_.data(), filtered_size, p + 8, bound);
  if (z == 0 || z > 0x7fffffffu) return make_error("png '", name, "': libdeflate: compression failed");
  p = close_chunk(p, static_cast<uint32_t>(z));
  std::memcpy(p + 4, "IEND", 4);
  p = close_chunk(p, 0);
  out_size_ = static_cast<std::size_t>(p - out_.data());
  return Ok{};
}

Status write_png(const std::string& path, int width, int height, const uint8_t* rgba, PngEncoder* encoder) {
  PngEncoder local;
  PngEncoder& enc = encoder != nullptr ? *encoder : local;
  if (auto st = enc.encode(width, height, rgba, path); !st) return st;
  // temp file beside the final name (never through a link, never over a device), renamed when complete
  auto out = AtomicFile::open(path, "png");
  if (!out) return out.error();
  AtomicFile& file = out.value();
  const auto& bytes = enc.bytes();
  file.write(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  return file.commit();
}

Result<Image> read_png(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return make_error("png '", path, "': ", std::strerror(errno));
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_stdio(&image, file)) {
    std::fclose(file);
    return make_error("png '", path, "': ", image.message);
  }
  if (image.width > kMaxSizePx || image.height > kMaxSizePx) {
    png_image_free(&image);
    std::fclose(file);
    return make_error("png '", path, "': size ", std::to_string(image.width), "x", std::to_string(image.height),
                      " exceeds ", std::to_string(kMaxSizePx));
  }
  image.format = PNG_FORMAT_RGBA;
  Image out;
  out.width = static_cast<int>(image.width);
  out.height = static_cast<int>(image.height);
  out.rgba.resize(PNG_IMAGE_SIZE(image));
  const bool ok = png_image_finish_read(&image, nullptr, out.rgba.data(), 0, nullptr) != 0;
  std::fclose(file);
  if (!ok) return make_error("png '", path, "': ", image.message);
  return out;
}

Result<Image> decode_png(const uint8_t* data, std::size_t size, const std::string& name) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&image, data, size)) return make_error("png '", name, "': ", image.message);
  if (image.width > kMaxSizePx || image.height > kMaxSizePx) {
    png_image_free(&image);
    return make_error("png '", name, "': size ", std::to_string(image.width), "x", std::to_string(image.height),
                      " exceeds ", std::to_string(kMaxSizePx));
  }
  image.format = PNG_FORMAT_RGBA;
  Image out;
  out.width = static_cast<int>(image.width);
  out.height = static_cast<int>(image.height);
  out.rgba.resize(PNG_IMAGE_SIZE(image));
  if (png_image_finish_read(&image, nullptr, out.rgba.data(), 0, nullptr) == 0)
    return make_error("png '", name, "': ", image.message);
  return out;
}

}  // namespace palpate
