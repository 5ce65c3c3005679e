#pragma once
// A refined lattice under external forces, stepped to rest with implicit Euler: its hanging nodes stay on their faces
// and no free-coordinate force is left. Shared by the refined and graded lattice tests and the cell-term ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "sim/lattice/forces.h"
#include "sim/lattice/hanging.h"
#include "sim/solvers/integrator.h"

namespace palpate::test {

// Steps lat under f_ext (n) for `frames` 1/60 s frames and checks the rest: hanging nodes on their faces, every free
// coordinate's force (hanging nodes' folded onto their masters) under 1e-4 of the largest applied force.
inline void expect_rest_on_faces(Lattice& lat, const std::vector<Vec3>& f_ext, int frames = 200) {
  IntegratorWorkspace ws;
  for (int frame = 0; frame < frames; ++frame)
    ASSERT_TRUE(step_lattice(&lat, IntegratorKind::kImplicitEuler, 1.0 / 60.0, 1, f_ext, &ws).solver_ok);
  for (const HangingNode& h : lat.hanging) {
    Vec3 on_face = Vec3::Zero();
    for (int k = 0; k < h.count; ++k)
      on_face += h.weight[static_cast<std::size_t>(k)] * lat.x_m[static_cast<std::size_t>(h.master[static_cast<std::size_t>(k)])];
    EXPECT_LT((lat.x_m[static_cast<std::size_t>(h.node)] - on_face).norm(), 1e-14);
  }
  std::vector<Vec3> f;
  compute_forces(lat, lat.x_m, lat.v_m_per_s, f_ext, &f);
  fold_hanging(lat, &f);
  for (std::size_t d = 0; d < lat.held_dof.size(); ++d)
    if (lat.held_dof[d]) f[d / 3][static_cast<int>(d % 3)] = 0.0;  // a support's reaction (folded from a hanging node)
  double worst = 0.0, applied = 0.0;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) {
    if (!lat.fixed[i]) worst = std::max(worst, f[i].norm());
    applied = std::max(applied, f_ext[i].norm());
  }
  EXPECT_LT(worst, 1e-4 * applied);
}

// The node nearest `top` pressed down by 0.05 N until at rest (expect_rest_on_faces), and moved by it.
inline void expect_pressed_rest_on_faces(Lattice& lat, const Vec3& top) {
  std::vector<Vec3> f_ext(lat.num_nodes(), Vec3::Zero());
  std::size_t pressed = 0;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if ((lat.rest_m[i] - top).norm() < (lat.rest_m[pressed] - top).norm()) pressed = i;
  f_ext[pressed] = Vec3(0.0, 0.0, -0.05);
  expect_rest_on_faces(lat, f_ext);
  EXPECT_GT((lat.x_m[pressed] - lat.rest_m[pressed]).norm(), 1e-6);
}

}  // namespace palpate::test
