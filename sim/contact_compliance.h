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

/// A point force, or a force spread over a contact patch, as lattice nodes and weights (weights sum to 1 over free
/// and fixed nodes).
struct PointWeights {
  static constexpr int kMax = 256;  ///< a point: 3 triangle corners x 8 cell nodes; a patch: the nodes of its cells
  std::array<int32_t, kMax> node{};
  std::array<double, kMax> weight{};
  int count = 0;
  /// Adds w to node's weight (a new entry when the node is not listed yet); false when full.
  bool add(int32_t node_id, double w) {
    for (int i = 0; i < count; ++i)
      if (node[i] == node_id) {
        weight[i] += w;
        return true;
      }
    if (count == kMax) return false;
    node[count] = node_id;
    weight[count++] = w;
    return true;
  }
};

/// Factorises the lattice's stiffness (again when given another lattice or revision, or its node or spring count
/// changes, or refactor is asked) and condenses it to a point. Thread: the sim thread. Not copyable.
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
