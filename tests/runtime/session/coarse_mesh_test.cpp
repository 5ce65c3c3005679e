// A mesh file coarser than the lattice's cells is subdivided on load (mesh.subdivisions "auto", the default) in
// touch and pull, so its surface can dent under the tool: a surface moves only at its triangles' corners.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/mesh_io.h"
#include "core/scene.h"
#include "runtime/session/model.h"
#include "support/fixtures.h"
#include "support/json_file.h"
#include "support/obj_text.h"
#include "tools/bench/bench_feel.h"

namespace palpate {
namespace {

// a 100 mm box of 12 triangles (a CAD export's), written as OBJ
std::string write_coarse_box(const std::string& dir) {
  const TriMesh box = make_box_mesh(Vec3::Constant(0.1), 1);
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/coarse_box.obj";
  test::write_text(path, test::obj_text(box));
  return path;
}

Scene scene_of(const std::string& mesh, const std::string& mode, const std::string& subdivisions) {
  const std::string text = R"({ "mesh": { "file": ")" + mesh + R"(", "size_m": 0.1)" +
                           (subdivisions.empty() ? "" : ", \"subdivisions\": " + subdivisions) + R"( },
    "grid": { "levels": 5 }, "lattice": { "level": 5, "fix_floor": true, "gravity_m_per_s2": [0, 0, 0] },
    "interaction": { "mode": ")" + mode + R"(" },
    "trajectory": [ { "t_s": 0.0, "pos_m": [0, 0, 0.07] } ], "duration_s": 0.1 })";
  auto s = parse_scene(text, "coarse.json");
  EXPECT_TRUE(s) << s.error().message;
  return s.value();
}

TEST(CoarseMesh, AFileCoarserThanTheLatticeIsSubdividedUntilItsTrianglesAreWithinTwoCells) {
  const std::string mesh = write_coarse_box(test::temp_path("coarse_mesh_", "box"));
  const Model plain = load_model(scene_of(mesh, "touch", "0")).value();
  ASSERT_EQ(plain.rest.triangles.size(), 12u);
  EXPECT_EQ(plain.auto_subdivisions, 0);
  const double cell_m = plain.grid.cell_size_m(5);
  EXPECT_GT(median_longest_edge_m(plain.rest), 20 * cell_m);  // the 141 mm diagonals against 6.25 mm cells

  // by default (touch and pull): halved until the median longest edge is within two cells, four times here
  for (const char* mode : {"touch", "pull"}) {
    const Model fine = load_model(scene_of(mesh, mode, "")).value();
    EXPECT_EQ(fine.auto_subdivisions, 4) << mode;
    EXPECT_EQ(fine.rest.triangles.size(), 12u << 8) << mode;
    EXPECT_LE(median_longest_edge_m(fine.rest), kCoarseMeshEdgeCells * cell_m) << mode;
    EXPECT_GT(median_longest_edge_m(fine.rest), 0.5 * kCoarseMeshEdgeCells * cell_m) << mode;  // no more than needed
    EXPECT_NEAR(fine.coarse_edge_m, median_longest_edge_m(plain.rest), 1e-12);
    // the same surface: every vertex on the box's faces
    for (const Vec3& v : fine.rest.vertices_m) EXPECT_NEAR(v.cwiseAbs().maxCoeff(), 0.05, 1e-9);
  }
  // "auto" spelled out is the default; a number is kept as given; cut mode's whole-object lattice is left alone
  EXPECT_EQ(load_model(scene_of(mesh, "touch", "\"auto\"")).value().auto_subdivisions, 4);
  EXPECT_EQ(load_model(scene_of(mesh, "touch", "2")).value().rest.triangles.size(), 192u);
  EXPECT_EQ(load_model(scene_of(mesh, "cut", "")).value().rest.triangles.size(), 12u);
  // a mesh finer than its lattice is not touched
  const Model bunny = load_model(load_scene(test::source_path("scenes/bunny_touch.json")).value()).value();
  EXPECT_EQ(bunny.auto_subdivisions, 0);
}

TEST(CoarseMesh, TheBudgetStopsItShortOfAMillionTriangles) {
  EXPECT_EQ(auto_subdivisions(0.1, 0.001, 12), 5);            // five at most
  EXPECT_EQ(auto_subdivisions(0.1, 0.001, 100000), 1);        // 400k after one, 1.6M after two
  EXPECT_EQ(auto_subdivisions(0.1, 0.001, 300000), 0);        // 1.2M after one
  EXPECT_EQ(auto_subdivisions(0.004, 0.001, 12), 1);          // 4 mm to 2 mm: within two 1 mm cells
  EXPECT_EQ(auto_subdivisions(0.002, 0.001, 12), 0);
}

// assimp's box.3mf (12 triangles, 105 mm edges), a 1.7 mm sphere on E 50 kPa pushed past the force limit and
// stroked over the top edge (bench feel --hands 50 --seed 11's hand 58): on the file's 12 triangles the surface could
// not dent, the god-object was held on a corner-moved facet and 2.5 % of the contact ticks stepped beyond the hand's
// motion (0.093 N at most) with 5.9 mJ into the hand; subdivided on load it is felt smoothly and passively.
TEST(CoarseMesh, APushPastTheForceLimitOnACoarseCadBoxIsFeltSmoothly) {
  const std::string box = "/usr/share/assimp/models/3MF/box.3mf";
  if (!std::filesystem::exists(box)) GTEST_SKIP() << box << " missing (Debian's assimp-testmodels)";
  const std::string text = R"({ "mesh": { "file": ")" + box + R"(", "size_m": 0.1, "up_axis": "z" },
    "grid": { "levels": 5 },
    "lattice": { "level": 5, "radius_cells": 3, "gravity_m_per_s2": [0, 0, 0], "fix_floor": true,
                 "integrator": "implicit_euler" },
    "material": { "young_modulus_Pa": 50000, "poisson_ratio": 0.45, "density_kg_per_m3": 1050,
                  "stiffness_damping_s": 0.005, "model": "volumetric" },
    "device": { "driver": "scripted", "max_force_N": 3.3, "coupling_N_per_m": 300, "coupling_damping_Ns_per_m": 0.5,
                "tool_radius_m": 0.00171, "workspace_half_m": 0.2, "tool_shape": "sphere" },
    "hand": { "mass_kg": 0.12, "stiffness_N_per_m": 150, "damping_Ns_per_m": 6 },
    "interaction": { "mode": "touch" },
    "trajectory": [
      {"t_s": 0.0, "pos_m": [-0.0266667, 0.0120113, 0.006894]}, {"t_s": 0.3, "pos_m": [-0.0266667, 0.0120113, 0.006894]},
      {"t_s": 0.44, "pos_m": [-0.0196667, 0.0120113, 0.006894]}, {"t_s": 0.801729, "pos_m": [0.0090384, 0.0120113, 0.006894]},
      {"t_s": 1.166972, "pos_m": [0.0090384, 0.0120113, 0.006894]}, {"t_s": 1.811195, "pos_m": [0.0105423, 0.026135, 0.0285207]},
      {"t_s": 1.912864, "pos_m": [0.0105423, 0.026135, 0.0285207]}, {"t_s": 2.228946, "pos_m": [0.0131929, 0.0190482, 0.0146804]},
      {"t_s": 2.540534, "pos_m": [0.0131929, 0.026135, 0.0285207]}, {"t_s": 2.655633, "pos_m": [0.0131929, 0.026135, 0.0285207]},
      {"t_s": 5.189763, "pos_m": [0.010636, 0.0328587, 0.0423992]}, {"t_s": 5.250562, "pos_m": [0.010636, 0.0328587, 0.0423992]},
      {"t_s": 5.760516, "pos_m": [-0.0266667, 0.0328587, 0.0423992]}, {"t_s": 5.960516, "pos_m": [-0.0266667, 0.0328587, 0.0423992]}],
    "duration_s": 6.061 })";

  auto scene = parse_scene(text, "hand_58.json");
  ASSERT_TRUE(scene) << scene.error().message;
  const Model model = load_model(scene.value()).value();
  EXPECT_GT(model.auto_subdivisions, 0);
  BenchFeelOptions o;
  auto run = run_feel(scene.value(), model, o);
  ASSERT_TRUE(run) << run.error().message;
  const FeelFigures& f = run.value().figures;
  ASSERT_GT(f.contact_ticks, 4000);
  EXPECT_EQ(f.wild_steps, 0);
  EXPECT_LE(f.excess_ticks, f.contact_ticks / 100);
  EXPECT_LE(f.energy_into_hand_J, 0.0);
  std::printf("[ figures ] contact %lld, excess ticks %lld, largest step %.4f N, energy %.2f mJ\n",
              static_cast<long long>(f.contact_ticks), static_cast<long long>(f.excess_ticks), f.max_step_N,
              1e3 * f.energy_into_hand_J);
}

}  // namespace
}  // namespace palpate
