#include "tools/video_command.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/limits.h"
#include "render/png_io.h"
#include "render/video_encoder.h"
#include "tools/session/frame_files.h"

namespace palpate {
namespace fs = std::filesystem;
namespace {

// the longest a realtime recording's frame is held in its video: ten minutes at 60 Hz
constexpr int64_t kMaxHeldFrames = 36'000;
// a side of a rendered frame at most (as a scene's render.width and render.height)
constexpr int64_t kMaxImageSide = 8192;

// the scene frame each file shows, from a realtime summary.json; empty when the files are frames 0, 1, 2, ...
Result<std::vector<int64_t>> scene_indices(const std::string& folder, std::size_t files) {
  const fs::path summary = fs::path(folder) / "summary.json";
  std::ifstream in(summary);
  if (!in) return std::vector<int64_t>{};
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded()) return make_error("summary '", summary.string(), "': not valid JSON");
  if (!j.contains("frames_scene_index")) return std::vector<int64_t>{};
  const auto& a = j["frames_scene_index"];
  if (!a.is_array() || a.size() != files)
    return make_error("summary '", summary.string(), "': frames_scene_index has ", std::to_string(a.size()),
                      " entries for ", std::to_string(files), " frame files");
  std::vector<int64_t> idx;
  for (const auto& v : a) {
    if (!v.is_number_integer() || v.get<int64_t>() < 0 || (!idx.empty() && v.get<int64_t>() <= idx.back()))
      return make_error("summary '", summary.string(), "': frames_scene_index[", std::to_string(idx.size()),
                        "] is not an increasing integer from 0");
    // a frame held longer than this is no recording's: it would make a video of days, or overflow its clock
    if (v.get<int64_t>() - (idx.empty() ? 0 : idx.back()) > kMaxHeldFrames)
      return make_error("summary '", summary.string(), "': frames_scene_index[", std::to_string(idx.size()), "] = ",
                        std::to_string(v.get<int64_t>()), " is more than ", std::to_string(kMaxHeldFrames),
                        " frames after the one before");
    idx.push_back(v.get<int64_t>());
  }
  return idx;
}

}  // namespace

Result<VideoCommandResult> make_recording_video(const std::string& folder, std::string out_path, int frame_rate_hz) {
  const fs::path frames_dir = fs::path(folder) / "frames";
  auto listed = list_frame_files(frames_dir.string());
  if (!listed) return make_error("recording '", folder, "': ", listed.error().message);
  const std::vector<FrameFile>& files = listed.value();
  auto idx = scene_indices(folder, files.size());
  if (!idx) return idx.error();
  if (out_path.empty()) out_path = (fs::path(folder) / "recording.mp4").string();

  // the size from each file's header before anything is decoded: a frame the renderer could not have made (a
  // few bytes can claim 32767 x 32767, a small file can inflate to gigabytes) is refused unread
  int64_t w = 0, h = 0;
  for (const FrameFile& f : files) {
    auto size = png_size(f.path);
    if (!size) return size.error();
    const auto [fw, fh] = size.value();
    if (w == 0) {
      if (fw < 1 || fh < 1 || fw > kMaxImageSide || fh > kMaxImageSide || fw * fh > kMaxImagePixels)
        return make_error("frame '", f.path, "': ", std::to_string(fw), "x", std::to_string(fh),
                          " is outside what a recording renders (sides 1..", std::to_string(kMaxImageSide), ", at most ",
                          std::to_string(kMaxImagePixels), " pixels)");
      w = fw;
      h = fh;
    } else if (fw != w || fh != h) {
      return make_error("frame '", f.path, "': ", std::to_string(fw), "x", std::to_string(fh),
                        " differs from the first frame's ", std::to_string(w), "x", std::to_string(h));
    }
  }
  auto enc_r = VideoEncoder::open(out_path, static_cast<int>(w), static_cast<int>(h), frame_rate_hz);
  if (!enc_r) return enc_r.error();
  VideoEncoder& enc = *enc_r.value();
  for (std::size_t i = 0; i < files.size(); ++i) {
    auto img = read_png(files[i].path);
    if (!img) return img.error();
    if (img.value().width != w || img.value().height != h)
      return make_error("frame '", files[i].path, "': ", std::to_string(img.value().width), "x",
                        std::to_string(img.value().height), " differs from the first frame's ", std::to_string(w), "x",
                        std::to_string(h));
    const int64_t index = idx.value().empty() ? static_cast<int64_t>(i) : idx.value()[i];
    if (auto st = enc.encode(img.value().rgba.data(), index); !st) return st.error();
  }
  if (auto st = enc.finish(); !st) return st.error();
  return VideoCommandResult{enc.path(), enc.encoder_name(), enc.frames(), enc.bytes()};
}

}  // namespace palpate
