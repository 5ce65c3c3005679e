#pragma once
/// What a frame shows besides the surface's shape (scene.render's color, color_range_m, force_arrow, legend): the
/// displacement colours' fixed range, the force arrow and the legend, set on a FrameView. Thread: the sim thread.

#include "core/scene.h"
#include "haptics/servo/haptic_sample.h"
#include "render/renderer.h"
#include "runtime/session/model.h"

namespace palpate {

/// The view's colours, arrow and legend for one recording.
class ViewStyle {
 public:
  ViewStyle(const Scene& scene, const Model& model);
  /// A frame was drawn with `view`: its largest surface displacement is noted, and a run whose scene gives no
  /// render.color_range_m (a recording of a scripted run gets one from a first pass, runtime/record/color_pass.h; a
  /// live device's run cannot) steps its range up (1, 2, 5 times a power of ten, never down) to cover it.
  void observe(const FrameView& view);
  /// The largest distance from rest of the vertices a view may move (all of them when it names none).
  static double largest_displacement_m(const FrameView& view);
  /// The largest strain of those vertices when the view colours by strain (0 otherwise).
  static double largest_strain(const FrameView& view);
  /// A frame is about to be drawn and the force sent to the device is force_N: the inset's trace takes its magnitude.
  void note_force(double force_N);
  /// The largest surface displacement the frames drew, and the largest strain (when coloured by it).
  double shown_max_m() const { return shown_max_m_; }
  double shown_max_strain() const { return shown_max_strain_; }
  /// Sets the colours' range, the arrow and the legend on *view (its rest positions and cut faces are the region's).
  void apply(const HapticSample& latest, FrameView* view) const;
  /// The displacement (metres) or strain at the colour map's top (0: not coloured), and whether it was fixed before
  /// the first frame (the scene's, or a first pass's) or followed the run.
  double range() const { return range_; }
  bool fixed() const { return planned_; }

 private:
  const Scene& scene_;
  double range_ = 0.0;
  bool planned_ = false;
  double shown_max_m_ = 0.0, shown_max_strain_ = 0.0;
  std::vector<float> trace_;        // the force's magnitude a drawn frame, oldest first, at most trace_frames_
  std::size_t trace_frames_ = 120;  // the inset's two seconds in frames
  double ground_z_m_ = 0.0, ground_half_m_ = 0.0;  // the floor under the model: its height and half-side
  Vec3 ground_centre_m_ = Vec3::Zero();
  bool closed_ = false;  // the model's surface is closed (and not cut): its shadow needs the light-facing faces only
};

}  // namespace palpate
