#include "runtime/record/video_output.h"

#include <cstdio>
#include <filesystem>

#include "core/stats.h"
#include "core/limits.h"
#include "render/png_io.h"
#include "runtime/record/frame_files.h"

namespace palpate {
namespace {
// a side of a rendered frame at most (as a scene's render.width and render.height)
constexpr int64_t kMaxImageSide = 8192;
}  // namespace

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

Result<FramesVideo> encode_png_frames(const std::vector<std::string>& files, const std::vector<int64_t>& scene_index,
                                     const std::string& out_path, int frame_rate_hz, const std::atomic<bool>* stop) {
  if (files.empty()) return make_error("video '", out_path, "': no frames to encode");
  // the size from each file's header before anything is decoded: a frame the renderer could not have made (a
  // few bytes can claim 32767 x 32767, a small file can inflate to gigabytes) is refused unread
  int64_t w0 = 0, h0 = 0;
  for (const std::string& f : files) {
    auto size = png_size(f);
    if (!size) return size.error();
    const auto [fw, fh] = size.value();
    if (w0 == 0) {
      if (fw < 1 || fh < 1 || fw > kMaxImageSide || fh > kMaxImageSide || fw * fh > kMaxImagePixels)
        return make_error("frame '", f, "': ", std::to_string(fw), "x", std::to_string(fh),
                          " is outside what a recording renders (sides 1..", std::to_string(kMaxImageSide),
                          ", at most ", std::to_string(kMaxImagePixels), " pixels)");
      w0 = fw;
      h0 = fh;
    } else if (fw != w0 || fh != h0) {
      return make_error("frame '", f, "': ", std::to_string(fw), "x", std::to_string(fh),
                        " differs from the first frame's ", std::to_string(w0), "x", std::to_string(h0));
    }
  }
  auto first = read_png(files.front());
  if (!first) return first.error();
  const int w = first.value().width, h = first.value().height;
  auto enc_r = VideoEncoder::open(out_path, w, h, frame_rate_hz);
  if (!enc_r) return enc_r.error();
  VideoEncoder& enc = *enc_r.value();
  for (std::size_t i = 0; i < files.size(); ++i) {
    // a stop request ends the encode between frames; the unfinished file is removed with the encoder
    if (stop && stop->load(std::memory_order_relaxed))
      return make_error("video '", out_path, "': stopped on request after ", std::to_string(i), " of ",
                        std::to_string(files.size()), " frames");
    auto img = i == 0 ? std::move(first) : read_png(files[i]);
    if (!img) return img.error();
    if (img.value().width != w || img.value().height != h)
      return make_error("frame '", files[i], "': ", std::to_string(img.value().width), "x",
                        std::to_string(img.value().height), " differs from the first frame's ", std::to_string(w), "x",
                        std::to_string(h));
    const int64_t index = scene_index.empty() ? static_cast<int64_t>(i) : scene_index[i];
    if (auto st = enc.encode(img.value().rgba.data(), index); !st) return st.error();
  }
  if (auto st = enc.finish(); !st) return st.error();
  return FramesVideo{enc.path(), enc.encoder_name(), enc.frames(), enc.bytes()};
}

void make_video_after_run(const std::string& path, const std::string& frames_dir, int count,
                          const std::vector<int64_t>& scene_index, int frame_rate_hz, RecordingVideo* video,
                          const std::atomic<bool>* stop) {
  video->path = path;
  video->optional = true;
  if (count <= 0) {
    video->error = "no frames were written";
    return;
  }
  std::vector<std::string> files;
  char name[32];
  for (int i = 0; i < count; ++i) {
    std::snprintf(name, sizeof name, "frame_%05d.png", i);
    files.push_back((std::filesystem::path(frames_dir) / name).string());
  }
  const std::vector<int64_t> index(scene_index.begin(), scene_index.begin() + count);
  auto made = encode_png_frames(files, index, path, frame_rate_hz, stop);
  if (!made) {
    video->error = made.error().message;
    std::fprintf(stderr, "palpate: warning: no video: %s\n", video->error.c_str());
    return;
  }
  const FramesVideo& m = made.value();
  video->made_after_run = {{"enabled", true}, {"made", "after the realtime run, from frames/"}, {"path", m.path},
                           {"codec", "h264"}, {"encoder", m.encoder}, {"frame_rate_hz", frame_rate_hz},
                           {"frames", m.frames}, {"bytes", m.bytes}};
}

nlohmann::json video_json(const RecordingVideo& video, const std::string& off_reason) {
  if (!video.made_after_run.is_null()) return video.made_after_run;
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
