#include "runtime/session/frame_outputs.h"

#include <chrono>

namespace palpate {

void FrameOutputs::warm(const FrameView& view) {
  if (!renderer_) return;
  warm_rgba_.resize(static_cast<std::size_t>(renderer_->width()) * static_cast<std::size_t>(renderer_->height()) * 4);
  renderer_->draw(view, warm_rgba_.data());
}

uint8_t* FrameOutputs::acquire(bool block) {
  if (!renderer_ || !writer_) return nullptr;
  t0_ = std::chrono::steady_clock::now();
  c0_ = cpu_clock_.now_ms();
  builds_ = renderer_->layer_builds();
  uint8_t* buf = writer_->acquire(block);
  if (!buf) ++stats_->frames_dropped;
  return buf;
}

void FrameOutputs::draw(int64_t index, bool block, uint8_t* buf, const FrameView& view, double latest_force_N) {  // the trace takes the largest force the hand got since the last frame drawn (the latest when no tick came)
  style_.note_force(peak_N_ >= 0.0 ? peak_N_ : latest_force_N);
  peak_N_ = -1.0;
  renderer_->draw(view, buf);
  style_.observe(view);
  stats_->frames_layered += renderer_->last_draw_layered() ? 1 : 0;
  // the video gets its own copy: its frame index is the scene's, so a skipped frame holds the last one shown
  if (video_) video_->submit(index, buf, block);
  if (live_) live_->offer_frame(index, buf);
  // files are numbered in the order written, so a realtime run's skipped frames leave no gap in the sequence;
  // written_frames says which scene frame each file shows
  writer_->submit(static_cast<int>(stats_->frames_rendered), buf);
  stats_->written_frames.push_back(index);
  ++stats_->frames_rendered;
  stats_->render_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0_).count());
  stats_->render_cpu_ms.push_back(cpu_clock_.now_ms() - c0_);
  if (renderer_->layer_builds() != builds_) {
    stats_->layer_build_ms.push_back(stats_->render_ms.back());
    stats_->layer_build_cpu_ms.push_back(stats_->render_cpu_ms.back());
    stats_->layer_build_px.push_back(static_cast<double>(renderer_->last_layer_px()));
  }
}

}  // namespace palpate
