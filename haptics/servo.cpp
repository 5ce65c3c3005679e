#include "haptics/servo.h"

#include <algorithm>
#include <cmath>

#include "haptics/force_limit.h"
#include "haptics/triangle_queries.h"

namespace palpate {

Servo::Servo(const ServoParams& params, const Rates& rates, Device* device, SpscQueue<HapticSample>* samples,
             TripleBuffer<LocalModel>* model)
    : params_(params), rates_(rates), device_(device), samples_(samples), model_(model) {}

bool Servo::closest_on_patch(const LocalModel& m, const Vec3& p, int* slot, Vec3* point, Vec3* bary,
                             const Vec3* side) const noexcept {
  double best = INFINITY;
  for (int i = 0; i < m.num_triangles; ++i) {
    Vec3 b = Vec3::Zero();
    const auto& t = m.tri_m[i];
    if (side && (t[1] - t[0]).cross(t[2] - t[0]).dot(*side) <= 0.0) continue;
    const Vec3 q = closest_point_on_triangle(p, t[0], t[1], t[2], &b);
    const double d = (q - p).squaredNorm();
    if (d < best) {
      best = d;
      *slot = i;
      *point = q;
      *bary = b;
    }
  }
  return best < INFINITY;
}

bool Servo::held_point(const LocalModel& m, Vec3* point) const noexcept {
  for (int i = 0; i < m.num_triangles; ++i)
    if (m.tri_ids[i] == tri_) {
      const auto& t = m.tri_m[i];
      *point = bary_[0] * t[0] + bary_[1] * t[1] + bary_[2] * t[2];
      return true;
    }
  return false;
}

void Servo::update_touch(const LocalModel& m, const Vec3& tool) noexcept {
  if (contact_ == ContactState::kFree) {
    // contact starts when the tool's path since the last tick enters the surface from outside
    for (int i = 0; i < m.num_triangles; ++i) {
      const auto& t = m.tri_m[i];
      double u = 0.0;
      Vec3 b = Vec3::Zero();
      if (segment_enters_triangle(prev_tool_m_, tool, t[0], t[1], t[2], &u, &b)) {
        contact_ = ContactState::kTouch;
        contact_normal_ = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
        break;
      }
    }
    if (contact_ == ContactState::kFree) {
      proxy_m_ = tool;
      return;
    }
  }
  // in contact: P_s is the nearest surface point on the side the contact began on (a tool pushed past the middle
  // of a thin part stays with its entry face: no pop-through); the tool is inside while it lies behind the
  // surface's smooth (vertex-interpolated) normal there, which stays consistent across edges and in dents
  int slot = -1;
  Vec3 q = Vec3::Zero(), b = Vec3::Zero();
  if (!closest_on_patch(m, tool, &slot, &q, &b, &contact_normal_)) return;
  const auto& n = m.normal[slot];
  const Vec3 normal = b[0] * n[0] + b[1] * n[1] + b[2] * n[2];
  if (normal.squaredNorm() > 0.0) contact_normal_ = normal.normalized();
  if ((tool - q).dot(normal) > 0.0) {
    contact_ = ContactState::kFree;
    tri_ = -1;
    proxy_m_ = tool;
    return;
  }
  tri_ = m.tri_ids[slot];
  bary_ = b;
  proxy_m_ = q;
}

void Servo::update_touch_sphere(const LocalModel& m, const Vec3& tool) noexcept {
  const double r = params_.tool_radius_m;
  if (contact_ == ContactState::kFree) {
    // contact starts when the sphere reaches a face from its front: the centre's path since the last tick enters
    // it (a fast tool), or the centre comes within the radius of it while in front of its plane
    for (int i = 0; i < m.num_triangles && contact_ == ContactState::kFree; ++i) {
      const auto& t = m.tri_m[i];
      const Vec3 face = (t[1] - t[0]).cross(t[2] - t[0]);
      double u = 0.0;
      Vec3 b = Vec3::Zero();
      const Vec3 q = closest_point_on_triangle(tool, t[0], t[1], t[2], &b);
      if (segment_enters_triangle(prev_tool_m_, tool, t[0], t[1], t[2], &u, &b) ||
          ((tool - q).squaredNorm() < r * r && (tool - q).dot(face) > 0.0)) {
        contact_ = ContactState::kTouch;
        contact_normal_ = face.normalized();
      }
    }
    if (contact_ == ContactState::kFree) {
      proxy_m_ = contact_point_m_ = tool;
      return;
    }
  }
  // the surface point nearest the device's centre on the entry side, as for a point tool: out of reach, contact ends
  int slot = -1;
  Vec3 q = Vec3::Zero(), b = Vec3::Zero();
  if (!closest_on_patch(m, tool, &slot, &q, &b, &contact_normal_)) return;
  const auto& n = m.normal[slot];
  Vec3 normal = b[0] * n[0] + b[1] * n[1] + b[2] * n[2];
  if (normal.squaredNorm() > 0.0) contact_normal_ = normal.normalized();
  const Vec3 d = tool - q;
  if (d.dot(contact_normal_) > 0.0 && d.squaredNorm() >= r * r) {
    contact_ = ContactState::kFree;
    tri_ = -1;
    proxy_m_ = contact_point_m_ = tool;
    return;
  }
  // god-object: the centre follows the device from where it was, sliding along the surface while the device
  // presses into it (the part of the motion into the surface is dropped), so it rolls round an edge instead of
  // jumping between the faces' offsets; then it is put one radius from the nearest surface point
  Vec3 c = proxy_m_;
  if (closest_on_patch(m, c, &slot, &q, &b, &contact_normal_)) {
    const Vec3 e = c - q;
    const double en = e.norm();
    const Vec3 out = en > 1e-9 * r && e.dot(contact_normal_) > 0.0 ? Vec3(e / en) : contact_normal_;
    Vec3 move = tool - c;
    const double into = move.dot(out);
    if (into < 0.0) move -= into * out;
    c += move;
  }
  if (!closest_on_patch(m, c, &slot, &q, &b, &contact_normal_)) return;
  {
    const Vec3 e = c - q;
    const double en = e.norm();
    const auto& nn = m.normal[slot];
    Vec3 sn = b[0] * nn[0] + b[1] * nn[1] + b[2] * nn[2];
    sn = sn.squaredNorm() > 0.0 ? Vec3(sn.normalized()) : contact_normal_;
    c = q + r * (en > 1e-9 * r && e.dot(sn) > 0.0 ? Vec3(e / en) : sn);
  }
  // a sphere in a dent or a concave corner also overlaps other faces: push it out of the deepest overlap, a few
  // rounds (each face of the entry side, so the far side of a thin part is never taken)
  for (int round = 0; round < 8; ++round) {
    double worst = 0.0;
    Vec3 push = Vec3::Zero();
    for (int i = 0; i < m.num_triangles; ++i) {
      const auto& t = m.tri_m[i];
      const Vec3 face = (t[1] - t[0]).cross(t[2] - t[0]);
      // faces turned more than 120 degrees from the contact's side are the far side of a thin part
      if (face.dot(contact_normal_) < -0.5 * face.norm()) continue;
      Vec3 bi = Vec3::Zero();
      const Vec3 qi = closest_point_on_triangle(c, t[0], t[1], t[2], &bi);
      const Vec3 e = c - qi;
      const double dist = e.norm();
      if (dist >= r) continue;  // the sphere does not reach this face
      const bool in_front = e.dot(face) > 0.0;
      const double depth = in_front ? r - dist : r + dist;  // how far the sphere reaches past this face (centre behind it: through)
      if (depth > worst + 1e-12 * r) {
        worst = depth;
        push = (in_front && dist > 1e-9 * r ? Vec3(e / dist) : Vec3(face.normalized())) * depth;
      }
    }
    if (worst <= 1e-9 * r) break;
    c += push;
  }
  // the contact point: the surface point under the centre
  if (!closest_on_patch(m, c, &slot, &q, &b, &contact_normal_)) return;
  tri_ = m.tri_ids[slot];
  bary_ = b;
  proxy_m_ = c;
  contact_point_m_ = q;
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
  if (held_point(m, &p)) proxy_m_ = p;
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
  // (a sphere's centre moves with the surface point under it)
  const Vec3& at = params_.tool_radius_m > 0.0 ? contact_point_m_ : proxy_m_;
  if (!m.has_contact_model || (at - m.contact_p0_m).norm() > m.model_radius_m) return proxy_m_;
  // the proxy P rides the surface, which has moved by v0 tau + C (F_obj - f0) with F_obj = -k_c (P - P_t);
  // solving for P: (I + k_c C) P = P_frame + v0 tau - C f0 + k_c C P_t
  const double k = params_.coupling_N_per_m;
  const double tau = std::max(0.0, t_s - m.t_s);
  const Mat3& c = m.compliance_m_per_N;
  const Mat3 a = Mat3::Identity() + k * c;
  const Vec3 rhs = proxy_m_ + tau * m.contact_v0_m_per_s - c * m.contact_f0_N + k * (c * tool);
  const Vec3 p = a.inverse() * rhs;
  return p.allFinite() ? p : proxy_m_;
}

void Servo::tick(int64_t tick_index, double t_s) noexcept {
  DevicePose pose;
  bool rejected = false;
  const bool got = device_->read(t_s, &pose);
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
  const LocalModel& m = model_->read();
  Vec3 axis = pose.orientation * Vec3::UnitZ();
  if (!axis.allFinite() || axis.squaredNorm() < 1e-12) axis = Vec3::UnitZ();
  axis.normalize();
  if (params_.mode == InteractionMode::kCut) update_cut(m, tool, axis, button);
  else if (params_.mode == InteractionMode::kTouch && params_.tool_radius_m > 0.0) update_touch_sphere(m, tool);
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
  if (contact_ == ContactState::kCut && !rejected) {
    force = cut_force_N_;
    if (params_.ramp_s > 0.0) force *= std::clamp((t_s - ramp_start_s_) / params_.ramp_s, 0.0, 1.0);
  } else if (contact_ != ContactState::kFree && !rejected) {
    if (params_.force_model == ForceModel::kLocalModel) {
      const Vec3 before = proxy_m_;
      proxy_m_ = predicted_proxy(m, tool, t_s);
      contact_point_m_ += proxy_m_ - before;
    }
    if (params_.force_model == ForceModel::kHoldFrame && held_frame_ == m.frame) {
      force = held_force_N_;
    } else {
      force = params_.coupling_N_per_m * (proxy_m_ - tool) - params_.coupling_damping_Ns_per_m * tool_vel_m_per_s_;
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
    const Vec3 guarded = guard_.filter(force, tool - prev_tool_m_, period_s);
    if (contact_ != ContactState::kFree) force = guarded;
    counters_.passivity_activations += guard_.activations() - before;
    counters_.passivity_dissipated_J = guard_.dissipated_J();
  }
  force = limit_force(force, device_->specs().max_force_N);
  guard_.sent(force);
  device_->write_force(force);

  HapticSample s;
  s.tick = tick_index;
  s.t_s = t_s;
  s.tool_pos_m = tool;
  s.proxy_pos_m = proxy_m_;
  s.force_N = force;
  s.contact = contact_;
  s.contact_tri = contact_ == ContactState::kFree ? -1 : tri_;
  s.contact_bary = bary_;
  s.buttons = pose.buttons;
  s.input_rejected = rejected ? 1 : 0;
  s.blade_axis = axis;
  s.wake_latency_us = wake_latency_us_;
  if (!samples_->try_push(s)) ++counters_.dropped_samples;
  last_ = s;
  counters_.max_force_N = std::max(counters_.max_force_N, force.norm());
  ++counters_.ticks;
  prev_tool_m_ = tool;
  prev_button_ = button;
}

}  // namespace palpate
