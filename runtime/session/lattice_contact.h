#pragma once
/// LatticeContact: the contact between the hand and the lattice, both ways, once a frame. The frame's mean device
/// force goes onto the lattice's nodes (spread over the contact point's cell nodes, a sphere's patch, or where the
/// solved contact puts it: device.contact), and the lattice's linearised response at the contact goes to the servo
/// (LocalModel's contact model: sim/contact/contact_response.h), which uses it between frames. Owns the contact compliance's
/// factor and the solved contact's state. Thread: the sim thread only.

#include <optional>
#include <vector>

#include "core/scene.h"
#include "haptics/servo/haptic_sample.h"
#include "runtime/session/contact_feed.h"
#include "haptics/servo/local_model.h"
#include "runtime/session/frame_stats.h"
#include "runtime/session/model.h"
#include "sim/contact/contact_compliance.h"
#include "sim/contact/contact_load.h"
#include "sim/contact/contact_response.h"
#include "sim/lattice/lattice.h"
#include "sim/contact/solved_contact.h"

namespace palpate {

/// The contact of sample s as the contact load reads it (sim/contact/contact_load.h), with the scene's tool.
ToolContact tool_contact(const Scene& scene, const HapticSample& s);

class LatticeContact {
 public:
  /// scene, rest and stats must outlive it; stats takes the contact's figures.
  LatticeContact(const Scene& scene, const Model& model, const RestObject& rest, FrameStats* stats);

  /// The region's lattice was built or changed: a solved contact starts afresh. With wait, the servo's contact model
  /// waits a frame (the region was placed or moved this frame: its lattice and factor are new).
  void region_changed(bool wait);
  /// The frame's force on the object, from its contact (zero without one): what the step pushes and the contact
  /// model's response is linearised about.
  void begin_frame(const FrameContact& fc);
  /// The frame's contact force on the lattice's nodes (*f_ext zeroed first, sized for lat); returns how many nodes
  /// it went to. near_tris: the patch's triangles, for a solved contact.
  int load(const Lattice& lat, const std::vector<Vec3>& vertices_m, const std::vector<int32_t>& near_tris,
           const FrameContact& fc, std::vector<Vec3>* f_ext);
  /// The object's linearised response at the current contact for the servo between frames (m->has_contact_model
  /// false when there is none); lat null: no lattice yet.
  void fill_model(const Lattice* lat, const std::vector<Vec3>& vertices_m, const FrameContact& fc, LocalModel* m);

 private:
  // the estimated compliance at w where the servo needs it (a point tool on a surface far softer than the coupling)
  std::optional<Mat3> needed_estimate(const Lattice& lat, const PointWeights& w);

  const Scene& scene_;
  const Model& model_;
  const RestObject& rest_;
  FrameStats* stats_;
  ContactCompliance compliance_;          // static condensation of the lattice at the contact
  std::vector<double> estimate_scratch_;  // per-node storage of the estimated compliance (sim/contact/compliance_estimate.h)
  SolvedContactLoad solved_;              // device.contact "solved": the push's weights from the contact
  PointWeights solved_w_;                 // those of this frame (valid while solved_this_frame_)
  bool solved_this_frame_ = false;
  bool wait_a_frame_ = false;             // the region was placed or moved this frame: no contact model until the next
  Vec3 frame_force_obj_N_ = Vec3::Zero(); // force pushed on the object during the frame's step
};

}  // namespace palpate
