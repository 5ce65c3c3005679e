#pragma once
/// ContactCompliance: the lattice's static compliance at the contact point (3x3, m/N), linearised about the
/// current configuration — how far the surface point moves per newton pushed on it. It lets the servo update
/// the contact between 60 Hz sim frames (multirate force).

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/types.h"
#include "sim/lattice.h"

namespace palpate {

/// A point force spread over lattice nodes: node ids and weights (weights sum to 1 over free and fixed nodes).
struct PointWeights {
  static constexpr int kMax = 24;  ///< 3 triangle corners x 8 cell nodes
  std::array<int32_t, kMax> node{};
  std::array<double, kMax> weight{};
  int count = 0;
};

/// Factorises the lattice's stiffness (rebuilt when the lattice's node or spring count changes or refresh is
/// asked) and condenses it to a point. Thread: the sim thread. Not copyable.
class ContactCompliance {
 public:
  ContactCompliance();
  ~ContactCompliance();
  ContactCompliance(const ContactCompliance&) = delete;
  ContactCompliance& operator=(const ContactCompliance&) = delete;

  /// C = W^T K^-1 W for the free nodes of `lat` at its current positions; false when the system is singular
  /// (e.g. no fixed node) and *c_m_per_N is left unchanged. refactor forces a new factorisation.
  bool compute(const Lattice& lat, const PointWeights& w, bool refactor, Mat3* c_m_per_N);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace palpate
