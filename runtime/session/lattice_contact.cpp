#include "runtime/session/lattice_contact.h"

#include <algorithm>

#include "sim/contact/compliance_estimate.h"
#include "sim/lattice/lattice_estimate.h"

namespace palpate {
namespace {

// The contact compliance's numeric factorisation per frame, in 3x3 block updates: about 3 ms of a frame here (55 ns an
// update at load 9, measured on phantom_press's 480-node region: 486,531 updates). A region of more than 256 free
// nodes is factored in stages over frames (assembly, ordering, analysis, then these slices); the servo keeps the
// surface's own force model until it is done. Smaller regions (the bunny scenes, cube_press, tissue_pull) factor
// whole in one frame as before.
constexpr int64_t kComplianceWorkPerFrame = 50000;

}  // namespace

ToolContact tool_contact(const Scene& scene, const HapticSample& s) {
  ToolContact c;
  c.tri = s.contact_tri;
  c.bary = s.contact_bary;
  c.centre_m = s.proxy_pos_m;
  c.sphere = scene.device.sphere_tool;
  c.radius_m = scene.device.tool_radius_m;
  return c;
}

LatticeContact::LatticeContact(const Scene& scene, const Model& model, const RestObject& rest, FrameStats* stats)
    : scene_(scene), model_(model), rest_(rest), stats_(stats) {
  // a lockstep run has no deadline: a solved contact gets its factor in the first frame it is asked for, not after
  // tens of frames of slices loaded by formula (a realtime run keeps the slices and loads by formula until done)
  compliance_.set_work_per_call(scene.device.solved_contact && scene.run_mode == RunMode::kLockstep ? 0
                                                                                                      : kComplianceWorkPerFrame);
  if (scene.mode != InteractionMode::kCut) {
    const LatticeEstimate most = estimate_lattice(model.grid, scene.lattice, false);
    compliance_.reserve(most.nodes, most.springs,
                        scene.lattice.material.enabled && scene.lattice.material.model != MaterialModel::kSprings);
  }
}

void LatticeContact::region_changed(bool wait) {
  solved_.reset();
  if (wait) wait_a_frame_ = true;
}

void LatticeContact::begin_frame(const FrameContact& fc) {
  solved_this_frame_ = false;
  frame_force_obj_N_ = fc.pushes() ? object_force(rest_, tool_contact(scene_, *fc.contact), -fc.mean_force_N)
                                   : Vec3::Zero();
}

int LatticeContact::load(const Lattice& lat, const std::vector<Vec3>& vertices_m, const std::vector<int32_t>& near_tris,
                         const FrameContact& fc, std::vector<Vec3>* f_ext) {
  std::fill(f_ext->begin(), f_ext->end(), Vec3::Zero());
  solved_this_frame_ = false;
  if (!fc.pushes()) {
    solved_.reset();
    return 0;
  }
  // the frame's mean device force, reacted on the material point P_s: -F spread over the cell nodes of the
  // contact triangle's vertices by barycentric and trilinear weights (a sphere tool: over its contact patch), or
  // (device.contact "solved") where the surface, deformed by it, meets the tool's tip
  const ToolContact c = tool_contact(scene_, *fc.contact);
  const Vec3 f_obj = object_force(rest_, c, -fc.mean_force_N);
  if (scene_.device.solved_contact) {
    // a sphere tool's centre is the proxy; a point tool's tip is a sphere of its radius resting on the proxy
    const double radius = scene_.device.tool_radius_m;
    const Vec3 push = f_obj.norm() > 0.0 ? Vec3(f_obj.normalized()) : Vec3::Zero();
    const Vec3 centre = c.sphere ? c.centre_m : Vec3(fc.contact->proxy_pos_m - radius * push);
    solved_this_frame_ = solved_.weights(lat, rest_, vertices_m, near_tris, centre, radius, f_obj, &compliance_, &solved_w_);
  }
  if (solved_this_frame_) {
    ++stats_->solved_contact_frames;
    stats_->solved_contact_radius_m = solved_.report().contact_radius_m;
  } else {
    ++stats_->prescribed_contact_frames;
  }
  const PointWeights w = solved_this_frame_ ? solved_w_ : contact_load_weights(lat, rest_, c);
  for (int i = 0; i < w.count; ++i) (*f_ext)[w.node[i]] += w.weight[i] * f_obj;
  int loaded = 0;
  for (const Vec3& f : *f_ext) loaded += f.squaredNorm() > 0.0 ? 1 : 0;
  return loaded;
}

std::optional<Mat3> LatticeContact::needed_estimate(const Lattice& lat, const PointWeights& w) {
  // the estimate is a point load's (a node's stiffness): a sphere's patch is many times stiffer. Given the node's
  // compliance the servo let the soft cube_press's sphere (level 6) leave the surface as the hand lifted off while the
  // frame's dent was still deep, and the next frames' surface met it again a millimetre up: steps of 0.25 N
  if (scene_.device.sphere_tool) return std::nullopt;
  const Mat3 c = estimate_compliance(lat, w, &estimate_scratch_);
  // only where the sampled force alone would overshoot (sim/contact/compliance_estimate.h: kEstimateNeededGain); on a stiffer
  // surface it settles as before, and an estimate several times too compliant would make the servo lag it
  if (!(scene_.device.coupling_N_per_m * c.trace() / 3.0 >= kEstimateNeededGain)) return std::nullopt;
  return c;
}

void LatticeContact::fill_model(const Lattice* lattice, const std::vector<Vec3>& vertices_m, const FrameContact& fc,
                                LocalModel* m) {
  m->has_contact_model = false;
  // a region placed or moved this frame has already built its lattice and the solver's factor: its compliance
  // factor waits a frame, and the servo keeps the surface's own force model until then
  if (wait_a_frame_) {
    wait_a_frame_ = false;
    return;
  }
  if (!lattice) return;
  const Lattice& lat = *lattice;
  // a free tool gets the model at its last contact too, on a surface far softer than the coupling: a touch that
  // begins within the next frame is then sampled against the surface's response, not against the surface as the
  // frame left it (that force, loaded as it is, would drive the surface many times the tool's depth past it, and the
  // touch would end again: a release and re-touch cycle). On a stiffer surface the sampled force settles as before.
  const bool free = fc.latest->contact == ContactState::kFree || fc.latest->contact_tri < 0;
  const HapticSample& at = free ? *fc.contact : *fc.latest;
  if (at.contact_tri < 0) return;
  const PointWeights w =
      solved_this_frame_ && !free ? solved_w_ : contact_load_weights(lat, rest_, tool_contact(scene_, at));
  // a free tool's model is the estimate's case only (and computed once)
  std::optional<Mat3> estimate;
  if (free && !(estimate = needed_estimate(lat, w))) return;
  const Vec3 p = surface_point(vertices_m, model_.rest.triangles[static_cast<std::size_t>(at.contact_tri)], at.contact_bary);
  ContactResponse r;
  if (contact_response(lat, w, p, frame_force_obj_N_, &compliance_, &r)) {
    ++stats_->contact_models;
  } else {
    // a refined lattice has no condensed compliance; a solved contact still needs its stiffness factored
    if (scene_.device.solved_contact && !lat.hanging.empty()) {
      Mat3 c;
      compliance_.compute(lat, w, false, &c);
    }
    // while the factor is made in slices, or on a refined lattice, the servo takes the estimate where it needs one; a
    // singular lattice (a piece with nothing holding it) gets no model
    if (!compliance_.factoring() && lat.hanging.empty()) return;
    if (!estimate) estimate = needed_estimate(lat, w);
    if (!estimate || !contact_response_with(lat, w, p, frame_force_obj_N_, *estimate, &r)) return;
    ++stats_->contact_models_estimated;
  }
  m->has_contact_model = true;
  m->contact_p0_m = r.p0_m;
  m->contact_centre_m = at.god_pos_m;
  m->contact_v0_m_per_s = r.v0_m_per_s;
  m->contact_f0_N = r.f0_N;
  m->compliance_m_per_N = r.compliance_m_per_N;
  m->model_radius_m = r.radius_m;
}

}  // namespace palpate
