#include "tools/video_command.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "tools/session/video_output.h"

namespace palpate {
namespace fs = std::filesystem;
namespace {

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
    if (!v.is_number_integer() || (!idx.empty() && v.get<int64_t>() <= idx.back()))
      return make_error("summary '", summary.string(), "': frames_scene_index[", std::to_string(idx.size()),
                        "] is not an increasing integer");
    idx.push_back(v.get<int64_t>());
  }
  return idx;
}

}  // namespace

Result<VideoCommandResult> make_recording_video(const std::string& folder, std::string out_path, int frame_rate_hz) {
  const fs::path frames_dir = fs::path(folder) / "frames";
  std::error_code ec;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(frames_dir, ec)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() == ".png" && name.rfind("frame_", 0) == 0) files.push_back(e.path());
  }
  if (ec) return make_error("recording '", folder, "': cannot read '", frames_dir.string(), "': ", ec.message());
  if (files.empty()) return make_error("recording '", folder, "': no frames/frame_*.png");
  std::sort(files.begin(), files.end());
  auto idx = scene_indices(folder, files.size());
  if (!idx) return idx.error();
  if (out_path.empty()) out_path = (fs::path(folder) / "recording.mp4").string();

  std::vector<std::string> names;
  for (const fs::path& f : files) names.push_back(f.string());
  auto made = encode_png_frames(names, idx.value(), out_path, frame_rate_hz);
  if (!made) return made.error();
  return VideoCommandResult{made.value().path, made.value().encoder, made.value().frames, made.value().bytes};
}

}  // namespace palpate
