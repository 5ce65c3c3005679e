#pragma once
/// An estimate of the lattice's compliance at a contact from its local stiffness alone, without a factorisation:
/// what the servo's contact model takes while the region's factor is still being made (in slices over frames) or
/// cannot be made (a refined lattice's hanging nodes). It errs high on purpose: a servo that takes the surface as
/// more compliant than it is converges on it a little slower, one that takes it as stiffer than half its compliance
/// overshoots past it each frame (the force then chatters). Thread: the sim thread.

#include <vector>

#include "core/types.h"
#include "sim/contact/contact_compliance.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// The compliance a point load on one surface node of a lattice has, per that node's stiffness (its 3x3 diagonal
/// block's mean eigenvalue): measured on a block held at its floor, the largest over a face's middle, an edge's and a
/// corner node at levels 3-5 (tests/sim/contact/compliance_estimate_test.cpp: 3.1 for springs), rounded up.
inline constexpr double kNodeComplianceTimesStiffness = 3.2;

/// What a cell's Neo-Hookean term adds to each corner's stiffness trace, per mu l: measured the same way (the node
/// compliance of a Neo-Hookean lattice at nu 0.45 is 2.2 times that of springs carrying the same shear).
inline constexpr double kNeoHookeanCornerStiffness = 0.75;

/// The loop gain k_c c (coupling times estimated compliance) from which the servo takes the estimate. Coupled by
/// the sampled force alone, each frame the surface moves by k_c c_true times the last frame's miss, the other way:
/// under 1 it settles, over it overshoots and grows. The estimate is 1 to about 5 times c_true, so from this gain on
/// k_c c_true is at least about 1 and the servo needs it; below, the sampled force settles (or nearly), and an
/// estimate several times too compliant would make the servo lag the surface (a stiff surface under a wide patch).
inline constexpr double kEstimateNeededGain = 5.0;

/// c I with c = kNodeComplianceTimesStiffness (sum of w over free nodes)^2 / k, k the free loaded nodes' stiffness
/// (springs, and a Neo-Hookean cell term by kNeoHookeanCornerStiffness; a volume term, which only stiffens, left
/// out) averaged by their weights: 1 to about 4.6 times the factored compliance (the more, the wider the load is
/// spread). Zero when no loaded node is free. scratch: per-node storage, reused.
Mat3 estimate_compliance(const Lattice& lat, const PointWeights& w, std::vector<double>* scratch);

}  // namespace palpate
