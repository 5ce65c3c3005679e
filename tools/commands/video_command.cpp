#include "tools/commands/video_command.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "runtime/record/frame_files.h"
#include "runtime/record/video_output.h"

namespace palpate {
namespace fs = std::filesystem;
namespace {

// the longest a realtime recording's frame is held in its video: ten minutes at 60 Hz
constexpr int64_t kMaxHeldFrames = 36'000;

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

  std::vector<std::string> names;
  for (const FrameFile& f : files) names.push_back(f.path);
  auto made = encode_png_frames(names, idx.value(), out_path, frame_rate_hz);
  if (!made) return made.error();
  return VideoCommandResult{made.value().path, made.value().encoder, made.value().frames, made.value().bytes};
}

}  // namespace palpate
