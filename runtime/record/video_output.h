#pragma once
/// The video beside a recording: opened before the first frame, finished after the last, reported in
/// summary.json's "video" object.

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/result.h"
#include "render/video_writer.h"

namespace palpate {

/// A recording's video and what became of it. Movable, not copyable. Thread: the sim thread.
struct RecordingVideo {
  std::string path;                     ///< the MP4 asked for; empty = no video
  bool optional = false;                ///< failures are warnings (video on by default), else errors
  std::unique_ptr<VideoWriter> writer;  ///< null when off or when opening failed
  std::string error;                    ///< the open or encode failure, empty when none
  nlohmann::json made_after_run;        ///< summary.json "video" of a video made from the frames after the run
};

/// What encode_png_frames wrote.
struct FramesVideo {
  std::string path;     ///< the MP4
  std::string encoder;  ///< FFmpeg encoder used
  int64_t frames = 0;   ///< frames encoded (one per PNG)
  int64_t bytes = 0;    ///< file size
};

/// Encodes the PNG files `files` (all of one size, in order) into out_path at frame_rate_hz, file i shown from
/// scene frame scene_index[i] on (empty: frame i), so skipped frames hold the previous one. Errors name the file.
/// A set `stop` ends it between frames with an error saying how far it got, and no file.
Result<FramesVideo> encode_png_frames(const std::vector<std::string>& files, const std::vector<int64_t>& scene_index,
                                     const std::string& out_path, int frame_rate_hz,
                                     const std::atomic<bool>* stop = nullptr);

/// A realtime run's default video, made after the run from frames_dir/frame_00000.png.. (`count` files, file i
/// showing scene frame scene_index[i]) at frame_rate_hz: fills video->path and made_after_run, or on failure prints
/// a warning and keeps it in video->error (the default video is optional). A set `stop` ends the encode between
/// frames (no video; the error says so).
void make_video_after_run(const std::string& path, const std::string& frames_dir, int count,
                          const std::vector<int64_t>& scene_index, int frame_rate_hz, RecordingVideo* video,
                          const std::atomic<bool>* stop = nullptr);

/// Frame copies the encoder may fall behind by before a realtime recording drops video frames.
inline constexpr int kVideoQueueFrames = 8;

/// Refuses a video path inside the frames folder (where frame files are written and removed); an error naming
/// both, Ok for an empty path or one elsewhere.
Status check_video_beside_frames(const std::string& video_path, const std::string& frames_dir);

/// Opens the encoder and its thread for width x height RGBA frames at frame_rate_hz. A failure is returned as
/// the error unless `optional`; then it is printed as a warning on stderr and kept in error.
Result<RecordingVideo> open_recording_video(const std::string& path, bool optional, int width, int height,
                                            int frame_rate_hz);

/// Encodes what is queued and finishes the file; a failure is returned unless video->optional (then printed as
/// a warning and kept in video->error).
Status finish_recording_video(RecordingVideo* video);

/// summary.json "video": {enabled, path, codec, encoder, frame_rate_hz, frames, frames_dropped, bytes,
/// encode_ms {p50, p99, max, count}, finish_ms} or {enabled: false, reason}.
nlohmann::json video_json(const RecordingVideo& video, const std::string& off_reason);

}  // namespace palpate
