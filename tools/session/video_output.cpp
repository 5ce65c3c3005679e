#include "tools/session/video_output.h"

#include <cstdio>
#include <filesystem>

#include "core/stats.h"

namespace palpate {

Status check_video_beside_frames(const std::string& video_path, const std::string& frames_dir) {
  if (video_path.empty() || frames_dir.empty()) return Ok{};
  std::error_code ec;
  const auto dir = std::filesystem::weakly_canonical(frames_dir, ec);
  const auto parent = std::filesystem::weakly_canonical(std::filesystem::absolute(video_path).parent_path(), ec);
  if (ec || dir != parent) return Ok{};
  return make_error("--video '", video_path, "': inside the frames folder '", frames_dir,
                    "', where the frames are written (and an earlier run's removed); choose a path outside it");
}

Result<RecordingVideo> open_recording_video(const std::string& path, bool optional, int width, int height,
                                            int frame_rate_hz) {
  RecordingVideo v;
  v.path = path;
  v.optional = optional;
  if (path.empty()) return v;
  auto enc = VideoEncoder::open(path, width, height, frame_rate_hz);
  if (!enc) {
    if (!optional) return enc.error();
    v.error = enc.error().message;
    std::fprintf(stderr, "palpate: warning: recording without video: %s\n", v.error.c_str());
    return v;
  }
  v.writer = std::make_unique<VideoWriter>(std::move(enc).value(), width, height, kVideoQueueFrames);
  return v;
}

Status finish_recording_video(RecordingVideo* video) {
  if (!video->writer) return Ok{};
  Status st = video->writer->finish();
  if (st) return st;
  video->error = st.error().message;
  if (!video->optional) return st;
  std::fprintf(stderr, "palpate: warning: the video failed: %s\n", video->error.c_str());
  return Ok{};
}

nlohmann::json video_json(const RecordingVideo& video, const std::string& off_reason) {
  if (!video.writer) {
    nlohmann::json j = {{"enabled", false}, {"reason", video.error.empty() ? off_reason : video.error}};
    if (!video.path.empty()) j["path"] = video.path;
    return j;
  }
  const VideoWriter& w = *video.writer;
  const std::vector<double>& ms = w.encode_ms();
  nlohmann::json j = {{"enabled", true},
                      {"path", video.path},
                      {"codec", "h264"},
                      {"encoder", w.encoder().encoder_name()},
                      {"pix_fmt", "yuv420p"},
                      {"frame_rate_hz", w.encoder().frame_rate_hz()},
                      {"frames", w.frames_encoded()},
                      {"frames_dropped", w.frames_dropped()},
                      {"bytes", w.encoder().bytes()},
                      {"encode_ms", {{"p50", percentile(ms, 0.5)}, {"p99", percentile(ms, 0.99)},
                                     {"max", percentile(ms, 1.0)}, {"count", ms.size()}}},
                      {"finish_ms", w.finish_ms()}};
  if (!video.error.empty()) j["error"] = video.error;
  return j;
}

}  // namespace palpate
