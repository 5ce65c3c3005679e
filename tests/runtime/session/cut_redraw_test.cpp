// CutRedraw: the renderer's layer stays valid while a blade cuts a block over many frames, and a stroke redraws it
// rarely.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/binding.h"
#include "sim/cut/cut.h"
#include "sim/solvers/integrator.h"
#include "sim/solvers/static_solve.h"
#include "support/fixtures.h"
#include "runtime/session/cut_redraw.h"

namespace palpate {
namespace {

// A block is cut by a stroke over 60 frames along the plane x + z = 4.5 cm: without gravity nothing moves and
// only the blade's reach grows the moving part; resting under gravity on its floor, the lattice moves where its
// springs were cut too. Within each layer epoch the layer holds the static part drawn at the epoch's start: every triangle the
// cut replaced must have had a moving vertex then (it was not in the layer), and every vertex not moving must
// still be within the tolerance of where the layer drew it. Not everything moves: the layer is kept over most
// frames and only a part of the mesh is redrawn.
TEST(CutRedraw, TheLayerHoldsOnlyWhatNoFrameChangedWhileABladeCuts) {
  for (const double gravity_m_per_s2 : {0.0, 9.81}) {
    SCOPED_TRACE(gravity_m_per_s2);
    constexpr double kSide_m = 0.08;
    constexpr int kLevel = 3;  // 2 cm cells
    const test::BoxModel box = test::make_box_model(kSide_m, 4, 16);
    LatticeSpec spec = test::spec_for(kLevel, 40, 20, 10);
    spec.fix_floor = true;
    spec.gravity_m_per_s2 = Vec3(0, 0, -gravity_m_per_s2);
    Lattice lat = build_lattice(box.grid, spec, region_cells(box.grid, kLevel, {1, 1, 1}, 8)).value();
    const auto settled = solve_static(&lat, {}, {});
    ASSERT_TRUE(settled) << settled.error().message;
    CutModel cut(box.mesh, bind_vertices(box.grid, kLevel, box.mesh.vertices_m), &box.grid, kLevel, 0.2);
    cut.set_max_cut_work_per_apply(400);
    std::vector<Vec3> vertices;
    cut.deform(lat, &vertices);
    const double tol_m = kRedrawTolerance * kSide_m;
    CutRedraw redraw(lat, box.grid.num_cells(kLevel), tol_m);
    IntegratorWorkspace ws;

    auto tris_E = cut.triangles();
    auto moving_E = redraw.moving_vertices();
    auto vertices_E = vertices;
    uint64_t epoch = redraw.layer_epoch();
    int frames_kept = 0;
    std::size_t first_grown = 0;  // moving vertices when the part first grew
    const Vec3 axis = Vec3(-1.0, 0.0, 1.0).normalized();
    for (int f = 0; f < 120; ++f) {
      // the blade sweeps 2 mm a frame along y, its edge across the block's +x top corner, for 60 frames
      const bool cutting = f < 60;
      const Vec3 tip(0.07, -0.06 + 0.002 * f, -0.025);
      for (int s = 0; s < 4 && cutting; ++s)
        cut.add_sample(tip + Vec3(0, 0.0005 * s, 0), axis, true);
      const std::size_t first_new = cut.rest_vertices_m().size();
      const CutReport rep = cut.apply(&lat, &vertices);
      step_lattice(&lat, IntegratorKind::kSymplecticEuler, 1.0 / 60.0, 256, {}, &ws);
      apply_floor(&lat, -kSide_m / 2);
      cut.deform(lat, &vertices);
      redraw.update(lat, cut, cutting, tip, tip + 0.2 * axis, rep.split.edges_cut > 0, first_new);
      const auto& moving = redraw.moving_vertices();
      ASSERT_TRUE(std::is_sorted(moving.begin(), moving.end()));
      if (redraw.layer_epoch() != epoch) {
        epoch = redraw.layer_epoch();
        if (first_grown == 0) first_grown = moving.size();
        tris_E = cut.triangles();
        moving_E = moving;
        vertices_E = vertices;
        continue;
      }
      ++frames_kept;
      auto was_moving = [&](int32_t v) { return std::binary_search(moving_E.begin(), moving_E.end(), v); };
      for (std::size_t t = 0; t < tris_E.size(); ++t) {
        if (cut.triangles()[t] == tris_E[t]) continue;
        const auto& old = tris_E[t];
        EXPECT_TRUE(was_moving(old[0]) || was_moving(old[1]) || was_moving(old[2])) << "frame " << f << " tri " << t;
      }
      for (std::size_t v = 0; v < vertices_E.size(); ++v) {
        if (std::binary_search(moving.begin(), moving.end(), static_cast<int32_t>(v))) continue;
        ASSERT_LE((vertices[v] - vertices_E[v]).norm(), tol_m) << "frame " << f << " vertex " << v;
      }
      // the split's new vertices move
      for (std::size_t v = vertices_E.size(); v < vertices.size(); ++v)
        ASSERT_TRUE(std::binary_search(moving.begin(), moving.end(), static_cast<int32_t>(v))) << "vertex " << v;
    }
    EXPECT_GT(lat.springs.size(), 0u);
    EXPECT_GT(cut.triangles().size(), box.mesh.triangles.size());
    EXPECT_GT(redraw.layer_changes(), 1);
    EXPECT_GT(frames_kept, 60);
    // the blade's first reach made only part of the block moving
    EXPECT_GT(first_grown, 0u);
    EXPECT_LT(first_grown, box.mesh.vertices_m.size());
  }
}

// A blade drawn straight across a 12k-triangle block (16 cells of 5 mm a side, as a 10 cm scan's level-5 grid) at
// 1 mm a frame, 80 mm of it inside the block: a redraw of the layer takes the cells the edge sweeps over the next
// kBladeLeadFrames frames (30 mm) and kBladeReachCells cells (5 mm) around it, and the next is due when the edge
// comes within a cell (5 mm) of a cell not taken, so one redraw serves 30 mm: one when the edge enters the block,
// then at most ceil(80 / 30) = 3 more, 4 in all (3 here). Taking only the edge's reach (kBladeLeadFrames = 0, as
// before) redraws every 5-10 mm (6 times with 2 cells of reach). The cells the blade left behind, where nothing
// moves, leave the part at each redraw: at the end no moving cell lies more than kBladeReachCells + 1 cells behind
// where the edge was at the last redraw (without that the part grows with every cell the blade crossed).
TEST(CutRedraw, AStrokeAcrossABigMeshRedrawsTheLayerRarelyAndTheMovingPartFollowsTheBlade) {
  constexpr double kSide_m = 0.08;
  constexpr int kLevel = 5;  // 5 mm cells
  const test::BoxModel box = test::make_box_model(kSide_m, kLevel, 32);
  ASSERT_GT(box.mesh.triangles.size(), 12000u);
  LatticeSpec spec = test::spec_for(kLevel, 40, 20, 10);
  Lattice lat = build_lattice(box.grid, spec, region_cells(box.grid, kLevel, {8, 8, 8}, 16)).value();
  CutModel cut(box.mesh, bind_vertices(box.grid, kLevel, box.mesh.vertices_m), &box.grid, kLevel, 0.05);
  std::vector<Vec3> vertices;
  cut.deform(lat, &vertices);
  CutRedraw redraw(lat, box.grid.num_cells(kLevel), kRedrawTolerance * kSide_m);

  // the blade upright, its tip 2 cm under the top face, drawn along x from outside the block to outside it
  const Vec3 axis(0.0, 0.0, 1.0);
  constexpr int kFrames = 100;
  constexpr double kStep_m = 0.001;
  uint64_t epoch = redraw.layer_epoch();
  auto tris_E = cut.triangles();
  auto moving_E = redraw.moving_vertices();
  double tip_x_at_redraw_m = 0.0;
  for (int f = 0; f < kFrames; ++f) {
    const Vec3 tip(-0.05 + kStep_m * f, 0.003, 0.02);
    for (int s = 0; s < 4; ++s) cut.add_sample(tip + Vec3(0.25 * kStep_m * s, 0, 0), axis, true);
    const std::size_t first_new = cut.rest_vertices_m().size();
    const CutReport rep = cut.apply(&lat, &vertices);
    cut.deform(lat, &vertices);
    redraw.update(lat, cut, true, tip, tip + 0.05 * axis, rep.split.edges_cut > 0, first_new);
    if (redraw.layer_epoch() != epoch) {
      epoch = redraw.layer_epoch();
      tip_x_at_redraw_m = tip.x();
      tris_E = cut.triangles();
      moving_E = redraw.moving_vertices();
      continue;
    }
    // within a layer, a triangle the blade replaced had a moving vertex when the layer was drawn
    auto was_moving = [&](int32_t v) { return std::binary_search(moving_E.begin(), moving_E.end(), v); };
    for (std::size_t t = 0; t < tris_E.size(); ++t) {
      if (cut.triangles()[t] == tris_E[t]) continue;
      const auto& old = tris_E[t];
      ASSERT_TRUE(was_moving(old[0]) || was_moving(old[1]) || was_moving(old[2])) << "frame " << f << " tri " << t;
    }
  }
  EXPECT_GT(cut.triangles().size(), box.mesh.triangles.size());  // the blade cut the mesh
  EXPECT_GE(redraw.layer_changes(), 2);
  EXPECT_LE(redraw.layer_changes(), 4);
  // the moving part follows the blade: no cell far behind where the edge was at the last redraw
  const int n = lat.cells_per_axis;
  ASSERT_FALSE(redraw.moving_cells().empty());
  for (int32_t c : redraw.moving_cells()) {
    const double cell_hi_x_m = -0.5 * kSide_m + lat.cell_m * (c % n + 1);
    EXPECT_GE(cell_hi_x_m, tip_x_at_redraw_m - (kBladeReachCells + 1) * lat.cell_m) << "cell " << c;
  }
}

}  // namespace
}  // namespace palpate
