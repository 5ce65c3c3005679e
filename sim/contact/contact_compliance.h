#pragma once
/// ContactCompliance: the lattice's static compliance at the contact point (3x3, m/N), linearised about the
/// current configuration — how far the surface point moves per newton pushed on it. It lets the servo update
/// the contact between 60 Hz sim frames (multirate force).

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/types.h"
#include "sim/lattice/lattice.h"

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
  /// (e.g. no fixed node) and *c_m_per_N is left unchanged. refactor forces a new factorisation. With a work
  /// budget set, a factorisation is spread over calls: each eliminates columns until the budget is spent and
  /// returns false until the last (K as assembled at the first; a changed lattice starts again).
  bool compute(const Lattice& lat, const PointWeights& w, bool refactor, Mat3* c_m_per_N);

  /// The factorisation's work per compute() call, in 3x3 block updates (<= 0, the default: all at once). A count,
  /// not a time, so a lockstep run stays reproducible.
  void set_work_per_call(int64_t blocks);

  /// Sizes and writes the storage of a lattice of up to `nodes` nodes and `springs` springs (capped at 4096 nodes),
  /// with cell_terms its cells' volume or Neo-Hookean blocks, so its first factorisation does not pay for fresh
  /// memory; call before a realtime run starts.
  void reserve(int64_t nodes, int64_t springs, bool cell_terms);

  /// True while a factorisation is under way (begun, not finished).
  bool factoring() const;

  /// True when a factorisation of `lat` as it is numbered now (its revision, nodes and springs) is done and sound:
  /// solve() and condense() use it.
  bool ready(const Lattice& lat) const;

  /// u = K^-1 f for node forces f (n; fixed nodes' entries ignored, their u zero). False when no factorisation is done or f's
  /// size is not the factored lattice's.
  bool solve(const std::vector<Vec3>& f_N, std::vector<Vec3>* u_m);

  /// The compliance between point loads: C(i, j) = (W_i d_i)^T K^-1 (W_j d_j), the displacement of load i's point along
  /// its direction d_i per newton of load j along d_j (loads[i]: weights W_i, dirs[i]: d_i). Dense, symmetric,
  /// positive semi-definite. False when no factorisation is done or a load names a node it does not have.
  bool condense(const std::vector<PointWeights>& loads, const std::vector<Vec3>& dirs, Eigen::MatrixXd* c);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int64_t work_per_call_ = 0;
};

}  // namespace palpate
