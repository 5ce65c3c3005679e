// The lattice inside a lockstep recording: the region follows a sliding contact, a resting lattice is skipped,
// and the summary reports what was simulated.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "support/temp_root.h"
#include "core/scene.h"
#include "runtime/record/recorder.h"

namespace palpate {
namespace {

// A 6 cm box pressed on top and dragged 4 cm across it, then left alone for a second.
constexpr const char* kSlide = R"({
  "mesh": {"box_m": [0.06, 0.06, 0.06], "box_subdivisions": 12, "size_m": 0.06},
  "grid": {"levels": 4},
  "lattice": {"level": 4, "radius_cells": 1, "node_mass_kg": 0.003,
              "stiffness_N_per_m": {"structural": 60, "shear": 30, "bend": 15},
              "damping_Ns_per_m": 0.06, "fix_floor": true, "integrator": "INTEGRATOR"},
  "interaction": {"mode": "touch"},
  "trajectory": [{"t_s": 0.0, "pos_m": [-0.02, 0.0, 0.04]},
                 {"t_s": 0.3, "pos_m": [-0.02, 0.0, 0.026]},
                 {"t_s": 1.3, "pos_m": [0.02, 0.0, 0.026]},
                 {"t_s": 1.5, "pos_m": [0.02, 0.0, 0.05]}],
  "duration_s": 2.5
})";

nlohmann::json record(const std::string& integrator) {
  std::string text = kSlide;
  text.replace(text.find("INTEGRATOR"), 10, integrator);
  Scene scene = parse_scene(text, "slide.json").value();
  RecordOptions opt;
  opt.out_dir = (std::filesystem::path(test::temp_root()) / ("palpate_slide_" + integrator)).string();
  opt.quiet = true;
  opt.render = false;
  auto r = record_scene(scene, opt);
  EXPECT_TRUE(r) << r.error().message;
  std::ifstream f(r.value().summary_path);
  return nlohmann::json::parse(f);
}

TEST(SessionLattice, RegionFollowsASlidingContactAndRestingFramesAreSkipped) {
  for (const char* integ : {"symplectic_euler", "implicit_euler", "local_global"}) {
    const auto j = record(integ);
    const auto& sim = j["sim"];
    EXPECT_EQ(j["nan_events"].get<int>(), 0) << integ;
    EXPECT_EQ(sim["divergence_events"].get<int>(), 0) << integ;
    EXPECT_GT(j["max_displacement_m"].get<double>(), 1e-4) << integ;
    // 4 cm of travel over 7.5 mm cells with a radius of one cell: the region moves several times
    EXPECT_GE(sim["region_moves"].get<int>(), 2) << integ;
    // after release the lattice settles and stops being stepped
    EXPECT_GT(sim["frames_resting"].get<int>(), 0) << integ;
    EXPECT_EQ(sim["frames_stepped"].get<int>() + sim["frames_resting"].get<int>() <= 150, true) << integ;
    // what was simulated per frame, on average, is less than the largest region (idle and resting frames cost 0)
    EXPECT_GT(sim["per_frame_mean"]["nodes"].get<double>(), 0.0) << integ;
    EXPECT_LT(sim["per_frame_mean"]["nodes"].get<double>(), sim["nodes"].get<double>()) << integ;
  }
}

}  // namespace
}  // namespace palpate
