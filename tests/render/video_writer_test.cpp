// The video writer on its own: every frame submitted before finish() is in the MP4 (the queue is drained, not
// dropped, when it stops), frames dropped only when asked not to block and counted, and gaps held.
#include "render/video_writer.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "render_test_util.h"
#include "support/cli_run.h"

namespace palpate {
namespace {

constexpr int kW = 320;
constexpr int kH = 240;

// a frame unlike its neighbours (so the encoder has work to do and cannot skip it)
std::vector<uint8_t> frame(int index) {
  std::vector<uint8_t> rgba(static_cast<std::size_t>(kW) * kH * 4);
  uint32_t x = 2654435761u * static_cast<uint32_t>(index + 1);
  for (std::size_t i = 0; i < rgba.size(); ++i) rgba[i] = (i % 4 == 3) ? 255 : static_cast<uint8_t>((x = x * 1664525u + 1013904223u) >> 24);
  return rgba;
}

// frames FFmpeg decodes from the file, and the stream's duration in seconds
std::pair<int, double> probe(const std::string& mp4) {
  const auto r = test::shell("ffprobe -v error -select_streams v:0 -count_frames -show_entries "
                             "stream=nb_read_frames,duration -of json '" + mp4 + "'");
  const auto j = nlohmann::json::parse(r.out, nullptr, false);
  if (j.is_discarded() || !j.contains("streams") || j["streams"].empty()) {
    ADD_FAILURE() << "ffprobe: " << r.out;
    return {-1, 0.0};
  }
  const auto& s = j["streams"][0];
  return {std::stoi(s.value("nb_read_frames", "-1")), std::stod(s.value("duration", "0"))};
}

// Frames submitted faster than they are encoded, with a queue of two: finish() must encode every one still
// queued (a writer that stopped on the flag with frames queued lost the last ones).
TEST(VideoWriter, FinishEncodesEveryQueuedFrame) {
  test::ScratchDir dir("video_writer_all");
  const std::string mp4 = dir.file("all.mp4");
  auto enc = VideoEncoder::open(mp4, kW, kH, 60);
  ASSERT_TRUE(enc) << enc.error().message;
  VideoWriter w(std::move(enc).value(), kW, kH, 2);
  for (int i = 0; i < 90; ++i) ASSERT_TRUE(w.submit(i, frame(i).data(), true)) << i;
  ASSERT_TRUE(w.finish());
  EXPECT_EQ(w.frames_encoded(), 90);
  EXPECT_EQ(w.frames_dropped(), 0);
  EXPECT_EQ(w.encoder().frames(), 90);
  const auto [frames, duration_s] = probe(mp4);
  EXPECT_EQ(frames, 90);
  EXPECT_NEAR(duration_s, 90.0 / 60.0, 1.5 / 60.0);
}

// Without blocking, a full queue drops the frame and counts it: encoded + dropped = submitted, and the MP4 holds
// exactly the frames encoded; a gap in the indices holds the frame before it.
TEST(VideoWriter, DroppedFramesAreCountedAndGapsHeld) {
  test::ScratchDir dir("video_writer_drop");
  const std::string mp4 = dir.file("drop.mp4");
  auto enc = VideoEncoder::open(mp4, kW, kH, 60);
  ASSERT_TRUE(enc) << enc.error().message;
  VideoWriter w(std::move(enc).value(), kW, kH, 1);
  int accepted = 0;
  for (int i = 0; i < 60; ++i) accepted += w.submit(i * 2, frame(i).data(), false) ? 1 : 0;
  ASSERT_TRUE(w.finish());
  EXPECT_EQ(w.frames_encoded(), accepted);
  EXPECT_EQ(w.frames_encoded() + w.frames_dropped(), 60);
  EXPECT_FALSE(w.submit(200, frame(0).data(), true)) << "a frame after finish() was taken";
  const auto [frames, duration_s] = probe(mp4);
  EXPECT_EQ(frames, accepted);
  EXPECT_GT(duration_s, 1.5 * accepted / 60.0) << "the gaps between indices are not held";
}

}  // namespace
}  // namespace palpate
