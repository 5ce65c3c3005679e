// The model error a scene's contact carries, read off the Hertz calibration of `palpate bench model`.

#include <gtest/gtest.h>

#include <cmath>

#include "sim/contact/contact_model_error.h"

namespace palpate {
namespace {

MaterialSpec material(MaterialModel model, double nu) {
  MaterialSpec m;
  m.enabled = true;
  m.model = model;
  m.poisson_ratio = nu;
  return m;
}

TEST(ContactModelError, PointToolHasNoHertzFigure) {
  const ContactModelError e = contact_model_error(material(MaterialModel::kSprings, 0.25), false, 0.002, 0.004);
  EXPECT_FALSE(e.defined);
  EXPECT_NE(e.basis.find("point load"), std::string::npos) << e.basis;
}

// At the calibrated contact radii the table's figures come back; between them, linear in log2(radius / cell).
TEST(ContactModelError, SphereToolReadsTheCalibrationAtItsRadiusInCells) {
  const MaterialSpec springs = material(MaterialModel::kSprings, 0.45);  // springs: nu 1/4 whatever is asked
  const ContactModelError one = contact_model_error(springs, true, 0.005, 0.005);
  ASSERT_TRUE(one.defined);
  EXPECT_DOUBLE_EQ(one.contact_radius_cells, 1.0);
  EXPECT_DOUBLE_EQ(one.hertz_force_error, 0.10);
  EXPECT_TRUE(one.within_calibration);
  const ContactModelError two = contact_model_error(springs, true, 0.005, 0.0025);
  EXPECT_DOUBLE_EQ(two.hertz_force_error, 0.029);
  const ContactModelError mid = contact_model_error(springs, true, 0.005 * std::sqrt(2.0), 0.005);
  EXPECT_NEAR(mid.hertz_force_error, 0.5 * (0.10 + 0.029), 1e-12);
  EXPECT_NE(mid.basis.find("not measured in this run"), std::string::npos) << mid.basis;
  // finer than calibrated: the nearest figure, flagged
  const ContactModelError fine = contact_model_error(springs, true, 0.02, 0.0025);
  EXPECT_DOUBLE_EQ(fine.hertz_force_error, 0.029);
  EXPECT_FALSE(fine.within_calibration);
}

// Between two calibrated Poisson ratios the figure is interpolated linearly in nu.
TEST(ContactModelError, PoissonRatioBetweenRowsIsInterpolated) {
  const double at_04 = contact_model_error(material(MaterialModel::kVolumetric, 0.4), true, 0.005, 0.005).hertz_force_error;
  const double at_045 = contact_model_error(material(MaterialModel::kVolumetric, 0.45), true, 0.005, 0.005).hertz_force_error;
  const ContactModelError between = contact_model_error(material(MaterialModel::kVolumetric, 0.425), true, 0.005, 0.005);
  EXPECT_NEAR(between.hertz_force_error, 0.5 * (at_04 + at_045), 1e-12);
  EXPECT_TRUE(between.within_calibration);
  EXPECT_NE(at_04, at_045);
}

// With device.contact "solved" the figure comes from the solved calibration, and a point tool's tip, loaded as a
// sphere of its radius, has one too.
TEST(ContactModelError, TheSolvedContactReadsItsOwnCalibrationAndTakesAPointsTipAsASphere) {
  const MaterialSpec tissue = material(MaterialModel::kVolumetric, 0.45);
  const ContactModelError prescribed = contact_model_error(tissue, true, 0.005, 0.0025);
  const ContactModelError solved = contact_model_error(tissue, true, 0.005, 0.0025, true);
  ASSERT_TRUE(solved.defined);
  EXPECT_NE(solved.hertz_force_error, prescribed.hertz_force_error);
  EXPECT_NE(solved.basis.find("solved under the sphere"), std::string::npos) << solved.basis;
  EXPECT_NE(prescribed.basis.find("prescribed"), std::string::npos) << prescribed.basis;
  const ContactModelError point = contact_model_error(tissue, false, 0.005, 0.0025, true);
  ASSERT_TRUE(point.defined);
  EXPECT_EQ(point.hertz_force_error, solved.hertz_force_error);
  EXPECT_NE(point.basis.find("point tool's tip"), std::string::npos) << point.basis;
}

}  // namespace
}  // namespace palpate
