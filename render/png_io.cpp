#include "render/png_io.h"

#include "core/atomic_file.h"

#include <png.h>
#include <zlib.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>

namespace palpate {

namespace {

constexpr int kMaxSizePx = 1 << 16;

// State shared with libpng's callbacks; plain data so longjmp over it is safe.
struct PngWriteState {
  std::FILE* file = nullptr;
  int saved_errno = 0;     // errno of the first failed fwrite
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
  if (std::fwrite(data, 1, length, state->file) != length) {
    if (state->saved_errno == 0) state->saved_errno = errno != 0 ? errno : EIO;
    png_error(png, "write failed");
  }
}

void on_png_flush(png_structp png) {
  auto* state = static_cast<PngWriteState*>(png_get_io_ptr(png));
  std::fflush(state->file);
}

// Encodes the image into state->file; false on failure with state's message/errno set.
// Only plain data lives in this frame, because libpng reports errors with longjmp.
bool encode_png(PngWriteState* state, int width, int height, const uint8_t* rgba) {
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
  png_set_compression_level(png, 1);
  png_set_compression_strategy(png, Z_RLE);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_BASE, PNG_FILTER_TYPE_BASE);
  png_write_info(png, info);
  const std::size_t row_bytes = static_cast<std::size_t>(width) * 4;
  for (int y = 0; y < height; ++y) {
    png_write_row(png, rgba + static_cast<std::size_t>(y) * row_bytes);
  }
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

Status write_png(const std::string& path, int width, int height, const uint8_t* rgba) {
  if (width < 1 || height < 1 || width > kMaxSizePx || height > kMaxSizePx) {
    return make_error("png '", path, "': size ", std::to_string(width), "x", std::to_string(height),
                      " outside 1..", std::to_string(kMaxSizePx));
  }
  if (rgba == nullptr) return make_error("png '", path, "': no pixel data");
  // temp file beside the final name (never through a link, never over a device), renamed when complete
  auto out = AtomicFile::open(path, "png");
  if (!out) return out.error();
  AtomicFile& file = out.value();
  PngWriteState state;
  state.file = file.stream();
  if (!encode_png(&state, width, height, rgba)) {
    file.discard();
    if (state.saved_errno != 0) return make_error("png '", path, "': ", std::strerror(state.saved_errno));
    return make_error("png '", path, "': libpng: ", state.message);
  }
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

}  // namespace palpate
