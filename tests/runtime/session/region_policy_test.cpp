// The frame stage's two region policies through their public interface: a LocalRegion is placed at the contact,
// stays while the contact stays inside it and moves (carrying its deformation over) when the contact leaves it;
// a CutRegion holds one lattice over every solid cell from the start, never moves it, and a blade drawn through
// the object cuts springs and splits the mesh while the node count stays what it was. The scene's mode picks
// which one the frame stage holds.
#include "runtime/session/cut_region.h"
#include "runtime/session/local_region.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "core/tri_mesh.h"
#include "runtime/session/frame_stage.h"
#include "runtime/session/region_policy_factory.h"

namespace palpate {
namespace {

// A 6 cm box on a grid of 7.5 mm cells at level 4, in `mode`, with the region's radius and following set.
Scene box_scene(const std::string& mode, int radius_cells, bool follow = true) {
  const std::string json = std::string(R"({
    "mesh": {"box_m": [0.06, 0.06, 0.06], "box_subdivisions": 12, "size_m": 0.06},
    "grid": {"levels": 4},
    "lattice": {"level": 4, "node_mass_kg": 0.003, "stiffness_N_per_m": {"structural": 60, "shear": 30, "bend": 15},
                "damping_Ns_per_m": 0.06, "fix_floor": true, "radius_cells": )") +
                           std::to_string(radius_cells) + ", \"follow_contact\": " + (follow ? "true" : "false") +
                           "},\n\"interaction\": {\"mode\": \"" + mode + R"(", "blade_length_m": 0.2},
    "trajectory": [{"t_s": 0.0, "pos_m": [0.0, 0.0, 0.05]}],
    "duration_s": 1.0
  })";
  return parse_scene(json, "box.json").value();
}

bool same_cell(const CellCoord& a, const CellCoord& b) { return a.i == b.i && a.j == b.j && a.k == b.k; }

int32_t slot_at(const Lattice& lat, const GridHierarchy& grid, const Vec3& p_m) {
  return lat.slot_of_cell[static_cast<std::size_t>(grid.linear_index(grid.cell_of(p_m, lat.level), lat.level))];
}

TEST(LocalRegion, PlacedAtTheContactMovedOnlyWhenTheContactLeavesItAndKeepsItsDeformation) {
  const Scene scene = box_scene("touch", 2);
  const Model model = load_model(scene).value();
  FrameStats stats;
  LocalRegion region(scene, model, &stats);
  std::vector<Vec3> vertices = model.rest.vertices_m, normals;
  const DeformedMesh mesh{&vertices, &normals};
  EXPECT_FALSE(region.prepared_ahead());
  EXPECT_EQ(region.cut_model(), nullptr);
  EXPECT_EQ(&region.triangles(), &model.rest.triangles);

  const double cell = model.grid.cell_size_m(4);
  // points a hair under the top face, at the centres of cells along x
  auto top = [&](int cells_from_left) { return Vec3(-0.03 + (cells_from_left + 0.5) * cell, 0.5 * cell, 0.03 - 1e-4); };
  const Vec3 p0 = top(1);
  EXPECT_FALSE(region.follow(p0, mesh));  // nothing placed yet
  ASSERT_TRUE(region.place(p0, mesh));
  ASSERT_TRUE(region.lattice().has_value());
  const Lattice& first = *region.lattice();
  EXPECT_TRUE(same_cell(region.center(), model.grid.cell_of(p0, 4)));
  EXPECT_GE(slot_at(first, model.grid, p0), 0);
  EXPECT_GT(region.bound_vertices(), 0u);
  const std::size_t nodes0 = first.num_nodes();
  EXPECT_EQ(stats.lattice_nodes, nodes0);
  // a second contact elsewhere does not place it again
  EXPECT_FALSE(region.place(top(6), mesh));
  EXPECT_TRUE(same_cell(region.center(), model.grid.cell_of(p0, 4)));

  // the view names the bound vertices as the moving ones; a rebuild changes the layer epoch
  FrameView view{};
  region.fill_view(HapticSample{}, &view);
  ASSERT_NE(view.moving_vertices, nullptr);
  EXPECT_EQ(view.moving_vertices->size(), region.bound_vertices());
  EXPECT_FALSE(view.show_blade);
  const uint64_t epoch0 = view.layer_epoch;

  // one cell away (inside the radius of 2): the region stays
  EXPECT_FALSE(region.follow(top(2), mesh));
  EXPECT_EQ(stats.region_moves, 0);
  EXPECT_EQ(region.lattice()->num_nodes(), nodes0);

  // press a free node under the contact down by 1 mm and deform the mesh: the vertices bound near it move
  Lattice* lat = region.mutable_lattice();
  ASSERT_NE(lat, nullptr);
  int32_t pressed = -1;
  for (std::size_t i = 0; i < lat->num_nodes(); ++i)
    if (!lat->fixed[i] && (lat->rest_m[i] - p0).norm() < cell) pressed = static_cast<int32_t>(i);
  ASSERT_GE(pressed, 0);
  const int32_t pressed_grid_node = lat->grid_node[pressed];
  lat->x_m[pressed].z() -= 1e-3;
  region.deform(&vertices);
  double moved = 0.0;
  for (std::size_t v = 0; v < vertices.size(); ++v) moved = std::max(moved, (vertices[v] - model.rest.vertices_m[v]).norm());
  EXPECT_GT(moved, 1e-4);

  // two cells from the centre (on the region's outer ring): it moves around the new contact cell
  const Vec3 p1 = top(3);
  ASSERT_TRUE(region.follow(p1, mesh));
  EXPECT_EQ(stats.region_moves, 1);
  EXPECT_TRUE(same_cell(region.center(), model.grid.cell_of(p1, 4)));
  EXPECT_GE(slot_at(*region.lattice(), model.grid, p1), 0);
  // and keeps the pressed node where it was pressed (its cells are still deformed, its state carried over)
  const Lattice& second = *region.lattice();
  const auto it = std::find(second.grid_node.begin(), second.grid_node.end(), pressed_grid_node);
  ASSERT_NE(it, second.grid_node.end());
  const auto at = static_cast<std::size_t>(it - second.grid_node.begin());
  EXPECT_EQ(second.x_m[at].z(), second.rest_m[at].z() - 1e-3);
  region.fill_view(HapticSample{}, &view);
  EXPECT_NE(view.layer_epoch, epoch0);
  // the new contact is inside the moved region: it stays
  EXPECT_FALSE(region.follow(p1, mesh));
  EXPECT_EQ(stats.region_moves, 1);

  // normals: computed in full when there are none, then only the region's; either way equal to a full pass
  region.update_normals(true, mesh);
  std::vector<Vec3> full;
  compute_vertex_normals(vertices, model.rest.triangles, &full);
  ASSERT_EQ(normals.size(), full.size());
  lat = region.mutable_lattice();
  ASSERT_NE(lat, nullptr);
  lat->x_m[at].z() -= 1e-3;
  region.deform(&vertices);
  region.update_normals(true, mesh);
  compute_vertex_normals(vertices, model.rest.triangles, &full);
  bool same = true;
  for (std::size_t v = 0; v < full.size(); ++v) same = same && (full[v].array() == normals[v].array()).all();
  EXPECT_TRUE(same);
}

TEST(LocalRegion, StaysPutWhenTheSceneTurnsFollowingOff) {
  const Scene scene = box_scene("pull", 2, false);
  const Model model = load_model(scene).value();
  FrameStats stats;
  LocalRegion region(scene, model, &stats);
  std::vector<Vec3> vertices = model.rest.vertices_m, normals;
  const DeformedMesh mesh{&vertices, &normals};
  const double cell = model.grid.cell_size_m(4);
  ASSERT_TRUE(region.place(Vec3(-0.03 + 1.5 * cell, 0.5 * cell, 0.03 - 1e-4), mesh));
  const CellCoord c0 = region.center();
  EXPECT_FALSE(region.follow(Vec3(0.03 - 1.5 * cell, 0.5 * cell, 0.03 - 1e-4), mesh));
  EXPECT_TRUE(same_cell(region.center(), c0));
  EXPECT_EQ(stats.region_moves, 0);
}

// Servo samples of a blade along +y (tip at y = -0.1, 0.2 m long) at height z_m, drawn from x = +0.1 to -0.1
// with the button held, then released.
void draw_blade(RegionPolicy* region, double z_m) {
  constexpr int kSteps = 40;
  for (int k = 0; k <= kSteps + 1; ++k) {
    HapticSample s;
    s.tick = k;
    s.tool_pos_m = Vec3(0.1 - 0.2 * std::min(k, kSteps) / kSteps, -0.1, z_m);
    s.blade_axis = Vec3::UnitY();
    s.buttons = k <= kSteps ? 1u : 0u;
    region->add_sample(s);
  }
}

TEST(CutRegion, OneWholeObjectLatticeThatNeverMovesAndWhoseSpringsTheBladeCuts) {
  const Scene scene = box_scene("cut", 2);
  const Model model = load_model(scene).value();
  FrameStats stats;
  CutRegion region(scene, model, &stats);
  std::vector<Vec3> vertices = model.rest.vertices_m, normals;
  const DeformedMesh mesh{&vertices, &normals};

  // the whole object from the start: every solid cell, only the floor fixed; nothing stepped (no solver prepared
  // ahead) until a piece comes free
  ASSERT_TRUE(region.lattice().has_value());
  const Lattice& lat = *region.lattice();
  EXPECT_FALSE(region.prepared_ahead());
  EXPECT_EQ(region.stepped_lattice(), nullptr);
  EXPECT_EQ(static_cast<int64_t>(lat.cells.size()), model.grid.solid_cells(4));
  const std::size_t nodes0 = lat.num_nodes(), springs0 = lat.springs.size();
  EXPECT_EQ(stats.lattice_nodes, nodes0);
  EXPECT_EQ(stats.lattice_springs, springs0);
  double floor = 1e9;
  for (const Vec3& r : lat.rest_m) floor = std::min(floor, r.z());
  EXPECT_EQ(region.floor_z_m(), floor);
  for (std::size_t i = 0; i < nodes0; ++i) EXPECT_EQ(lat.fixed[i] != 0, lat.rest_m[i].z() == floor) << i;
  ASSERT_NE(region.cut_model(), nullptr);
  EXPECT_EQ(&region.triangles(), &region.cut_model()->triangles());

  // contacts anywhere never place or move it
  EXPECT_FALSE(region.place(Vec3(0.025, 0.025, 0.03), mesh));
  EXPECT_FALSE(region.follow(Vec3(0.025, 0.025, 0.03), mesh));
  EXPECT_FALSE(region.follow(Vec3(-0.025, -0.025, 0.03), mesh));
  EXPECT_EQ(&*region.lattice(), &lat);
  EXPECT_EQ(lat.num_nodes(), nodes0);
  EXPECT_EQ(stats.region_moves, 0);

  // the view: the blade drawn, and nothing moving yet (the layer holds the whole mesh until a cut or a node moves)
  HapticSample latest;
  latest.tool_pos_m = Vec3(0.01, -0.1, 0.0);
  latest.blade_axis = Vec3::UnitY();
  FrameView view{};
  region.fill_view(latest, &view);
  EXPECT_TRUE(view.show_blade);
  ASSERT_NE(view.moving_vertices, nullptr);
  EXPECT_TRUE(view.moving_vertices->empty());
  EXPECT_TRUE(view.static_part_kept);
  EXPECT_EQ((view.blade_end_m - Vec3(0.01, 0.1, 0.0)).norm(), 0.0);
  EXPECT_EQ((region.patch_edge(latest) - Vec3(0.0, 0.2, 0.0)).norm(), 0.0);

  // no blade yet: the frame changes nothing and files no cutting time
  EXPECT_FALSE(region.begin_frame(mesh));
  region.end_frame(1.0);
  EXPECT_TRUE(stats.cutting_ms.empty());
  EXPECT_TRUE(stats.after_cut_ms.empty());

  // a blade drawn clean through the object halfway between two node planes above the floor
  double z_plane = floor, above = 1e9;
  for (const Vec3& r : lat.rest_m)
    if (r.z() > floor + 1e-9) above = std::min(above, r.z());
  z_plane = floor + 0.5 * (above - floor) + (above - floor);  // between the 2nd and 3rd node planes
  std::size_t nodes_above = 0;
  for (const Vec3& r : lat.rest_m) nodes_above += r.z() > z_plane ? 1 : 0;
  ASSERT_GT(nodes_above, 0u);
  const std::size_t tris0 = region.triangles().size(), verts0 = vertices.size();
  region.update_normals(false, mesh);  // all of them, the first time
  ASSERT_EQ(normals.size(), verts0);
  draw_blade(&region, z_plane);
  EXPECT_TRUE(region.begin_frame(mesh));
  region.end_frame(2.0);
  // springs removed, nodes kept: everything above the plane is a piece cut free of the fixed floor
  EXPECT_EQ(stats.frames_cutting, 1);
  EXPECT_GT(stats.springs_cut, 0);
  EXPECT_EQ(lat.springs.size(), springs0 - static_cast<std::size_t>(stats.springs_cut));
  EXPECT_EQ(lat.num_nodes(), nodes0);
  EXPECT_EQ(stats.free_nodes, static_cast<int64_t>(nodes_above));
  for (const auto& s : lat.springs)
    EXPECT_EQ(lat.rest_m[s.a].z() > z_plane, lat.rest_m[s.b].z() > z_plane) << s.a << "-" << s.b;
  // the mesh split along the cut: more triangles and vertices; the normals around the split are recomputed, the
  // others kept, and all of them are a full pass's
  EXPECT_GT(region.triangles().size(), tris0);
  EXPECT_EQ(static_cast<int64_t>(region.triangles().size() - tris0), stats.triangles_added);
  EXPECT_EQ(static_cast<int64_t>(vertices.size() - verts0), stats.vertices_added);
  EXPECT_GT(stats.vertices_added, 0);
  region.update_normals(false, mesh);
  std::vector<Vec3> full;
  compute_vertex_normals(vertices, region.triangles(), &full);
  EXPECT_TRUE(normals == full);
  EXPECT_EQ(stats.cutting_ms, std::vector<double>{2.0});
  // the next frame cuts nothing and is filed after the cut
  EXPECT_FALSE(region.begin_frame(mesh));
  region.end_frame(3.0);
  EXPECT_EQ(stats.after_cut_ms, std::vector<double>{3.0});
  EXPECT_EQ(stats.frames_cutting, 1);
  ASSERT_EQ(stats.cut_normals.size(), 2u);  // filed with the frame they were recomputed in
  EXPECT_GE(stats.cut_normals.back(), static_cast<double>(stats.vertices_added));
  EXPECT_LT(stats.cut_normals.back(), static_cast<double>(vertices.size()));

  // the piece cut free is the lattice stepped: its nodes, none fixed; moved below the floor by a step, it is
  // written into the whole lattice and held on the floor, no further
  Lattice* piece = region.stepped_lattice();
  ASSERT_NE(piece, nullptr);
  EXPECT_EQ(piece->num_nodes(), nodes_above);
  for (std::size_t i = 0; i < piece->num_nodes(); ++i) {
    EXPECT_GT(piece->rest_m[i].z(), z_plane);
    EXPECT_EQ(piece->fixed[i], 0);
    piece->x_m[i].z() = floor - 0.01;
  }
  region.after_step();
  std::size_t held = 0;
  for (std::size_t i = 0; i < nodes0; ++i)
    if (lat.rest_m[i].z() > z_plane) held += lat.x_m[i].z() == floor ? 1 : 0;
  EXPECT_EQ(held, nodes_above);
  for (std::size_t i = 0; i < piece->num_nodes(); ++i) EXPECT_EQ(piece->x_m[i].z(), floor);
  // the body below the cut never moved
  for (std::size_t i = 0; i < nodes0; ++i) {
    if (lat.rest_m[i].z() < z_plane) {
      EXPECT_EQ(lat.x_m[i], lat.rest_m[i]) << i;
    }
  }
}

TEST(RegionPolicy, ChosenFromTheSceneModeAndSeenThroughTheFrameStage) {
  for (const char* mode : {"touch", "pull", "cut"}) {
    SCOPED_TRACE(mode);
    const Scene scene = box_scene(mode, 2);
    const Model model = load_model(scene).value();
    const bool cut = scene.mode == InteractionMode::kCut;
    FrameStats stats;
    const auto policy = make_region_policy(scene, model, &stats);
    EXPECT_EQ(dynamic_cast<const CutRegion*>(policy.get()) != nullptr, cut);
    EXPECT_EQ(dynamic_cast<const LocalRegion*>(policy.get()) != nullptr, !cut);
    // the stage shows its policy's lattice, mesh and cut model: the whole object up front in cut mode only
    SpscQueue<HapticSample> samples(16);
    TripleBuffer<LocalModel> local;
    FrameStage stage(scene, model, &samples, &local, nullptr, nullptr, nullptr);
    EXPECT_EQ(stage.lattice().has_value(), cut);
    EXPECT_EQ(stage.cut_model() != nullptr, cut);
    if (cut) {
      EXPECT_EQ(&stage.triangles(), &stage.cut_model()->triangles());
      EXPECT_EQ(static_cast<int64_t>(stage.lattice()->cells.size()), model.grid.solid_cells(4));
    } else {
      EXPECT_EQ(&stage.triangles(), &model.rest.triangles);
    }
  }
}

}  // namespace
}  // namespace palpate
