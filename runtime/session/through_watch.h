#pragma once
/// ThroughWatch: counts what breaks the god-object's invariant (docs/feel.md), for summary.json's tool_inside and
/// through figures: a drained tick whose free tool, or held proxy, lies inside the object deeper than the material
/// can have moved, and a frame whose free tool does (touch mode). Every point of the object is at most the lattice's
/// largest node displacement from where it rests, so a point deeper than that (and the tool's radius) under the rest
/// surface is inside the deformed object, whatever the dent: never a false alarm. A surface that is not closed (an
/// open sheet, a scan with holes) has no inside; there the point is through when its path since it was last away from
/// the surface has crossed the rest surface an odd number of times and it is away from it again, farther than the
/// same reach (a dent and the path back out of it cross twice; a way round the sheet's edge, never).
/// Thread: the sim thread only.

#include <cstdint>
#include <vector>

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
  // an open surface: the judged point's last place, and whether its path has crossed the surface an odd number of
  // times since it was last away from it
  void open_tick(bool free, const Vec3& p, double reach_m, double t_s);
  bool have_path_ = false;
  Vec3 path_at_m_ = Vec3::Zero();
  bool path_odd_ = false;
  std::vector<int32_t> ids_;      // the crossing query's scratch
};

}  // namespace palpate
