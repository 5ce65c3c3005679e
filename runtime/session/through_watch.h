#pragma once
/// ThroughWatch: counts what breaks the god-object's invariant (docs/feel.md), for summary.json's tool_inside and
/// through figures: a drained tick whose free tool, or held proxy, lies inside the object deeper than the material
/// can have moved, and a frame whose free tool does (touch mode). Every point of the object is at most the lattice's
/// largest node displacement from where it rests, so a point deeper than that (and the tool's radius) under the rest
/// surface is inside the deformed object, whatever the dent: never a false alarm. Thread: the sim thread only.

#include "core/scene.h"
#include "haptics/servo/haptic_sample.h"
#include "runtime/session/frame_stats.h"
#include "runtime/session/model.h"
#include "sim/lattice/lattice.h"

namespace palpate {

class ThroughWatch {
 public:
  /// scene, model and stats must outlive it; stats takes the counts.
  ThroughWatch(const Scene& scene, const Model& model, FrameStats* stats) : scene_(scene), model_(model), stats_(stats) {}
  /// A frame begins: the material's reach may have changed with the last step, so every tick asks afresh.
  void begin_frame() { still_m_ = 0.0; }
  /// The lattice's largest node displacement after the frame's step (what the material can have moved).
  void set_moved(double lattice_moved_m) { moved_m_ = lattice_moved_m; }
  /// A drained tick.
  void tick(const HapticSample& s);
  /// The frame's end at scene time t_s: the newest sample's free tool against the lattice (null: none yet).
  void frame(const HapticSample& latest, const Lattice* lat, double t_s);

 private:
  const Scene& scene_;
  const Model& model_;
  FrameStats* stats_;
  double moved_m_ = 0.0;          // the lattice's largest node displacement after the last step
  Vec3 at_m_ = Vec3::Zero();      // where tick() last asked, and how far from it its answer still holds
  double still_m_ = 0.0;
};

}  // namespace palpate
