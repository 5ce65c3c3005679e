// An open surface (a cup: a box without its top, read from a file) has no inside and two sides: a tool pressed onto its
// bottom from inside the cup touches it, is held on that side, is pushed back up, and comes out as it went in. Before,
// the servo met a face only from its front: a point or sphere went through the bottom from inside, and on the way back
// the bottom's front held it outside the cup, pulling the hand away at the device's 3.3 N (a cup, a mask, a scan with
// holes touched from behind).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/scene.h"
#include "runtime/session/device_factory.h"
#include "runtime/session/model.h"
#include "runtime/session/session.h"

namespace palpate {
namespace {

// the cup: five faces of a unit box, 8 x 8 quads each, wound outward (their backs face the cup's inside)
std::string cup_obj() {
  std::string text;
  int base = 1;
  const auto face = [&](Vec3 o, Vec3 u, Vec3 v) {
    const int n = 8;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        const Vec3 p = o + (i / double(n)) * u + (j / double(n)) * v;
        char line[96];
        std::snprintf(line, sizeof line, "v %.6f %.6f %.6f\n", p.x(), p.y(), p.z());
        text += line;
      }
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int a = base + j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
        text += "f " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "\n";
        text += "f " + std::to_string(a) + " " + std::to_string(c) + " " + std::to_string(d) + "\n";
      }
    base += (n + 1) * (n + 1);
  };
  const double h = 0.5;
  face(Vec3(-h, -h, -h), Vec3(0, 1, 0), Vec3(1, 0, 0));  // bottom, facing -z
  face(Vec3(-h, -h, -h), Vec3(1, 0, 0), Vec3(0, 0, 1));  // y = -h, facing -y
  face(Vec3(-h, h, -h), Vec3(0, 0, 1), Vec3(1, 0, 0));   // y = +h, facing +y
  face(Vec3(-h, -h, -h), Vec3(0, 0, 1), Vec3(0, 1, 0));  // x = -h, facing -x
  face(Vec3(h, -h, -h), Vec3(0, 1, 0), Vec3(0, 0, 1));   // x = +h, facing +x
  return text;
}

TEST(OpenSurface, ACupPressedFromInsideHoldsTheToolInsideAndPushesItBack) {
  const auto path = std::filesystem::path(testing::TempDir()) / "cup.obj";
  std::ofstream(path) << cup_obj();
  for (const char* shape : {"point", "sphere"}) {
    SCOPED_TRACE(shape);
    // the cup 100 mm wide, its bottom at z = -0.05; the hand lowered from its middle to 6 mm under the bottom, held,
    // then lifted back to the middle
    char text[2048];
    std::snprintf(text, sizeof text, R"({
      "mesh": {"file": "%s", "size_m": 0.1, "up_axis": "z", "subdivisions": 0},
      "grid": {"levels": 5},
      "lattice": {"level": 5, "radius_cells": 3, "integrator": "implicit_euler", "gravity_m_per_s2": [0, 0, 0]},
      "material": {"young_modulus_Pa": 3e5, "poisson_ratio": 0.45, "density_kg_per_m3": 1050, "model": "volumetric"},
      "device": {"max_force_N": 3.3, "coupling_N_per_m": 300, "tool_shape": "%s", "tool_radius_m": 0.002},
      "interaction": {"mode": "touch"},
      "trajectory": [{"t_s": 0.0, "pos_m": [0.003, 0.004, 0.0]}, {"t_s": 0.3, "pos_m": [0.003, 0.004, 0.0]},
                     {"t_s": 1.3, "pos_m": [0.003, 0.004, -0.056]}, {"t_s": 2.0, "pos_m": [0.003, 0.004, -0.056]},
                     {"t_s": 2.6, "pos_m": [0.003, 0.004, 0.0]}],
      "duration_s": 2.6
    })",
                  path.string().c_str(), shape);
    const Scene scene = parse_scene(text, "cup.json").value();
    const Model model = load_model(scene).value();
    ASSERT_FALSE(model.closed);
    auto device = make_device(scene, "").value();
    Session session(scene, model, device.get());
    const double r = std::string(shape) == "sphere" ? 0.002 : 0.0;
    int touching = 0;
    double lowest_god = 1.0, largest_up = 0.0, least_up = 1e9;
    session.run_lockstep(
        scene.duration_s, [](int64_t, double) {},
        [&](int64_t, double t) {
          const HapticSample& s = session.servo().last_sample();
          if (s.contact != ContactState::kTouch) return;
          ++touching;
          lowest_god = std::min(lowest_god, s.god_pos_m.z());
          // held against the bottom while the hand is pressed under it: pushed back up, never down
          if (t > 1.4 && t < 2.0) {
            largest_up = std::max(largest_up, s.force_N.z());
            least_up = std::min(least_up, s.force_N.z());
          }
        });
    EXPECT_GT(touching, 500);
    // the god-object stays on the inside: above the bottom, less what the soft bottom gives
    EXPECT_GT(lowest_god, -0.05 + r - 0.002);
    EXPECT_GT(least_up, 0.3);
    EXPECT_LT(largest_up, 3.3 + 1e-9);
    // and the tool, lifted back to the middle, is free again, with nothing counted through the cup
    EXPECT_EQ(session.servo().last_sample().contact, ContactState::kFree);
    EXPECT_EQ(session.stage().stats().tool_inside_ticks + session.stage().stats().proxy_inside_ticks, 0);
  }
}

}  // namespace
}  // namespace palpate
