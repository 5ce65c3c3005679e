#pragma once
/// Contact response: the object's linearised response at a contact, what the servo extrapolates the contact with
/// between sim frames (multirate force): where the contact point is and how fast it moves at the frame, the force
/// that acted on it, and the lattice's static compliance there. Thread: the sim thread.

#include "core/types.h"
#include "sim/contact/contact_compliance.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// The response at one contact, at one frame. Plain data.
struct ContactResponse {
  Vec3 p0_m = Vec3::Zero();                ///< contact point (deformed surface)
  Vec3 v0_m_per_s = Vec3::Zero();          ///< its velocity: the loaded nodes' velocities by their weights
  Vec3 f0_N = Vec3::Zero();                ///< force on the object during the frame's step
  Mat3 compliance_m_per_N = Mat3::Zero();  ///< C = W^T K^-1 W (3 x 3, symmetric)
  double radius_m = 0.0;                   ///< the linearisation holds within this distance of p0 (a cell)
};

/// The response of `lat` at the contact point point_m loaded by weights `w` with force f_N during the step, its
/// compliance from `compliance` (which keeps its factorisation between calls). False, *out untouched, when w is
/// empty or the lattice's stiffness is singular there.
bool contact_response(const Lattice& lat, const PointWeights& w, const Vec3& point_m, const Vec3& f_N,
                      ContactCompliance* compliance, ContactResponse* out);

/// The same with the compliance `c_m_per_N` given (an estimate, sim/contact/compliance_estimate.h, for a lattice whose factor
/// is not done or cannot be made: hanging nodes). False, *out untouched, when w is empty.
bool contact_response_with(const Lattice& lat, const PointWeights& w, const Vec3& point_m, const Vec3& f_N,
                           const Mat3& c_m_per_N, ContactResponse* out);

}  // namespace palpate
