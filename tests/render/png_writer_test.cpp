#include "render/png_writer.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "render/png_io.h"
#include "render_test_util.h"

namespace palpate {
namespace {

constexpr int kW = 48;
constexpr int kH = 32;

std::string frame_path(const test::ScratchDir& dir, int index) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", index);
  return dir.file(name);
}

void fill_frame(uint8_t* rgba, int index) {
  for (int i = 0; i < kW * kH * 4; ++i) rgba[i] = static_cast<uint8_t>(index * 31 + i / 4 + (i % 4) * 64);
}

TEST(PngWriter, WritesNumberedFramesInOrder) {
  test::ScratchDir dir("png_writer");
  constexpr int kFrames = 12;
  std::vector<double> png_ms;
  {
    PngWriter writer(dir.str(), kW, kH, 3);
    for (int i = 1; i <= kFrames; ++i) {
      uint8_t* buffer = writer.acquire(/*block=*/true);
      ASSERT_NE(buffer, nullptr);
      fill_frame(buffer, i);
      writer.submit(i, buffer);
    }
    writer.finish();
    writer.finish();  // idempotent
    EXPECT_EQ(writer.frames_written(), kFrames);
    EXPECT_EQ(writer.write_errors(), 0) << writer.first_error();
    EXPECT_EQ(writer.first_error(), "");
    png_ms = writer.png_ms();
  }
  ASSERT_EQ(png_ms.size(), static_cast<std::size_t>(kFrames));
  for (double ms : png_ms) EXPECT_GT(ms, 0.0);

  std::vector<uint8_t> expected(kW * kH * 4);
  auto previous_time = std::filesystem::file_time_type::min();
  for (int i = 1; i <= kFrames; ++i) {
    auto image = read_png(frame_path(dir, i));
    ASSERT_TRUE(image.ok()) << image.error().message;
    fill_frame(expected.data(), i);
    EXPECT_EQ(image.value().rgba, expected) << "frame " << i;
    // one thread writes in submission order, so modification times never go backwards
    const auto t = std::filesystem::last_write_time(frame_path(dir, i));
    EXPECT_GE(t, previous_time) << "frame " << i;
    previous_time = t;
  }
  EXPECT_FALSE(std::filesystem::exists(frame_path(dir, 0)));
  EXPECT_FALSE(std::filesystem::exists(frame_path(dir, kFrames + 1)));
}

TEST(PngWriter, AcquireWithoutBlockingReturnsNullWhenPoolIsExhausted) {
  test::ScratchDir dir("png_writer");
  PngWriter writer(dir.str(), kW, kH, 2);
  uint8_t* a = writer.acquire(false);
  uint8_t* b = writer.acquire(false);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_NE(a, b);
  EXPECT_EQ(writer.acquire(false), nullptr);
  fill_frame(a, 7);
  writer.submit(7, a);
  uint8_t* c = writer.acquire(true);  // comes back once frame 7 is written
  EXPECT_EQ(c, a);
  writer.submit(8, b);
  writer.finish();
  EXPECT_EQ(writer.frames_written(), 2);
  EXPECT_EQ(writer.acquire(true), nullptr);  // finished: nothing to wait for
  EXPECT_TRUE(std::filesystem::exists(frame_path(dir, 7)));
  EXPECT_TRUE(std::filesystem::exists(frame_path(dir, 8)));
}

TEST(PngWriter, WriteFailuresAreCountedWithTheFirstPath) {
  test::ScratchDir dir("png_writer");
  const std::string missing = dir.file("missing");
  PngWriter writer(missing, kW, kH, 2);
  for (int i = 1; i <= 3; ++i) {
    uint8_t* buffer = writer.acquire(true);
    ASSERT_NE(buffer, nullptr);
    writer.submit(i, buffer);
  }
  writer.finish();
  EXPECT_EQ(writer.frames_written(), 0);
  EXPECT_EQ(writer.write_errors(), 3);
  EXPECT_NE(writer.first_error().find(missing + "/frame_00001.png"), std::string::npos) << writer.first_error();
  EXPECT_TRUE(writer.png_ms().empty());
}

TEST(PngWriter, SubmitAfterFinishAndForeignBuffersAreErrors) {
  test::ScratchDir dir("png_writer");
  PngWriter writer(dir.str(), kW, kH, 2);
  std::vector<uint8_t> foreign(kW * kH * 4);
  writer.submit(1, foreign.data());
  uint8_t* buffer = writer.acquire(false);
  ASSERT_NE(buffer, nullptr);
  writer.finish();
  writer.submit(2, buffer);
  EXPECT_EQ(writer.write_errors(), 2);
  EXPECT_EQ(writer.frames_written(), 0);
  EXPECT_NE(writer.first_error().find("frame_00001.png"), std::string::npos) << writer.first_error();
  EXPECT_TRUE(std::filesystem::is_empty(dir.str()));
}

}  // namespace
}  // namespace palpate
