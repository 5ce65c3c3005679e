#include "haptics/servo/servo.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "haptics/force/force_limit.h"
#include "haptics/force/proxy_solver.h"
#include "haptics/force/triangle_queries.h"
#include "haptics/servo/servo_touch_limits.h"

namespace palpate {
namespace {

using servo_touch::kFarSideCos;
using servo_touch::kPointClearance_m;
using servo_touch::kReturnReach_m;

// whether a sphere of radius r centred at c lies where the patch is whole (LocalModel::cover_radius_m); a sphere wider
// than half what the patch covers is not judged (its reach is more surface than the patch can hold; the patch is
// ordered round it all the same)
bool covered(const LocalModel& m, const Vec3& c, double r) noexcept {
  if (!(m.cover_radius_m < INFINITY) || m.cover_radius_m < 2.0 * r) return true;
  return (c - c.cwiseMax(m.cover_lo_m).cwiseMin(m.cover_hi_m)).norm() + r <= m.cover_radius_m;
}

// what a servo feels while its session starts again under new controls: no surface
const LocalModel kNoPatch{};

}  // namespace

Servo::Servo(const ServoParams& params, const Rates& rates, Device* device, SpscQueue<HapticSample>* samples,
             TripleBuffer<LocalModel>* model)
    : params_(params), rates_(rates), device_(device), samples_(samples), model_(model) {
  for (const InteractionMode m : {InteractionMode::kTouch, InteractionMode::kPull, InteractionMode::kCut}) {
    ServoParams& p = mode_params_[static_cast<std::size_t>(m)];
    p = params;
    p.mode = m;
    if (m != InteractionMode::kTouch) {
      p.tool_radius_m = 0.0;
      p.friction = FrictionParams{};
    }
  }
  controls_.mode = params.mode;
  controls_.tool_radius_m = params.tool_radius_m;
  // force shading: the smooth normal in full up to a quarter of the crease angle from the facets' push, none from half
  const double crease_rad = std::clamp(params.force_shading_deg, 0.0, 180.0) * std::numbers::pi / 180.0;
  if (crease_rad > 0.0) {
    shade_full_cos_ = std::cos(0.25 * crease_rad);
    shade_none_cos_ = std::cos(0.5 * crease_rad);
  }
}

void Servo::update_touch(const LocalModel& src, const Vec3& tool) noexcept {
  const bool sphere = params_.tool_radius_m > 0.0;
  const double r = sphere ? params_.tool_radius_m : kPointClearance_m;
  bool began = false;
  if (contact_ == ContactState::kFree) {
    back_ = false;
    const LocalModel& m = src;
    // the tool's path since the last tick; failing that, with the surface moved, the same path carried with the
    // surface point nearest the tool: a surface that moves through a slower tool (a dent springing back after a
    // release) touches it too, instead of leaving it inside, untouched, for good
    Vec3 from = prev_tool_m_;
    if (!covered(m, tool, r) || !covered(m, from, r)) {
      // the tool is where the patch does not reach (faster than the patch follows, or a patch cut short by a dense
      // mesh): its path is judged once a patch covers it, from the last point seen outside
      if (!unseen_) unseen_from_m_ = from;
      unseen_ = true;
      near_tri_ = -1;
      near_outside_ = false;
      proxy_m_ = contact_point_m_ = tool;
      return;
    }
    if (unseen_) {
      from = unseen_from_m_;
      unseen_ = false;
    }
    bool back = false;
    int met = -1;
    bool begins = touch_begins(m, from, tool, r, &back, &met);
    Vec3 p = Vec3::Zero();
    if (!begins && surface_moved_ && near_tri_ >= 0 && material_point(m, near_tri_, near_bary_, &p)) {
      from += p - near_m_;
      begins = touch_begins(m, from, tool, r, &back, &met);
    }
    if (!begins && surface_moved_ && near_outside_) {
      // the surface came through the tool by another way than the point nearest it (a fold springing back, or its
      // triangles no longer in the patch): outside by the last tick's surface, inside by this one. The god-object
      // starts on this surface's outside, over the point nearest the tool among the faces facing the side the tool
      // was on (not the last contact's side: with that, the inner face of a wall thinner than the reach was taken for
      // the near one, and a tool 2.6 mm outside the wall was held 5 mm inside it, and pulled through)
      int slot = -1;
      Vec3 q = Vec3::Zero(), b = Vec3::Zero(), normal = Vec3::Zero();
      if (closest_on_patch(m, tool, &slot, &q, &b, &near_normal_) && (tool - q).norm() <= r + kReturnReach_m &&
          !outside_of(m, slot, b, q, tool, r, &normal) && normal.squaredNorm() > 0.0) {
        contact_normal_ = normal.normalized();
        from = q + (r + kPointClearance_m) * contact_normal_;
        begins = true;
      }
    }
    if (!begins) {
      track_nearest(m, tool, r);
      proxy_m_ = contact_point_m_ = tool;
      return;
    }
    // the god-object starts where the tool was, outside (on a two-sided surface, on the side it came from)
    contact_ = ContactState::kTouch;
    god_m_ = from;
    shade_ = Quat::Identity();
    shade_n_ = shade_push_ = Vec3::Zero();
    shade_free_m_ = from;
    back_ = back;
    back_part_ = back && met >= 0 ? m.part[met] : 0;
    began = true;
  }
  // touched from the back of its faces, the part touched is felt turned over: its back is then the front every query
  // holds to (a cup pressed from inside; before, a tool went through an open surface from behind, and the way back out
  // from the front held it outside the cup: 3.3 N pulling the hand away). Other parts keep their sides (turned with it,
  // the front of a part the tool slid onto was passed over as a far side, and the tool went through it)
  if (back_) turn_over(src, back_part_, &turned_);
  const LocalModel& m = back_ ? turned_ : src;
  if (!began && surface_moved_) {
    // the surface moved under the held proxy (a new frame, or the blend toward it): it goes with the material
    // point under it
    Vec3 p = Vec3::Zero();
    if (material_point(m, tri_, bary_, &p)) {
      god_m_ += p - contact_frame_m_;
      shade_free_m_ += p - contact_frame_m_;
    }
  }
  // from where it was (out of any overlap the surface's move made), toward the device as far as the surface lets it
  Vec3 held = god_m_;
  push_out(m, r, contact_normal_, 4, &held);
  const double pushed_m = (held - god_m_).norm();
  int active = 0;
  Vec3 free = god_object_move(m, held, tool, r, contact_normal_, &active);
  if (active == 0 && !tool_outside(m, tool, r)) {
    // the move reached a tool still inside (the sweep let it through): the proxy holds where it was
    free = held;
    active = 1;
  }
  if (active == 0) {
    // the tool is out of reach of the surface: contact ends (the free tool is judged by the surface as it is)
    contact_ = ContactState::kFree;
    tri_ = -1;
    friction_ = FrictionState{};
    back_ = bary_turned_ = false;
    track_nearest(src, tool, r);
    proxy_m_ = contact_point_m_ = tool;
    return;
  }
  // with a jump limit the proxy goes at most the device's step and the limit's share of the coupling a tick: where
  // the surface alone would snap it over (a convex ridge or facet edge), it rolls over in bounded steps (the
  // friction cone and the release still judge from where the surface alone would put it); a point tool always does
  const double roll_N = params_.jump_limit_N_per_tick > 0.0 ? params_.jump_limit_N_per_tick
                        : sphere                           ? 0.0
                                                           : kPointRoll_N_per_tick;
  const double path_m = roll_N > 0.0 && params_.coupling_N_per_m > 0.0
                            ? (tool - prev_tool_m_).norm() + roll_N / params_.coupling_N_per_m
                            : 0.0;
  // a push out further than the path a tick allows (a face that came into the patch overlapping the proxy, a corner
  // of a part turning under a sphere pressed onto it): the proxy goes where the surface puts it, and its step reaches
  // the hand at the jump limit (shoved 0.6 mm sideways off a cube's corner in one tick: a 0.19 N click)
  if (path_m > 0.0 && pushed_m > path_m) push_event_ = true;
  Vec3 c = free;
  if (params_.friction.on()) {
    const FrictionStep f = friction_step(params_.friction, held, free, tool, tool_vel_m_per_s_, &friction_);
    c = f.stick ? held : god_object_move(m, held, f.goal, r, contact_normal_, &active, path_m);
  } else if (path_m > 0.0 && (free - held).norm() > path_m) {
    c = god_object_move(m, held, tool, r, contact_normal_, &active, path_m);
  }
  // the contact point under the centre, and the surface's smooth normal there (the side later ticks hold to)
  int slot = -1;
  Vec3 q = Vec3::Zero(), b = Vec3::Zero();
  // (a point's contact point is its proxy: taken among the faces the god-object's move holds to, those within 120
  // degrees of the contact's side, not 90, so the face that holds it is never passed over for the edge of another —
  // from which a point on regr01.obj's folds was felt, then jumped 0.3 mm when the side turned: 0.13 N)
  if (!closest_on_patch(m, c, &slot, &q, &b, &contact_normal_, sphere ? 0.0 : kFarSideCos)) return;
  const auto& n = m.normal[slot];
  Vec3 normal = b[0] * n[0] + b[1] * n[1] + b[2] * n[2];
  // a sphere's side is where its centre is: where the smooth normal points away from it (faces back to back, an
  // open sheet touched from its back), the way from the surface point to the centre, a radius long, stands for it
  // (taken as it was, it named the far side the contact's, and the next overlap was pushed out through the sheet: 7 mm
  // and a 2.1 N step on regr01.obj). A point's proxy rides a micrometre off the surface, too near to tell the side
  // by: on a thin part of WusonOBJ.obj that way named the far side, and the point fell through the near one.
  if (sphere && normal.dot(c - q) < 0.0) normal = c - q;
  if (normal.squaredNorm() > 0.0) contact_normal_ = normal.normalized();
  god_m_ = c;
  contact_frame_m_ = q;
  tri_ = m.tri_ids[slot];
  bary_ = b;
  bary_turned_ = back_ && m.part[slot] == back_part_;
  proxy_m_ = sphere ? c : q;
  contact_point_m_ = q;
  if (shade_full_cos_ < 1.0) update_shading(m, c, slot, b, tool, r, path_m);
}

void Servo::update_pull(const LocalModel& m, const Vec3& tool, bool button) noexcept {
  if (!button) {
    contact_ = ContactState::kFree;
    tri_ = -1;
    proxy_m_ = tool;
    return;
  }
  if (contact_ == ContactState::kFree) {
    // grab only on the press itself, when the surface is within reach
    int slot = -1;
    Vec3 q = Vec3::Zero(), b = Vec3::Zero();
    if (!prev_button_ && closest_on_patch(m, tool, &slot, &q, &b) && (q - tool).norm() <= params_.grab_radius_m) {
      contact_ = ContactState::kGrab;
      tri_ = m.tri_ids[slot];
      bary_ = b;
      proxy_m_ = q;
    } else {
      proxy_m_ = tool;
    }
    return;
  }
  // held in material coordinates: P_s follows the deformed surface
  Vec3 p = Vec3::Zero();
  if (material_point(m, tri_, bary_, &p)) proxy_m_ = p;
}

void Servo::update_cut(const LocalModel& m, const Vec3& tool, const Vec3& axis, bool button) noexcept {
  contact_ = ContactState::kFree;
  tri_ = -1;
  proxy_m_ = tool;
  cut_force_N_.setZero();
  if (!button) return;
  const Vec3 end = tool + params_.blade_length_m * axis;
  bool inside = false;
  for (int i = 0; i < m.num_triangles && !inside; ++i) {
    const auto& t = m.tri_m[i];
    double u = 0.0;
    Vec3 b = Vec3::Zero();
    inside = segment_enters_triangle(tool, end, t[0], t[1], t[2], &u, &b) ||
             segment_enters_triangle(end, tool, t[0], t[1], t[2], &u, &b);
  }
  if (!inside) {
    // no crossing: the blade is wholly inside when its tip lies behind the nearest surface point's normal
    int slot = -1;
    Vec3 q = Vec3::Zero(), b = Vec3::Zero();
    if (!closest_on_patch(m, tool, &slot, &q, &b)) return;
    const auto& n = m.normal[slot];
    inside = (tool - q).dot(b[0] * n[0] + b[1] * n[1] + b[2] * n[2]) < 0.0;
  }
  if (!inside) return;
  // viscous resistance to the motion across the edge (sliding along the edge is free)
  contact_ = ContactState::kCut;
  const Vec3 v_across = tool_vel_m_per_s_ - tool_vel_m_per_s_.dot(axis) * axis;
  cut_force_N_ = -params_.cut_resistance_Ns_per_m * v_across;
}

Vec3 Servo::predicted_proxy(const LocalModel& m, const Vec3& tool, double t_s) const noexcept {
  // the model holds while the proxy stays near the frame's contact: a point's proxy is its contact point; a sphere's
  // is judged by its centre, since a sphere resting in a dent it fills has its nearest surface point jump across the
  // dent as it rolls a hair, which is no move of the contact (judged by that point, the prediction dropped out for a
  // tick: a click of 0.36 N)
  // (proxy_m_ is still the god-object here, before this tick's prediction: it is compared with the frame's)
  const Vec3 moved = params_.tool_radius_m > 0.0 ? Vec3(proxy_m_ - m.contact_centre_m) : Vec3(proxy_m_ - m.contact_p0_m);
  // (a grab's held point is the contact itself, a material point: on the blended surface it starts a frame where the
  // last frame had it, up to a cell from the new frame's contact point when the surface moves fast, and judged by that
  // distance the prediction dropped out for the frame's first ticks — steps of 1-2 N at 60 Hz on a shaken gel)
  if (!m.has_contact_model || (contact_ != ContactState::kGrab && moved.norm() > m.model_radius_m)) return proxy_m_;
  // the proxy P rides the surface, which has moved by v0 tau + C (F_obj - f0) with F_obj = -k_c (P - P_t);
  // solving for P: (I + k_c C) P = P_frame + v0 tau - C f0 + k_c C P_t
  const double k = params_.coupling_N_per_m;
  const double tau = std::max(0.0, t_s - m.t_s);
  const Mat3& c = m.compliance_m_per_N;
  const Mat3 a = Mat3::Identity() + k * c;
  // a blended patch moves the surface over the frame itself: only the response to the force is predicted
  const double drift_s = m.blend_s > 0.0 && params_.surface_blend ? 0.0 : tau;
  const Vec3 rhs = proxy_m_ + drift_s * m.contact_v0_m_per_s - c * m.contact_f0_N + k * (c * tool);
  const Vec3 p = a.inverse() * rhs;
  return p.allFinite() ? p : proxy_m_;
}

bool Servo::jump_event(const LocalModel& m, ContactState before) noexcept {
  // every change of contact: a touch beginning (its first tick's depth and the coupling's damping of the device's
  // speed come at once), a release, a grab and its release, a cut starting or ending
  bool event = before != contact_ || controls_event_ || (push_event_ && contact_ != ContactState::kFree);
  controls_event_ = false;
  push_event_ = false;
  // a frame whose patch came from a region placed or moved (no contact model on it), or that brings the first
  // contact model after one, while in contact
  if (m.frame != jump_frame_) {
    if (jump_frame_ >= 0 && contact_ != ContactState::kFree && (!m.has_contact_model || !jump_model_)) event = true;
    jump_frame_ = m.frame;
    jump_model_ = m.has_contact_model;
  }
  return event;
}

void Servo::apply_controls(const Controls& c) noexcept {
  controls_ = c;
  params_ = mode_params_[static_cast<std::size_t>(c.mode)];
  if (params_.tool_radius_m > 0.0 && c.tool_radius_m > 0.0) params_.tool_radius_m = c.tool_radius_m;
  contact_ = ContactState::kFree;
  tri_ = -1;
  friction_ = FrictionState{};
  near_tri_ = -1;
  near_outside_ = false;
  unseen_ = false;
  back_ = bary_turned_ = false;
  shade_ = Quat::Identity();
  shade_n_ = shade_push_ = Vec3::Zero();
  cut_force_N_.setZero();
  restart_pending_ = true;
  controls_event_ = true;  // the force the contact gave goes as a contact's release does (the jump limit)
}

void Servo::tick(int64_t tick_index, double t_s) noexcept {
  DevicePose pose;
  bool rejected = false;
  const bool got = device_->read(t_s, &pose);
  // (a mode that is none of the three is no change: a driver's bad value never indexes past the modes)
  if (pose.controls.seq > controls_.seq && static_cast<unsigned>(pose.controls.mode) < mode_params_.size())
    apply_controls(pose.controls);
  if (!got || !pose.pos_m.allFinite() || pose.pos_m.cwiseAbs().maxCoeff() > device_->specs().workspace_half_m) {
    // no reading (e.g. a disconnected link) and a refused reading are counted apart
    rejected = true;
    if (got) ++counters_.rejected_inputs;
    else ++counters_.no_readings;
    pose = pose_;  // keep the last good pose
  } else {
    pose_ = pose;
  }
  const Vec3 tool = pose.pos_m;
  if (restart_pending_ && !rejected) {
    // the first good reading under new controls: the tool's path starts here (a reset's tool may be far away)
    have_pose_ = false;
    restart_pending_ = false;
    tool_vel_m_per_s_.setZero();
  }
  if (!have_pose_) {
    prev_tool_m_ = tool;
    proxy_m_ = tool;
    have_pose_ = true;
  }
  // tool velocity: first difference, low-passed at velocity_cutoff_hz whatever the rate
  const double period_s = rates_.servo_period_s();
  const Vec3 vel = (tool - prev_tool_m_) / period_s;
  tool_vel_m_per_s_ += low_pass_weight(params_.velocity_cutoff_hz, period_s) * (vel - tool_vel_m_per_s_);

  const bool button = (pose.buttons & 1u) != 0;
  const LocalModel& latest = model_->read();
  const LocalModel& m = surface_at(latest.controls_seq == controls_.seq ? latest : kNoPatch, t_s);
  const ContactState contact_before = contact_;
  Vec3 axis = pose.orientation * Vec3::UnitZ();
  if (!axis.allFinite() || axis.squaredNorm() < 1e-12) axis = Vec3::UnitZ();
  axis.normalize();
  if (params_.mode == InteractionMode::kCut) update_cut(m, tool, axis, button);
  else if (params_.mode == InteractionMode::kTouch) update_touch(m, tool);
  else update_pull(m, tool, button);

  // after a rejected reading the coupling starts again softly
  if (rejected) {
    ramp_pending_ = true;
  } else if (ramp_pending_) {
    ramp_pending_ = false;
    ramp_start_s_ = t_s;
    guard_.reset();
    ++counters_.ramps;
  }
  Vec3 force = Vec3::Zero();
  // (a free touch tool the patch has lost: where it was last seen outside, so the next patch covers its path)
  god_m_sample_ = contact_ == ContactState::kFree && unseen_ ? unseen_from_m_ : proxy_m_;
  if (contact_ == ContactState::kCut && !rejected) {
    force = cut_force_N_;
    if (params_.ramp_s > 0.0) force *= std::clamp((t_s - ramp_start_s_) / params_.ramp_s, 0.0, 1.0);
  } else if (contact_ != ContactState::kFree && !rejected) {
    // (a grab takes it only on a lattice that settles within a frame: ServoParams::predict_grab)
    if (params_.force_model == ForceModel::kLocalModel && (contact_ != ContactState::kGrab || params_.predict_grab)) {
      const Vec3 before = proxy_m_;
      proxy_m_ = predicted_proxy(m, tool, t_s);
      contact_point_m_ += proxy_m_ - before;
      god_m_sample_ = before;
    }
    if (params_.force_model == ForceModel::kHoldFrame && held_frame_ == m.frame) {
      force = held_force_N_;
    } else {
      // (force shading turns the spring about the device; the proxy stays where the facets hold it)
      const Vec3 spring = contact_ == ContactState::kTouch ? Vec3(shade_ * (proxy_m_ - tool)) : Vec3(proxy_m_ - tool);
      force = params_.coupling_N_per_m * spring - params_.coupling_damping_Ns_per_m * tool_vel_m_per_s_;
      held_force_N_ = force;
      held_frame_ = m.frame;
    }
    if (params_.ramp_s > 0.0) force *= std::clamp((t_s - ramp_start_s_) / params_.ramp_s, 0.0, 1.0);
  } else {
    held_frame_ = -2;
  }
  if (params_.passivity && !rejected) {
    const int64_t before = guard_.activations();
    // the observer runs on every tick; its damping acts only through a contact (never as drag in free air)
    const Vec3 guarded = guard_.filter(force, tool - prev_tool_m_, period_s, params_.jump_limit_N_per_tick);
    if (contact_ != ContactState::kFree) force = guarded;
    counters_.passivity_activations += guard_.activations() - before;
    counters_.passivity_dissipated_J = guard_.dissipated_J();
  }
  // a step the device's motion does not explain reaches the hand at most jump_limit_N_per_tick a tick
  if (rejected) {
    jump_.reset();
  } else {
    if (jump_event(m, contact_before)) jump_.absorb(last_.force_N, force);
    force = jump_.apply(force, params_.jump_limit_N_per_tick);
  }
  // a driver fading its link out (browser watchdog) scales the force; anything but 0..1 counts as 0 or 1
  const double scale = rejected ? 1.0 : pose.force_scale > 0.0 ? std::min(pose.force_scale, 1.0) : 0.0;
  if (scale != 1.0) force *= scale;
  force = limit_force(force, device_->specs().max_force_N);
  guard_.sent(force);
  device_->write_force(force);

  HapticSample s;
  s.tick = tick_index;
  s.t_s = t_s;
  s.tool_pos_m = tool;
  s.proxy_pos_m = proxy_m_;
  s.god_pos_m = god_m_sample_;
  s.force_N = force;
  s.contact = contact_;
  s.contact_tri = contact_ == ContactState::kFree ? -1 : tri_;
  // (a surface touched from its back is felt turned over: its corners 1 and 2 swapped)
  s.contact_bary = bary_turned_ && contact_ == ContactState::kTouch ? Vec3(bary_[0], bary_[2], bary_[1]) : bary_;
  s.buttons = pose.buttons;
  s.input_rejected = rejected ? 1 : 0;
  s.blade_axis = axis;
  s.wake_latency_us = wake_latency_us_;
  s.model_frame = latest.frame;  // the patch read (felt, or passed over under new controls): the run's order
  s.force_scale = scale;
  s.controls = controls_;
  if (!samples_->try_push(s)) ++counters_.dropped_samples;
  last_ = s;
  counters_.max_force_N = std::max(counters_.max_force_N, force.norm());
  ++counters_.ticks;
  prev_tool_m_ = tool;
  prev_button_ = button;
}

}  // namespace palpate
