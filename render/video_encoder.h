#pragma once
/// VideoEncoder: RGBA frames to an H.264 (yuv420p) MP4 with the index first ("faststart"), through FFmpeg.

#include <cstdint>
#include <memory>
#include <string>

#include "core/result.h"

namespace palpate {

/// One MP4 being encoded; FFmpeg state kept behind a pointer. Movable by its unique_ptr only, not copyable.
/// The file is written as "<path>.tmp" (created through AtomicFile) and renamed to path by finish(); destroying
/// it unfinished removes the temporary. Odd widths or heights lose their last column or row (yuv420p needs even
/// sizes). Thread: one thread at a time; allocates.
class VideoEncoder {
 public:
  /// Opens the first H.264 encoder that works: libx264, then libopenh264, then libavcodec's default H.264
  /// encoder. Errors name the path and cause ("video 'x.mp4': no H.264 encoder in this libavcodec (tried ...)",
  /// "... is not a regular file ..."); nothing is left behind on failure.
  static Result<std::unique_ptr<VideoEncoder>> open(const std::string& path, int width, int height, int frame_rate_hz);
  ~VideoEncoder();
  VideoEncoder(const VideoEncoder&) = delete;
  VideoEncoder& operator=(const VideoEncoder&) = delete;

  /// Encodes one RGBA8 frame (rows top-down, width*height*4 bytes) shown from frame `index` (in 1/frame_rate s)
  /// until the next one: a gap in the indices holds this frame. Indices must increase; errors name the path.
  Status encode(const uint8_t* rgba, int64_t index);
  /// Flushes the encoder, writes the index before the data and renames the temporary to path; idempotent.
  Status finish();

  /// The FFmpeg encoder in use ("libx264").
  const std::string& encoder_name() const;
  /// The final path.
  const std::string& path() const;
  /// Frames encoded so far.
  int64_t frames() const;
  /// Size of the finished file in bytes (0 before finish()).
  int64_t bytes() const;
  /// Frames per second of the stream.
  int frame_rate_hz() const;

  struct Impl;

 private:
  explicit VideoEncoder(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace palpate
