#pragma once
/// ContactFeed: what a frame takes from the servo's samples. The newest sample, the newest in contact (this frame or
/// before), and the mean device force of the frame's samples; a frame the servo sent nothing to (a realtime servo
/// stalled) keeps the last frame's contact and mean force, rather than letting go of the surface for the frame (a pull
/// shaken through the browser sprang back during a 100 ms servo stall, and the hand met it with a 0.6 N step when the
/// servo came back). Thread: the sim thread only.

#include <cstdint>

#include "core/types.h"
#include "haptics/servo/haptic_sample.h"

namespace palpate {

/// One frame's contact as the servo's samples gave it. Plain data; the samples are the feed's.
struct FrameContact {
  const HapticSample* contact = nullptr;  ///< the newest sample in contact, this frame or before (contact_tri < 0: never)
  const HapticSample* latest = nullptr;   ///< the newest sample drained
  bool in_contact = false;                ///< a sample of this frame was in contact
  Vec3 mean_force_N = Vec3::Zero();       ///< the mean device force of the frame's samples
  int64_t samples = 0;                    ///< the frame's samples
  /// The frame pushes on the object: in contact, with samples.
  bool pushes() const { return in_contact && samples > 0; }
};

class ContactFeed {
 public:
  /// Before any sample the tool (and proxy) are at start_m.
  explicit ContactFeed(const Vec3& start_m) {
    latest_.tool_pos_m = start_m;
    latest_.proxy_pos_m = start_m;
  }
  /// A frame begins: no sample of it yet.
  void begin_frame() {
    in_contact_ = false;
    force_sum_N_.setZero();
    samples_ = 0;
  }
  /// One drained sample, in order.
  void take(const HapticSample& s) {
    ++samples_;
    force_sum_N_ += s.force_N;
    if (s.contact != ContactState::kFree && s.contact_tri >= 0) {
      contact_ = s;
      in_contact_ = true;
    }
    latest_ = s;
  }
  /// The frame's samples are all taken: a frame with none holds what the hand held.
  void end_drain() {
    if (samples_ > 0) {
      last_mean_force_N_ = force_sum_N_ / static_cast<double>(samples_);
      return;
    }
    if (latest_.contact == ContactState::kFree || latest_.contact_tri < 0) return;
    in_contact_ = true;
    force_sum_N_ = last_mean_force_N_;
    samples_ = 1;
  }
  const HapticSample& latest() const { return latest_; }
  const HapticSample& contact() const { return contact_; }
  bool in_contact() const { return in_contact_; }
  /// The frame's contact so far (pointers into the feed).
  FrameContact frame() const {
    FrameContact fc;
    fc.contact = &contact_;
    fc.latest = &latest_;
    fc.in_contact = in_contact_;
    fc.samples = samples_;
    if (samples_ > 0) fc.mean_force_N = force_sum_N_ / static_cast<double>(samples_);
    return fc;
  }

 private:
  HapticSample latest_;              // newest sample drained
  HapticSample contact_;             // newest sample in contact
  bool in_contact_ = false;          // a sample of this frame was in contact (or the frame held the last contact)
  Vec3 force_sum_N_ = Vec3::Zero();  // sum of device forces over the frame's samples
  int64_t samples_ = 0;
  Vec3 last_mean_force_N_ = Vec3::Zero();  // the mean device force of the last frame that had samples
};

}  // namespace palpate
