#include "render/png_io.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <span>

#include "render_test_util.h"
#include "support/file_size_limit.h"

namespace palpate {
namespace {

std::vector<uint8_t> random_rgba(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<uint8_t> rgba(static_cast<std::size_t>(width) * height * 4);
  for (auto& b : rgba) b = static_cast<uint8_t>(rng());
  return rgba;
}

TEST(PngIo, RoundTripIsBitExact) {
  test::ScratchDir dir("png_io");
  for (const auto& [w, h] : {std::pair{1, 1}, {37, 19}, {64, 48}}) {
    const auto rgba = random_rgba(w, h, static_cast<unsigned>(w * 131 + h));
    const std::string path = dir.file("img_" + std::to_string(w) + ".png");
    const Status written = write_png(path, w, h, rgba.data());
    ASSERT_TRUE(written.ok()) << written.error().message;
    EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
    auto image = read_png(path);
    ASSERT_TRUE(image.ok()) << image.error().message;
    EXPECT_EQ(image.value().width, w);
    EXPECT_EQ(image.value().height, h);
    EXPECT_EQ(image.value().rgba, rgba);
  }
}

TEST(PngIo, SmoothImageRoundTripsAndOverwrites) {
  test::ScratchDir dir("png_io");
  const int w = 320, h = 240;
  std::vector<uint8_t> rgba(w * h * 4);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      uint8_t* p = &rgba[(y * w + x) * 4];
      p[0] = uint8_t(x), p[1] = uint8_t(y), p[2] = 200, p[3] = 255;
    }
  }
  const std::string path = dir.file("smooth.png");
  ASSERT_TRUE(write_png(path, w, h, random_rgba(w, h, 7).data()).ok());
  ASSERT_TRUE(write_png(path, w, h, rgba.data()).ok());
  auto image = read_png(path);
  ASSERT_TRUE(image.ok()) << image.error().message;
  EXPECT_EQ(image.value().rgba, rgba);
  // a gradient is where a predictor pays off: with SUB the fast level still compresses it well
  PngEncoder sub;
  sub.set_filter(PngFilter::kSub);
  ASSERT_TRUE(write_png(path, w, h, rgba.data(), &sub).ok());
  EXPECT_EQ(read_png(path).value().rgba, rgba);
  EXPECT_LT(std::filesystem::file_size(path), rgba.size() / 4);
}

uint32_t be32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}

// Walks the chunks of a PNG: signature, IHDR first, CRC-32 of each chunk (checked with zlib's crc32, not the
// encoder's), IEND last. Returns the chunk types in order; the colour type in *colour_type.
std::vector<std::string> chunks_of(std::span<const uint8_t> png, int* colour_type) {
  static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<std::string> types;
  if (png.size() < 8 || !std::equal(sig, sig + 8, png.begin())) {
    ADD_FAILURE() << "no PNG signature";
    return types;
  }
  std::size_t at = 8;
  while (at + 12 <= png.size()) {
    const uint32_t len = be32(&png[at]);
    if (at + 12 + len > png.size()) {
      ADD_FAILURE() << "chunk runs past the end";
      break;
    }
    types.emplace_back(reinterpret_cast<const char*>(&png[at + 4]), 4);
    const uLong crc = crc32(crc32(0L, Z_NULL, 0), &png[at + 4], 4 + len);
    EXPECT_EQ(crc, be32(&png[at + 8 + len])) << "CRC of chunk " << types.back();
    if (types.back() == "IHDR") *colour_type = png[at + 8 + 9];
    at += 12 + len;
  }
  EXPECT_EQ(at, png.size()) << "bytes after the last chunk";
  return types;
}

TEST(PngIo, OpaqueFramesAreStoredAsRgbAndReadBackAsTheSameRgba) {
  for (PngCodec codec : {PngCodec::kZlib, PngCodec::kLibdeflate}) {
    PngEncoder enc(codec);
    for (const auto& [w, h] : {std::pair{1, 1}, std::pair{37, 19}, std::pair{640, 48}}) {
      auto rgba = random_rgba(w, h, static_cast<unsigned>(w + 7 * h));
      for (std::size_t i = 3; i < rgba.size(); i += 4) rgba[i] = 255;
      ASSERT_TRUE(enc.encode(w, h, rgba.data(), "opaque").ok());
      int colour = -1;
      const auto chunks = chunks_of(enc.bytes(), &colour);
      ASSERT_GE(chunks.size(), 3u);
      EXPECT_EQ(chunks.front(), "IHDR");
      EXPECT_EQ(chunks.back(), "IEND");
      for (std::size_t c = 1; c + 1 < chunks.size(); ++c) EXPECT_EQ(chunks[c], "IDAT");
      if (codec == PngCodec::kLibdeflate) {
        EXPECT_EQ(chunks.size(), 3u) << "one IDAT";
      }
      EXPECT_EQ(colour, 2) << "RGB";
      EXPECT_TRUE(enc.last_rgb());
      auto back = decode_png(enc.bytes().data(), enc.bytes().size(), "opaque");
      ASSERT_TRUE(back.ok()) << back.error().message;
      EXPECT_EQ(back.value().rgba, rgba) << w << "x" << h;
      // one pixel not quite opaque: the alpha channel is kept, and still exact
      rgba[rgba.size() - 1] = 254;
      ASSERT_TRUE(enc.encode(w, h, rgba.data(), "translucent").ok());
      EXPECT_EQ((chunks_of(enc.bytes(), &colour), colour), 6) << "RGBA";
      EXPECT_FALSE(enc.last_rgb());
      back = decode_png(enc.bytes().data(), enc.bytes().size(), "translucent");
      ASSERT_TRUE(back.ok()) << back.error().message;
      EXPECT_EQ(back.value().rgba, rgba) << w << "x" << h;
    }
  }
}

// The inflated image data of a PNG with one IDAT chunk (the libdeflate codec's layout): per row the filter type
// byte and the filtered bytes. Empty when there is no single IDAT or it does not inflate to `expected` bytes.
std::vector<uint8_t> inflated_idat(std::span<const uint8_t> png, std::size_t expected) {
  std::size_t at = 8;
  std::vector<uint8_t> out;
  while (at + 12 <= png.size()) {
    const uint32_t len = be32(&png[at]);
    if (std::string(reinterpret_cast<const char*>(&png[at + 4]), 4) == "IDAT") {
      out.resize(expected + 1);
      uLongf size = static_cast<uLongf>(out.size());
      if (uncompress(out.data(), &size, &png[at + 8], len) != Z_OK || size != expected) return {};
      out.resize(size);
      return out;
    }
    at += 12 + len;
  }
  return {};
}

// Rendered-like content: flat background, a smooth disc, a few lines and a noisy corner.
std::vector<uint8_t> frame_like_rgba(int w, int h, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<uint8_t> rgba(static_cast<std::size_t>(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = &rgba[(static_cast<std::size_t>(y) * w + x) * 4];
      const bool disc = (x - w / 2) * (x - w / 2) + (y - h / 2) * (y - h / 2) < (h / 3) * (h / 3);
      const bool line = (x + 2 * y) % 17 == 0;
      const bool noise = x < w / 5 && y < h / 4;
      p[0] = noise ? uint8_t(rng()) : line ? 30 : disc ? uint8_t(3 * x + y) : 247;
      p[1] = noise ? uint8_t(rng()) : line ? 40 : disc ? uint8_t(x ^ y) : 247;
      p[2] = noise ? uint8_t(rng()) : line ? 50 : disc ? uint8_t(200 - y) : 250;
      p[3] = 255;
    }
  return rgba;
}

std::vector<uint8_t> flipped(const std::vector<uint8_t>& rgba, int w, int h) {
  std::vector<uint8_t> out(rgba.size());
  const std::size_t row = static_cast<std::size_t>(w) * 4;
  for (int y = 0; y < h; ++y)
    std::copy_n(rgba.begin() + static_cast<std::ptrdiff_t>(y * row), row,
                out.begin() + static_cast<std::ptrdiff_t>((h - 1 - y) * row));
  return out;
}

TEST(PngIo, EveryRowFilterDecodesToTheSamePixelsAndIsTheOneUsed) {
  // libpng undoes the filters by the PNG specification: a wrong predictor (Paeth's ties, the first row and
  // column) shows up as different pixels
  for (PngFilter filter : {PngFilter::kNone, PngFilter::kSub, PngFilter::kUp, PngFilter::kPaeth}) {
    for (const auto& [w, h] : {std::pair{1, 1}, std::pair{2, 3}, std::pair{37, 19}, std::pair{640, 48}}) {
      for (int variant = 0; variant < 3; ++variant) {  // opaque; one translucent pixel half-way; RGBA kept
        auto rgba = frame_like_rgba(w, h, static_cast<unsigned>(w * 7 + h));
        if (variant == 1) rgba[(static_cast<std::size_t>(h / 2) * w + w / 2) * 4 + 3] = 254;
        PngEncoder enc(PngCodec::kLibdeflate);
        enc.set_filter(filter);
        enc.set_keep_alpha(variant == 2);
        const std::string what = "filter " + std::to_string(static_cast<int>(filter)) + " " + std::to_string(w) +
                                 "x" + std::to_string(h) + " variant " + std::to_string(variant);
        ASSERT_TRUE(enc.encode(w, h, rgba.data(), "f").ok()) << what;
        const int channels = variant == 0 ? 3 : 4;
        EXPECT_EQ(enc.last_rgb(), channels == 3) << what;
        int colour = -1;
        chunks_of(enc.bytes(), &colour);
        EXPECT_EQ(colour, channels == 3 ? 2 : 6) << what;
        const std::size_t stride = 1 + static_cast<std::size_t>(w) * channels;
        const auto rows = inflated_idat(enc.bytes(), stride * static_cast<std::size_t>(h));
        ASSERT_EQ(rows.size(), stride * static_cast<std::size_t>(h)) << what;
        for (int y = 0; y < h; ++y) ASSERT_EQ(rows[y * stride], static_cast<uint8_t>(filter)) << what << " row " << y;
        auto back = decode_png(enc.bytes().data(), enc.bytes().size(), what);
        ASSERT_TRUE(back.ok()) << back.error().message;
        EXPECT_EQ(back.value().rgba, rgba) << what;
        // the same image given bottom-up (as GL reads it) makes the same file
        const std::vector<uint8_t> top_down(enc.bytes().begin(), enc.bytes().end());
        const auto upside_down = flipped(rgba, w, h);
        enc.set_bottom_up(true);
        ASSERT_TRUE(enc.encode(w, h, upside_down.data(), "f").ok()) << what;
        EXPECT_TRUE(std::equal(top_down.begin(), top_down.end(), enc.bytes().begin(), enc.bytes().end()))
            << what << " bottom-up";
      }
    }
  }
}

TEST(PngIo, BottomUpRowsThroughZlibReadBackTopDown) {
  const int w = 37, h = 19;
  const auto rgba = frame_like_rgba(w, h, 5);
  const auto upside_down = flipped(rgba, w, h);
  PngEncoder enc(PngCodec::kZlib);
  enc.set_bottom_up(true);
  ASSERT_TRUE(enc.encode(w, h, upside_down.data(), "zlib").ok());
  auto back = decode_png(enc.bytes().data(), enc.bytes().size(), "zlib");
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back.value().rgba, rgba);
}

TEST(PngIo, LibdeflateAndZlibGiveTheSamePixelsAndTheFileReadsBack) {
  // a smooth opaque image with flat areas (like a rendered frame) through both codecs, to files and back
  test::ScratchDir dir("png_codecs");
  const int w = 320, h = 240;
  std::vector<uint8_t> rgba(w * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = &rgba[(y * w + x) * 4];
      const bool disc = (x - 160) * (x - 160) + (y - 120) * (y - 120) < 80 * 80;
      p[0] = disc ? uint8_t(x) : 40, p[1] = disc ? uint8_t(y) : 40, p[2] = disc ? 200 : 48, p[3] = 255;
    }
  for (PngCodec codec : {PngCodec::kZlib, PngCodec::kLibdeflate}) {
    PngEncoder enc(codec);
    enc.set_filter(PngFilter::kSub);  // the zlib codec's filter (the disc is a gradient)
    const std::string path = dir.file(codec == PngCodec::kZlib ? "zlib.png" : "deflate.png");
    ASSERT_TRUE(write_png(path, w, h, rgba.data(), &enc).ok());
    auto image = read_png(path);
    ASSERT_TRUE(image.ok()) << image.error().message;
    EXPECT_EQ(image.value().rgba, rgba);
    EXPECT_LT(std::filesystem::file_size(path), rgba.size() / 8);
  }
}

TEST(PngIo, WriteIntoMissingDirectoryNamesThePathAndLeavesNoFile) {
  test::ScratchDir dir("png_io");
  const std::string path = dir.file("no_such_dir/frame_00001.png");
  const auto rgba = random_rgba(8, 8, 1);
  const Status written = write_png(path, 8, 8, rgba.data());
  ASSERT_FALSE(written.ok());
  EXPECT_NE(written.error().message.find("png '" + path + "'"), std::string::npos) << written.error().message;
  EXPECT_NE(written.error().message.find("No such file or directory"), std::string::npos)
      << written.error().message;
  EXPECT_TRUE(std::filesystem::is_empty(dir.str()));
}

TEST(PngIo, FailedWriteNamesThePathAndLeavesNoFrame) {
  // a file size limit makes the writes fail (EFBIG) as a full disk does (ENOSPC)
  test::ScratchDir dir("png_full");
  const std::string path = dir.file("frame_00003.png");
  const auto rgba = random_rgba(256, 256, 3);
  Status written = Ok{};
  {
    test::FileSizeLimit limit(4096);
    written = write_png(path, 256, 256, rgba.data());
  }
  ASSERT_FALSE(written.ok());
  EXPECT_NE(written.error().message.find("png '" + path + "'"), std::string::npos) << written.error().message;
  EXPECT_NE(written.error().message.find("File too large"), std::string::npos) << written.error().message;
  EXPECT_FALSE(std::filesystem::exists(path));  // never a half-written frame under the final name
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
}

TEST(PngIo, APlantedLinkAtTheTemporaryNameIsNotFollowed) {
  // a link planted at the temporary name (here to /dev/full) is replaced, never written through
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  test::ScratchDir dir("png_link");
  const std::string path = dir.file("frame_00003.png");
  std::filesystem::create_symlink("/dev/full", path + ".tmp");
  const auto rgba = random_rgba(64, 64, 3);
  const Status written = write_png(path, 64, 64, rgba.data());
  ASSERT_TRUE(written.ok()) << written.error().message;
  EXPECT_TRUE(std::filesystem::is_regular_file(path));
  EXPECT_TRUE(std::filesystem::is_character_file("/dev/full"));
}

TEST(PngIo, WriteOverADirectoryFailsAndRemovesTheTemporary) {
  // the rename onto an existing directory fails after the data was written
  test::ScratchDir dir("png_io");
  const std::string path = dir.file("taken.png");
  std::filesystem::create_directory(path);
  std::filesystem::create_directory(path + "/inside");
  const auto rgba = random_rgba(8, 8, 2);
  const Status written = write_png(path, 8, 8, rgba.data());
  ASSERT_FALSE(written.ok());
  EXPECT_NE(written.error().message.find(path), std::string::npos) << written.error().message;
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
}

TEST(PngIo, BadSizeIsRejected) {
  test::ScratchDir dir("png_io");
  const uint8_t px[4] = {0, 0, 0, 0};
  const Status written = write_png(dir.file("unused.png"), 0, 1, px);
  ASSERT_FALSE(written.ok());
  EXPECT_NE(written.error().message.find("0x1"), std::string::npos) << written.error().message;
  EXPECT_TRUE(std::filesystem::is_empty(dir.str()));
}

TEST(PngIo, ReadErrorsNameThePath) {
  test::ScratchDir dir("png_io");
  const std::string missing = dir.file("missing.png");
  auto a = read_png(missing);
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.error().message.find("png '" + missing + "'"), std::string::npos) << a.error().message;

  const std::string junk = dir.file("junk.png");
  std::ofstream(junk) << "this is not a png file at all";
  auto b = read_png(junk);
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.error().message.find("png '" + junk + "'"), std::string::npos) << b.error().message;
}

}  // namespace
}  // namespace palpate
