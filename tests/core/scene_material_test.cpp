// The scene's "material" object: parsed strictly, exclusive with the raw spring/mass/damping keys.

#include <gtest/gtest.h>

#include "core/scene.h"

namespace palpate {
namespace {

std::string scene_with(const std::string& extra) {
  return R"({"mesh": {"box_m": [0.05, 0.05, 0.05]}, "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0.05]}])" + extra + "}";
}

std::string error_of(const std::string& json) {
  auto r = parse_scene(json, "m.json");
  return r ? std::string("(no error)") : r.error().message;
}

TEST(SceneMaterial, PhysicalUnitsAreRead) {
  auto r = parse_scene(scene_with(R"(, "material": {"young_modulus_Pa": 1.2e5, "poisson_ratio": 0.45,
      "density_kg_per_m3": 1070, "stiffness_damping_s": 0.002})"), "m.json");
  ASSERT_TRUE(r) << r.error().message;
  const MaterialSpec& m = r.value().lattice.material;
  EXPECT_TRUE(m.enabled);
  EXPECT_EQ(m.young_modulus_Pa, 1.2e5);
  EXPECT_EQ(m.poisson_ratio, 0.45);
  EXPECT_EQ(m.density_kg_per_m3, 1070.0);
  EXPECT_EQ(m.stiffness_damping_s, 0.002);
}

TEST(SceneMaterial, AbsentMeansRawKeys) {
  auto r = parse_scene(scene_with(""), "m.json");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_FALSE(r.value().lattice.material.enabled);
}

TEST(SceneMaterial, BothMaterialAndRawKeysIsAnErrorNamingThem) {
  const std::string e = error_of(scene_with(R"(, "lattice": {"node_mass_kg": 0.003, "damping_Ns_per_m": 0.1},
      "material": {"young_modulus_Pa": 1e5, "poisson_ratio": 0.25, "density_kg_per_m3": 1000})"));
  EXPECT_NE(e.find("scene 'm.json': material: is exclusive with lattice.node_mass_kg, lattice.damping_Ns_per_m"),
            std::string::npos) << e;
  const std::string k = error_of(scene_with(R"(, "lattice": {"stiffness_N_per_m": {"shear": 3}},
      "material": {"young_modulus_Pa": 1e5, "poisson_ratio": 0.25, "density_kg_per_m3": 1000})"));
  EXPECT_NE(k.find("material: is exclusive with lattice.stiffness_N_per_m"), std::string::npos) << k;
}

TEST(SceneMaterial, MissingUnknownAndOutOfRangeNameKeyAndValue) {
  EXPECT_NE(error_of(scene_with(R"(, "material": {"young_modulus_Pa": 1e5, "poisson_ratio": 0.25})"))
                .find("material.density_kg_per_m3: is required"), std::string::npos);
  EXPECT_NE(error_of(scene_with(R"(, "material": {"young_modulus_Pa": 1e5, "poisson_ratio": 0.25,
      "density_kg_per_m3": 1000, "shear_modulus_Pa": 4e4})")).find("material.shear_modulus_Pa: unknown key"),
            std::string::npos);
  EXPECT_NE(error_of(scene_with(R"(, "material": {"young_modulus_Pa": 1e5, "poisson_ratio": 0.5,
      "density_kg_per_m3": 1000})")).find("material.poisson_ratio: 0.5 out of range [-0.999, 0.4999]"),
            std::string::npos);
  EXPECT_NE(error_of(scene_with(R"(, "material": {"young_modulus_Pa": -3, "poisson_ratio": 0.25,
      "density_kg_per_m3": 1000})")).find("material.young_modulus_Pa: -3 out of range"), std::string::npos);
  EXPECT_NE(error_of(scene_with(R"(, "material": 5)")).find("material: must be an object"), std::string::npos);
}

// material.model: springs by default (nu 1/4 represented, the scenes' behaviour unchanged), "volumetric" for the
// asked nu in [0, 0.49]; the integrator and mode that cannot carry the volume term are refused at load, by key.
TEST(SceneMaterial, ModelKeyRangeAndTheIntegratorsThatCannotCarryIt) {
  auto d = parse_scene(scene_with(R"(, "material": {"young_modulus_Pa": 1e5, "poisson_ratio": 0.45, "density_kg_per_m3": 1000})"), "m.json");
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(d.value().lattice.material.model, MaterialModel::kSprings);
  auto v = parse_scene(scene_with(R"(, "lattice": {"integrator": "implicit_euler"}, "material": {"young_modulus_Pa": 1e5,
      "poisson_ratio": 0.49, "density_kg_per_m3": 1000, "model": "volumetric"})"), "m.json");
  ASSERT_TRUE(v) << v.error().message;
  EXPECT_EQ(v.value().lattice.material.model, MaterialModel::kVolumetric);
  EXPECT_NE(error_of(scene_with(R"(, "material": {"young_modulus_Pa": 1e5, "poisson_ratio": 0.25,
      "density_kg_per_m3": 1000, "model": "foam"})")).find("material.model: 'foam' is not one of: springs, volumetric"),
            std::string::npos);
  EXPECT_NE(error_of(scene_with(R"(, "lattice": {"integrator": "implicit_euler"}, "material": {"young_modulus_Pa": 1e5,
      "poisson_ratio": 0.495, "density_kg_per_m3": 1000, "model": "volumetric"})"))
                .find("material.poisson_ratio: 0.495"), std::string::npos);
  EXPECT_NE(error_of(scene_with(R"(, "lattice": {"integrator": "local_global"}, "material": {"young_modulus_Pa": 1e5,
      "poisson_ratio": 0.45, "density_kg_per_m3": 1000, "model": "volumetric"})"))
                .find("material.model: 'volumetric' is not supported by lattice.integrator 'local_global'"),
            std::string::npos);
  EXPECT_NE(error_of(scene_with(R"(, "lattice": {"integrator": "implicit_euler"}, "interaction": {"mode": "cut"},
      "material": {"young_modulus_Pa": 1e5, "poisson_ratio": 0.45, "density_kg_per_m3": 1000, "model": "volumetric"})"))
                .find("not supported with interaction.mode 'cut'"), std::string::npos);
}

}  // namespace
}  // namespace palpate
