// The MP4 beside a recording, checked by FFmpeg's own tools: codec, pixel format, rate, frame count, the index
// before the data, and the pixels of a decoded frame against the PNG of the same frame.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "render/png_io.h"
#include "support/cli_run.h"
#include "support/fixtures.h"
#include "support/json_file.h"
#include "support/read_file.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

using test::CliRun;
using test::palpate;
using test::read_json;
using test::shell;

// ffprobe's view of the first video stream, frames counted by decoding
nlohmann::json probe(const std::string& mp4) {
  const CliRun r = shell("ffprobe -v error -select_streams v:0 -count_frames -show_entries "
                      "stream=codec_name,pix_fmt,r_frame_rate,nb_frames,nb_read_frames,width,height -of json '" + mp4 + "'");
  EXPECT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
  if (j.is_discarded() || !j.contains("streams") || j["streams"].empty()) {
    ADD_FAILURE() << "ffprobe: " << r.out;
    return nlohmann::json::object();
  }
  return j["streams"][0];
}

// top-level MP4 box types in file order
std::vector<std::string> top_level_boxes(const std::string& mp4) {
  std::ifstream in(mp4, std::ios::binary);
  std::vector<std::string> types;
  const auto size = static_cast<uint64_t>(fs::file_size(mp4));
  uint64_t pos = 0;
  while (pos + 8 <= size) {
    in.seekg(static_cast<std::streamoff>(pos));
    unsigned char h[16] = {};
    in.read(reinterpret_cast<char*>(h), 16);
    uint64_t len = (uint64_t{h[0]} << 24) | (uint64_t{h[1]} << 16) | (uint64_t{h[2]} << 8) | h[3];
    types.emplace_back(reinterpret_cast<char*>(h + 4), 4);
    if (len == 1) {
      len = 0;
      for (int i = 8; i < 16; ++i) len = (len << 8) | h[i];
    } else if (len == 0) {
      len = size - pos;
    }
    if (len < 8) break;
    pos += len;
  }
  return types;
}

void expect_browser_ready(const std::string& mp4, int64_t frames) {
  const nlohmann::json s = probe(mp4);
  EXPECT_EQ(s.value("codec_name", ""), "h264");
  EXPECT_EQ(s.value("pix_fmt", ""), "yuv420p");
  EXPECT_EQ(s.value("r_frame_rate", ""), "60/1");
  EXPECT_EQ(s.value("nb_frames", ""), std::to_string(frames));
  EXPECT_EQ(s.value("nb_read_frames", ""), std::to_string(frames));
  const auto boxes = top_level_boxes(mp4);
  const auto moov = std::find(boxes.begin(), boxes.end(), "moov");
  const auto mdat = std::find(boxes.begin(), boxes.end(), "mdat");
  ASSERT_NE(moov, boxes.end());
  ASSERT_NE(mdat, boxes.end());
  EXPECT_LT(moov - boxes.begin(), mdat - boxes.begin()) << "moov must precede mdat (faststart)";
}

// mean absolute difference over R, G, B between frame n of the MP4 (decoded by ffmpeg) and a PNG
double mean_abs_diff(const std::string& mp4, int n, const std::string& png, const std::string& scratch) {
  const CliRun r = shell("ffmpeg -v error -y -i '" + mp4 + "' -vf 'select=eq(n\\," + std::to_string(n) +
                      ")' -frames:v 1 -pix_fmt rgba '" + scratch + "'");
  EXPECT_EQ(r.code, 0) << r.out;
  auto a = read_png(scratch);
  auto b = read_png(png);
  if (!a || !b) {
    ADD_FAILURE() << (a ? b.error().message : a.error().message);
    return 1e9;
  }
  EXPECT_EQ(a.value().width, b.value().width);
  EXPECT_EQ(a.value().height, b.value().height);
  if (a.value().rgba.size() != b.value().rgba.size()) return 1e9;
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < a.value().rgba.size(); i += 4)
    for (int c = 0; c < 3; ++c, ++count) sum += std::abs(int{a.value().rgba[i + c]} - int{b.value().rgba[i + c]});
  return sum / static_cast<double>(count);
}

// lossy H.264 at crf 20 of a rendered frame stays within a few levels on average (3.2 measured on cube_press);
// a broken colour conversion (swapped channels, full/limited range mixed up) is off by far more
constexpr double kLossyMeanTol = 5.0;

TEST(Video, LockstepRecordingGivesBrowserReadyMp4) {
  const std::string out = test::fresh_dir("video_lockstep");
  const CliRun r = palpate("record scenes/cube_press.json --duration 0.5 -q --out '" + out + "'");
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json sum = read_json(out + "/summary.json");
  const int64_t written = sum["frames_written"].get<int64_t>();
  EXPECT_EQ(written, 30);
  // on by default, at <out>/recording.mp4
  const std::string mp4 = out + "/recording.mp4";
  ASSERT_TRUE(fs::exists(mp4)) << r.out;
  EXPECT_FALSE(fs::exists(mp4 + ".tmp"));
  const nlohmann::json& v = sum["video"];
  EXPECT_TRUE(v["enabled"].get<bool>());
  EXPECT_EQ(v["path"], mp4);
  EXPECT_EQ(v["codec"], "h264");
  EXPECT_EQ(v["frames"].get<int64_t>(), written);
  EXPECT_EQ(v["frames_dropped"].get<int64_t>(), 0);
  EXPECT_EQ(v["bytes"].get<int64_t>(), static_cast<int64_t>(fs::file_size(mp4)));
  EXPECT_EQ(v["encode_ms"]["count"].get<int64_t>(), written);
  EXPECT_GT(v["encode_ms"]["p99"].get<double>(), 0.0);
  expect_browser_ready(mp4, written);
  for (int n : {0, 20}) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.png", n);
    const double mad = mean_abs_diff(mp4, n, out + "/frames/" + name, out + "/decoded.png");
    EXPECT_LT(mad, kLossyMeanTol) << "frame " << n;
  }

  // the same frames through `palpate video` give an equivalent file
  const std::string again = out + "/again.mp4";
  const CliRun rv = palpate("video '" + out + "' --out '" + again + "'");
  ASSERT_EQ(rv.code, 0) << rv.out;
  EXPECT_NE(rv.out.find("30 frames"), std::string::npos) << rv.out;
  expect_browser_ready(again, written);
  EXPECT_LT(mean_abs_diff(again, 20, out + "/frames/frame_00020.png", out + "/decoded.png"), kLossyMeanTol);
}

TEST(Video, ExplicitPathAndNoVideo) {
  const std::string out = test::fresh_dir("video_explicit");
  fs::create_directories(out);
  const std::string mp4 = out + "/press.mp4";
  const CliRun r = palpate("record scenes/cube_press.json --duration 0.1 -q --out '" + out + "/rec' --video '" + mp4 + "'");
  ASSERT_EQ(r.code, 0) << r.out;
  expect_browser_ready(mp4, 6);
  EXPECT_FALSE(fs::exists(out + "/rec/recording.mp4"));

  const CliRun rn = palpate("record scenes/cube_press.json --duration 0.1 -q --out '" + out + "/none' --no-video");
  ASSERT_EQ(rn.code, 0) << rn.out;
  EXPECT_FALSE(fs::exists(out + "/none/recording.mp4"));
  const nlohmann::json sum = read_json(out + "/none/summary.json");
  EXPECT_FALSE(sum["video"]["enabled"].get<bool>());
  EXPECT_NE(sum["video"]["reason"].get<std::string>().find("--no-video"), std::string::npos);
}

TEST(Video, RealtimeRecordingMakesItsDefaultVideoAfterTheRun) {
  // no encoder thread beside the servo during a realtime run: the MP4 is made from the frames afterwards
  const std::string out = test::fresh_dir("video_realtime");
  const CliRun r = palpate("record scenes/cube_press.json --mode realtime --duration 0.5 -q --out '" + out + "'");
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json sum = read_json(out + "/summary.json");
  ASSERT_TRUE(sum["video"]["enabled"].get<bool>()) << sum["video"].dump();
  EXPECT_EQ(sum["video"]["made"].get<std::string>(), "after the realtime run, from frames/");
  EXPECT_GT(sum["video"]["frames"].get<int64_t>(), 0);
  EXPECT_TRUE(fs::exists(out + "/recording.mp4"));
}

TEST(Video, BadVideoPathIsAnErrorBeforeRecording) {
  const std::string out = test::fresh_dir("video_bad");
  fs::create_directories(out + "/a_folder");
  for (const std::string& bad : {out + "/a_folder", std::string("/dev/null")}) {
    const std::string rec = out + "/rec";
    const CliRun r = palpate("record scenes/cube_press.json --duration 0.1 -q --out '" + rec + "' --video '" + bad + "'");
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_NE(r.out.find("video '" + bad + "': is not a regular file"), std::string::npos) << r.out;
    // nothing was recorded
    EXPECT_FALSE(fs::exists(rec)) << bad;
  }
  EXPECT_TRUE(fs::is_directory(out + "/a_folder"));
}

TEST(Video, VideoCommandErrorsNameTheFolder) {
  const std::string out = test::fresh_dir("video_empty");
  fs::create_directories(out + "/frames");
  const CliRun r = palpate("video '" + out + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("recording '" + out + "': no frame_*.png in '" + out + "/frames'"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out + "/recording.mp4"));
}


// a small recording folder of n solid frames (frame i has red = i % 256) named frame_%0Nd.png
std::string frames_folder(const std::string& name, int n, int digits = 5) {
  const std::string out = test::fresh_dir(name);
  fs::create_directories(out + "/frames");
  std::vector<uint8_t> rgba(32 * 16 * 4, 255);
  for (int i = 0; i < n; ++i) {
    for (std::size_t p = 0; p < rgba.size(); p += 4) rgba[p] = static_cast<uint8_t>(i % 256);
    char file[64];
    std::snprintf(file, sizeof file, "/frames/frame_%0*d.png", digits, i);
    EXPECT_TRUE(write_png(out + file, 32, 16, rgba.data()));
  }
  return out;
}

// Frames are taken in the order of their number, not of their name's text: frame_10 follows frame_9 when the
// names are not zero-padded to one width (as past frame 99,999 of %05d). The MP4's frame 10 must be file 10.
TEST(Video, FramesAreOrderedByNumberNotByName) {
  const std::string out = frames_folder("video_numeric", 12, 1);
  const CliRun r = palpate("video '" + out + "'");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(probe(out + "/recording.mp4").value("nb_read_frames", ""), "12");
  // text order would put frame_10 and frame_11 right after frame_1
  EXPECT_LT(mean_abs_diff(out + "/recording.mp4", 10, out + "/frames/frame_10.png", out + "/f10.png"), 2.0);
  EXPECT_LT(mean_abs_diff(out + "/recording.mp4", 2, out + "/frames/frame_2.png", out + "/f2.png"), 2.0);
}

// A frame missing from the sequence is named (it would shift every later frame); so are numbers far apart.
TEST(Video, MissingFrameIsNamedNotShiftedOver) {
  const std::string out = frames_folder("video_missing", 6);
  fs::remove(out + "/frames/frame_00003.png");
  CliRun r = palpate("video '" + out + "'");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("frame 3 is missing"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out + "/recording.mp4"));
  fs::rename(out + "/frames/frame_00005.png", out + "/frames/frame_1000000000.png");
  fs::rename(out + "/frames/frame_00004.png", out + "/frames/frame_00003.png");
  r = palpate("video '" + out + "'");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("frame 4 is missing"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("frame_1000000000.png"), std::string::npos) << r.out;
  fs::rename(out + "/frames/frame_1000000000.png", out + "/frames/frame_99999999999999.png");
  r = palpate("video '" + out + "'");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("frame_99999999999999.png': the name is not frame_N.png"), std::string::npos) << r.out;
  // a realtime summary's scene frames 1e12 apart: refused, not a video of a fraction of a second
  fs::remove(out + "/frames/frame_99999999999999.png");
  std::ofstream(out + "/summary.json") << R"({"frames_scene_index": [0, 1, 2, 1000000000000]})";
  r = palpate("video '" + out + "'");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("frames_scene_index[3] = 1000000000000 is more than 36000 frames after"), std::string::npos)
      << r.out;
  EXPECT_FALSE(fs::exists(out + "/recording.mp4"));
}

// A FIFO under a frame's name would block the reader for ever: refused by name before anything is opened.
TEST(Video, FifoFrameIsRefusedNotWaitedOn) {
  const std::string out = frames_folder("video_fifo", 5);
  fs::remove(out + "/frames/frame_00003.png");
  ASSERT_EQ(::mkfifo((out + "/frames/frame_00003.png").c_str(), 0600), 0);
  const CliRun r = shell("timeout 60 " + std::string(std::getenv("PALPATE_BIN_DIR") ? std::getenv("PALPATE_BIN_DIR") : "build/bin") +
                         "/palpate video '" + out + "'");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("frame_00003.png': not a regular file"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out + "/recording.mp4"));
  EXPECT_FALSE(fs::exists(out + "/recording.mp4.tmp"));
}

// A PNG whose header claims a size no recording renders is refused from its header, never decoded: 68 bytes
// claiming 32767 x 32767 (4.3 GB to decode), and a frame of another size than the first.
TEST(Video, FrameSizeIsCheckedBeforeDecoding) {
  const std::string out = frames_folder("video_huge", 3);
  // a valid PNG's IHDR with the size patched (the CRC no longer matches: nothing may read past the header)
  std::string png = test::read_file(out + "/frames/frame_00000.png");
  ASSERT_GT(png.size(), 24u);
  const unsigned char big[8] = {0, 0, 0x7f, 0xff, 0, 0, 0x7f, 0xff};
  std::memcpy(png.data() + 16, big, 8);
  std::ofstream(out + "/frames/frame_00000.png", std::ios::binary) << png;
  CliRun r = palpate("video '" + out + "'");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("frame_00000.png': 32767x32767 is outside what a recording renders"), std::string::npos) << r.out;
  std::ofstream(out + "/frames/frame_00000.png", std::ios::binary) << "\x89PNG\r\n\x1a\n";
  r = palpate("video '" + out + "'");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("frame_00000.png': not a PNG file"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out + "/recording.mp4"));
}

// A realtime run asked to write its video over one of its own frames: refused by name before anything is
// written (it ended in a raw libav line, after the previous run's files were gone).
TEST(Video, VideoPathInsideTheFramesFolderIsRefused) {
  const std::string out = test::fresh_dir("video_in_frames");
  const CliRun r = palpate("record scenes/cube_press.json --mode realtime --duration 0.2 --video '" + out +
                           "/frames/frame_00003.png' --out '" + out + "'");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("palpate: --video '" + out + "/frames/frame_00003.png': is where the recording writes its frames"),
            std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("[mp4 @"), std::string::npos) << "a raw libav line: " << r.out;
  EXPECT_FALSE(fs::exists(out + "/summary.json"));
}

}  // namespace
}  // namespace palpate
