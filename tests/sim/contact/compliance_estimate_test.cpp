// The compliance the servo's contact model takes before the region's factor is done: from the loaded nodes'
// stiffness alone, never below what the factor gives (a servo that takes the surface as stiffer than it is
// overshoots past it every frame), and not so far above that it gives the servo a surface of a different kind.
#include "sim/contact/compliance_estimate.h"

#include <gtest/gtest.h>

#include <cstdio>

#include <Eigen/Eigenvalues>

#include "sim/contact/contact_load.h"
#include "sim/contact_block.h"

namespace palpate {
namespace {

constexpr double kTop_m = test::kContactBlockSide_m / 2;

LatticeSpec material_spec(MaterialModel model, double nu) {
  LatticeSpec s;
  s.material.enabled = true;
  s.material.young_modulus_Pa = 1e4;
  s.material.poisson_ratio = nu;
  s.material.model = model;
  s.material.density_kg_per_m3 = 1000.0;
  s.gravity_m_per_s2 = Vec3::Zero();
  return s;
}

int32_t node_at(const Lattice& lat, const Vec3& p) {
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if ((lat.rest_m[i] - p).norm() < 1e-9) return static_cast<int32_t>(i);
  return -1;
}

double largest(const Mat3& c) { return Eigen::SelfAdjointEigenSolver<Mat3>(c).eigenvalues().maxCoeff(); }

TEST(ComplianceEstimate, IsAboveTheFactoredComplianceAndWithinAFewTimesIt) {
  struct Case {
    const char* name;
    MaterialModel model;
    double nu;
  };
  const Case materials[] = {{"springs", MaterialModel::kSprings, 0.25},
                            {"volumetric 0.45", MaterialModel::kVolumetric, 0.45},
                            {"neo_hookean 0.45", MaterialModel::kNeoHookean, 0.45}};
  double lowest = 1e9, highest = 0.0;
  for (const Case& m : materials)
    for (int level : {3, 4, 5}) {
      const test::ContactBlock b(level, 8, material_spec(m.model, m.nu));
      ContactCompliance cc;
      std::vector<double> scratch;
      // one node: the top face's middle, an edge's, a corner; and a point inside a top triangle (24 nodes)
      std::vector<std::pair<const char*, PointWeights>> loads;
      for (const auto& [where, p] : {std::pair{"face", Vec3(0, 0, kTop_m)}, std::pair{"edge", Vec3(kTop_m, 0, kTop_m)},
                                     std::pair{"corner", Vec3(kTop_m, kTop_m, kTop_m)}}) {
        PointWeights w;
        ASSERT_TRUE(w.add(node_at(b.lat, p), 1.0)) << where;
        ASSERT_GE(w.node[0], 0) << where;
        loads.emplace_back(where, w);
      }
      loads.emplace_back("in a triangle", point_weights(b.lat, b.rest, b.top_triangle(0.006, -0.013), Vec3(0.2, 0.3, 0.5)));
      for (const auto& [where, w] : loads) {
        Mat3 c;
        ASSERT_TRUE(cc.compute(b.lat, w, false, &c));
        const double ratio = largest(estimate_compliance(b.lat, w, &scratch)) / largest(c);
        std::printf("%-17s level %d %-14s estimate / factored %.2f\n", m.name, level, where, ratio);
        lowest = std::min(lowest, ratio);
        highest = std::max(highest, ratio);
      }
    }
  EXPECT_GE(lowest, 1.0);
  EXPECT_LE(highest, 5.0);
}

}  // namespace
}  // namespace palpate
