// The incision: a slit that does not open still shows, as a groove whose flanks sink along the blade's swept
// surface; a blade along a row of vertices grooves too; the groove never reaches past the blade's tip.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/binding.h"
#include "sim/cut/cut_incision.h"
#include "sim/cut/cut_model.h"
#include "sim/cut_block.h"
#include "sim/sim_test_util.h"

namespace palpate {
namespace {

constexpr double kSide_m = test::kCutBlockSide_m;  // block from -0.04 to 0.04; level 3 cells of 2 cm, mesh quads of 1 cm
constexpr int kLevel = test::kCutBlockLevel;
using Block = test::CutBlock;

// A blade in the plane x = x0 whose tip runs tip_z_m below the top (z = 0.04) across the whole block along y.
BladeQuad slit(double x0, double tip_z_m) {
  return {{x0, -0.06, tip_z_m}, {x0, -0.06, 0.2}, {x0, 0.06, tip_z_m}, {x0, 0.06, 0.2}};
}

// The new vertices that came from edges inside the top face (both ends at z = 0.04, away from its rim), found where
// the same cut without a groove put them (at the crossing).
std::vector<std::size_t> top_copies(const Block& flat, std::size_t first_new) {
  std::vector<std::size_t> out;
  for (std::size_t v = first_new; v < flat.cut.rest_vertices_m().size(); ++v) {
    const Vec3& q = flat.cut.rest_vertices_m()[v];
    if (q.z() > 0.04 - 1e-9 && std::abs(q.y()) < 0.04 - 1e-9) out.push_back(v);
  }
  return out;
}

// A 15 mm deep slit through the top: every copy on the top face sinks along the blade (straight down, its plane
// vertical) by the groove's depth, a quarter cell, and stays on the blade's plane; the mesh stays one valid piece
// and the split's figures are those of a cut with no groove.
TEST(CutIncision, AShallowSlitSinksItsRimIntoAGrooveAlongTheBlade) {
  Block b, flat;
  flat.cut.set_incision_depth_cells(0.0);
  const std::size_t n0 = b.cut.rest_vertices_m().size();
  const CutReport rep = b.cut.apply_quads({slit(0.003, 0.025)}, &b.lat, &b.vertices);
  const CutReport rep_flat = flat.cut.apply_quads({slit(0.003, 0.025)}, &flat.lat, &flat.vertices);
  EXPECT_EQ(rep.split.edges_cut, rep_flat.split.edges_cut);
  EXPECT_EQ(rep.split.triangles_added, rep_flat.split.triangles_added);
  EXPECT_EQ(b.cut.triangles().size(), flat.cut.triangles().size());
  EXPECT_EQ(triangle_components(b.vertices.size(), b.cut.triangles()), 1);
  EXPECT_EQ(mesh_problem(b.cut.rest_vertices_m(), b.cut.triangles()), "");

  const double depth_m = kIncisionDepthCells * b.lat.cell_m;
  const double blade_x = 0.003 + kBladeOffsetCells * b.lat.cell_m * Vec3(1.0, 0.618034, 0.381966).normalized().x();
  const auto top = top_copies(flat, n0);
  ASSERT_GE(top.size(), 14u);  // 7 edges inside the top, two copies each
  for (std::size_t v : top) {
    const Vec3& p = b.cut.rest_vertices_m()[v];
    const Vec3& q = flat.cut.rest_vertices_m()[v];
    EXPECT_NEAR(p.z(), 0.04 - depth_m, 1e-12) << "vertex " << v;  // sunk straight down by the depth
    EXPECT_NEAR(p.x(), blade_x, 1e-12);                           // on the blade's plane
    EXPECT_NEAR(p.y(), q.y(), 1e-12);
    EXPECT_LE((p - q).norm(), b.lat.cell_m);
  }
}

// The groove stops at the blade's tip: a blade whose tip only just entered the top grooves as deep as the tip went.
TEST(CutIncision, TheGrooveIsNoDeeperThanTheBladesTip) {
  Block b, flat;
  const std::size_t n0 = b.cut.rest_vertices_m().size();
  flat.cut.set_incision_depth_cells(0.0);
  b.cut.apply_quads({slit(0.003, 0.04 - 0.001)}, &b.lat, &b.vertices);
  flat.cut.apply_quads({slit(0.003, 0.04 - 0.001)}, &flat.lat, &flat.vertices);
  const auto top = top_copies(flat, n0);
  ASSERT_FALSE(top.empty());
  // the tip, moved with every quad by the blade offset
  const double tip_z = 0.039 + kBladeOffsetCells * b.lat.cell_m * Vec3(1.0, 0.618034, 0.381966).normalized().z();
  for (std::size_t v : top) EXPECT_NEAR(b.cut.rest_vertices_m()[v].z(), tip_z, 1e-12);
}

// A blade along a row of vertices (x = 0, where mesh vertices and lattice nodes lie) still grooves: its copies sink
// by the groove's depth, beside vertices that stay on the surface.
TEST(CutIncision, ABladeAlongARowOfVerticesGroovesToo) {
  Block b, flat;
  flat.cut.set_incision_depth_cells(0.0);
  const std::size_t n0 = b.cut.rest_vertices_m().size();
  b.cut.apply_quads({slit(0.0, 0.025)}, &b.lat, &b.vertices);
  flat.cut.apply_quads({slit(0.0, 0.025)}, &flat.lat, &flat.vertices);
  const auto top = top_copies(flat, n0);
  ASSERT_GE(top.size(), 14u);
  for (std::size_t v : top)
    EXPECT_NEAR(b.cut.rest_vertices_m()[v].z(), 0.04 - kIncisionDepthCells * b.lat.cell_m, 1e-12);
  EXPECT_EQ(mesh_problem(b.cut.rest_vertices_m(), b.cut.triangles()), "");
}

// Where the blade left through the far side of a cut through, the groove sinks into the material from that side
// (up, from the bottom face), not out of it.
TEST(CutIncision, AtTheFaceTheBladeLeftThroughTheGrooveSinksIntoTheMaterial) {
  Block b, flat;
  flat.cut.set_incision_depth_cells(0.0);
  const std::size_t n0 = b.cut.rest_vertices_m().size();
  b.cut.apply_quads({slit(0.003, -0.06)}, &b.lat, &b.vertices);
  flat.cut.apply_quads({slit(0.003, -0.06)}, &flat.lat, &flat.vertices);
  int bottom = 0;
  for (std::size_t v = n0; v < flat.cut.rest_vertices_m().size(); ++v) {
    const Vec3& q = flat.cut.rest_vertices_m()[v];
    if (q.z() > -0.04 + 1e-9 || std::abs(q.y()) > 0.04 - 1e-9) continue;
    ++bottom;
    EXPECT_NEAR(b.cut.rest_vertices_m()[v].z(), -0.04 + kIncisionDepthCells * b.lat.cell_m, 1e-12);
  }
  EXPECT_GE(bottom, 14);
}

// A blade 2 mm wide sets the cut's two sides apart: each pair of copies lies 1 mm either side of the blade's plane,
// each on the side of the triangles it belongs to (a sheet with no thickness, which no groove shows, opens a slit).
TEST(CutIncision, ABladesWidthSetsTheTwoSidesApart) {
  Block b;
  b.cut.set_incision_gap_m(0.002);
  const std::size_t n0 = b.cut.rest_vertices_m().size();
  b.cut.apply_quads({slit(0.003, 0.025)}, &b.lat, &b.vertices);
  const double blade_x = 0.003 + kBladeOffsetCells * b.lat.cell_m * Vec3(1.0, 0.618034, 0.381966).normalized().x();
  const auto& rest = b.cut.rest_vertices_m();
  ASSERT_GE(rest.size(), n0 + 14);
  // the copies come in pairs, one per side of a crossed edge
  for (std::size_t v = n0; v + 1 < rest.size(); v += 2) {
    EXPECT_NEAR(std::abs(rest[v].x() - blade_x), 0.001, 1e-9) << "vertex " << v;
    EXPECT_NEAR(rest[v].x() - blade_x, blade_x - rest[v + 1].x(), 1e-9) << "vertex " << v;
    EXPECT_NEAR(rest[v].y(), rest[v + 1].y(), 1e-12);
    EXPECT_NEAR(rest[v].z(), rest[v + 1].z(), 1e-12);
  }
  // every triangle of the top and the groove lies on one side of the blade's plane: none spans the slit
  for (const auto& t : b.cut.triangles()) {
    if (std::min({rest[t[0]].z(), rest[t[1]].z(), rest[t[2]].z()}) < 0.04 - kIncisionDepthCells * b.lat.cell_m - 1e-9)
      continue;
    double lo = 1.0, hi = -1.0;
    for (int32_t i : t) lo = std::min(lo, rest[i].x() - blade_x), hi = std::max(hi, rest[i].x() - blade_x);
    EXPECT_FALSE(lo < -1e-9 && hi > 1e-9) << "a triangle spans the slit from " << lo << " to " << hi << " m";
  }
  EXPECT_EQ(mesh_problem(rest, b.cut.triangles()), "");
}

}  // namespace
}  // namespace palpate
