// Friction measured in the contact's own frame, through the whole pipeline (lattice, dent, patch, servo): a 5 mm
// sphere pressed into a block to about 1.65 N and stroked across it at constant depth. The force is split along the
// dented surface's normal where the sphere touches it (the deformed mesh's vertex normals, interpolated), and along
// the world's vertical (the block's rest normal). On a stiff block (10 MPa) friction breaks away at mu_s and slides at
// mu_d within 5 %, and frictionless has nothing across. On a soft one (300 kPa) it does not hold yet: the run prints
// its figures (docs/feel.md, "Friction on a soft surface").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/scene.h"
#include "sim/contact/contact_load.h"
#include "runtime/session/device_factory.h"
#include "runtime/session/model.h"
#include "runtime/session/session.h"

namespace palpate {
namespace {

struct FrictionRun {
  double breakaway = 0.0;       // largest |F_t| / F_n in the contact's frame before the first slip
  double sliding = 0.0;         // mean |F_t| / F_n in the contact's frame over the stroke's last 2 s
  double breakaway_world = 0.0; // the same with the world's vertical as the normal
  double sliding_world = 0.0;
  double normal_N = 0.0;        // mean F_n over the stroke's last 2 s
  int released = 0;             // stroke ticks out of contact
};

// A 6 cm block of `young_Pa` (nu 0.45) on a fixed floor, its top at z = 0.03 m, a 5 mm sphere. The scripted hand
// (it yields, as a hand does) is taken to z_m, held, then stroked 40 mm along x in 4 s.
FrictionRun stroke(double young_Pa, double mu_s, double mu_d, double z_m) {
  char text[2048];
  std::snprintf(text, sizeof text, R"({
    "mesh": {"box_m": [0.06, 0.06, 0.06], "box_subdivisions": 24, "size_m": 0.06},
    "grid": {"levels": 5},
    "lattice": {"level": 5, "radius_cells": 3, "fix_floor": true, "integrator": "implicit_euler",
                "gravity_m_per_s2": [0, 0, 0]},
    "material": {"young_modulus_Pa": %g, "poisson_ratio": 0.45, "density_kg_per_m3": 1070,
                 "stiffness_damping_s": 2e-3, "static_friction": %g, "dynamic_friction": %g},
    "device": {"max_force_N": 3.3, "coupling_N_per_m": 300, "coupling_damping_Ns_per_m": 0.5,
               "tool_shape": "sphere", "tool_radius_m": 0.005, "workspace_half_m": 0.2},
    "interaction": {"mode": "touch"},
    "trajectory": [{"t_s": 0.0, "pos_m": [-0.02, 0.0, 0.045]}, {"t_s": 0.6, "pos_m": [-0.02, 0.0, %g]},
                   {"t_s": 1.2, "pos_m": [-0.02, 0.0, %g]}, {"t_s": 5.2, "pos_m": [0.02, 0.0, %g]}],
    "duration_s": 5.2
  })",
                young_Pa, mu_s, mu_d, z_m, z_m, z_m);
  const Scene scene = parse_scene(text, "soft_friction.json").value();
  const Model model = load_model(scene).value();
  auto device = make_device(scene, "").value();
  Session session(scene, model, device.get());
  FrictionRun r;
  double sum = 0.0, sum_world = 0.0, sum_n = 0.0, last_x = 0.0;
  int slid = 0;
  bool slipped = false;
  session.run_lockstep(
      scene.duration_s, [](int64_t, double) {},
      [&](int64_t, double t) {
        if (t < 1.2) return;
        const HapticSample& s = session.servo().last_sample();
        if (s.contact != ContactState::kTouch || s.contact_tri < 0) {
          ++r.released;
          return;
        }
        // the dented surface's normal where the sphere touches it, as the last frame left it
        const auto& tri = model.rest.triangles[static_cast<std::size_t>(s.contact_tri)];
        const auto& nv = session.stage().normals();
        const Vec3 n = (s.contact_bary[0] * nv[static_cast<std::size_t>(tri[0])] +
                        s.contact_bary[1] * nv[static_cast<std::size_t>(tri[1])] +
                        s.contact_bary[2] * nv[static_cast<std::size_t>(tri[2])])
                           .normalized();
        const double fn = s.force_N.dot(n);
        const double ratio = (s.force_N - fn * n).norm() / fn;
        const double world = std::hypot(s.force_N.x(), s.force_N.y()) / s.force_N.z();
        // the held sphere first moves along the stroke: it slipped
        slipped = slipped || (t > 1.25 && s.god_pos_m.x() > last_x + 1e-6);
        last_x = s.god_pos_m.x();
        if (!slipped) {
          r.breakaway = std::max(r.breakaway, ratio);
          r.breakaway_world = std::max(r.breakaway_world, world);
        }
        if (t >= 3.2) {
          sum += ratio;
          sum_world += world;
          sum_n += fn;
          ++slid;
        }
      });
  r.sliding = sum / std::max(slid, 1);
  r.sliding_world = sum_world / std::max(slid, 1);
  r.normal_N = sum_n / std::max(slid, 1);
  return r;
}

TEST(SoftFriction, OnAStiffBlockMuHoldsInTheContactsFrameOnASoftOneItIsMeasured) {
  // the hand's target gives about 1.65 N on each (the scripted hand yields, 150 N/m)
  for (const auto& [young, z] : {std::pair{1e7, 0.01845}, {3e5, 0.0177}}) {
    const FrictionRun free = stroke(young, 0.0, 0.0, z);
    const FrictionRun rough = stroke(young, 0.6, 0.4, z);
    std::printf("[ figures ] E %.0f kPa, F_n %.2f N; contact frame (world frame): frictionless sliding %.3f (%.3f); "
                "mu_s 0.6 breakaway %.3f (%.3f); mu_d 0.4 sliding %.3f (%.3f)\n",
                young / 1e3, rough.normal_N, free.sliding, free.sliding_world, rough.breakaway, rough.breakaway_world,
                rough.sliding, rough.sliding_world);
    EXPECT_EQ(free.released, 0);
    EXPECT_EQ(rough.released, 0);
    EXPECT_NEAR(rough.normal_N, 1.65, 0.1);
    if (young < 1e6) continue;  // soft: measured, not yet held (docs/feel.md)
    EXPECT_LE(free.sliding, 0.05);
    EXPECT_NEAR(rough.breakaway, 0.6, 0.6 * 0.05);
    EXPECT_NEAR(rough.sliding, 0.4, 0.4 * 0.05);
  }
}

}  // namespace
}  // namespace palpate
