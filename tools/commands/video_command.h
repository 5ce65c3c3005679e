#pragma once
/// `palpate video FOLDER`: the MP4 of an existing recording, made from its frames/frame_*.png.

#include <string>

#include "core/result.h"

namespace palpate {

/// What `palpate video` wrote.
struct VideoCommandResult {
  std::string path;     ///< the MP4
  std::string encoder;  ///< FFmpeg encoder used
  int64_t frames = 0;   ///< frames encoded (one per PNG)
  int64_t bytes = 0;    ///< file size
};

/// Encodes FOLDER/frames/frame_N.png (in the order of N, which must run 0, 1, 2, ... with no gap; each a regular
/// file no larger than a rendered frame) into out_path (default FOLDER/recording.mp4) at
/// frame_rate_hz; a realtime recording's summary.json "frames_scene_index" places each file at its scene frame, so
/// skipped frames hold the previous one, as in the recorder's video. Errors name the folder, file or key.
Result<VideoCommandResult> make_recording_video(const std::string& folder, std::string out_path, int frame_rate_hz);

}  // namespace palpate
