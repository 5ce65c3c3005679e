#include "render/camera.h"

#include <gtest/gtest.h>

#include <cmath>

#include "render/gl_context.h"
#include "render/gl_context_factory.h"
#include "render/renderer.h"

namespace palpate {
namespace {

constexpr int kWidth = 160;
constexpr int kHeight = 120;

TEST(Camera, FramingLooksFromFrontRightAbove) {
  const Vec3 lo(-0.05, -0.04, 0.0), hi(0.05, 0.04, 0.06);
  const Camera cam = Camera::framing(lo, hi, 4.0 / 3.0);
  const Vec3 center = 0.5 * (lo + hi);
  EXPECT_TRUE(cam.target_m.isApprox(center));
  EXPECT_GT(cam.eye_m.x(), center.x());  // right
  EXPECT_LT(cam.eye_m.y(), center.y());  // front
  EXPECT_GT(cam.eye_m.z(), center.z());  // above
  EXPECT_GT(cam.near_m, 0.0);
  EXPECT_LT(cam.near_m, (cam.eye_m - center).norm() - 0.5 * (hi - lo).norm());
  EXPECT_GT(cam.far_m, (cam.eye_m - center).norm() + 0.5 * (hi - lo).norm());
}

TEST(Camera, FramingFromAGivenSideKeepsTheBoxInViewAndStraightDownHasAnUp) {
  const Vec3 lo(-0.05, -0.04, 0.0), hi(0.05, 0.04, 0.06), center = 0.5 * (lo + hi);
  for (const Vec3& from : {Vec3(0, 0, 1), Vec3(0.2, -0.3, 0.9), Vec3(-1, 0, 0)}) {
    const Camera cam = Camera::framing(lo, hi, 4.0 / 3.0, from);
    EXPECT_TRUE(cam.target_m.isApprox(center));
    EXPECT_GT((cam.eye_m - center).normalized().dot(from.normalized()), 0.999);
    // the box's every corner in front of the near plane and inside the view's clip box
    const Eigen::Matrix4d pv = cam.projection_matrix(4.0 / 3.0) * cam.view_matrix();
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector4d p(c & 1 ? hi.x() : lo.x(), c & 2 ? hi.y() : lo.y(), c & 4 ? hi.z() : lo.z(), 1.0);
      const Eigen::Vector4d q = pv * p;
      ASSERT_GT(q.w(), 0.0);
      EXPECT_LT(std::abs(q.x() / q.w()), 1.0) << from.transpose();
      EXPECT_LT(std::abs(q.y() / q.w()), 1.0) << from.transpose();
    }
    EXPECT_TRUE(cam.view_matrix().allFinite());  // straight down: +y is up, not the view direction itself
  }
  // zero: the default view
  EXPECT_TRUE(Camera::framing(lo, hi, 1.0, Vec3::Zero()).eye_m.isApprox(Camera::framing(lo, hi, 1.0).eye_m));
}

// A part of the model framed (a cut's incision): the sphere around the point fills the narrower field of view, and
// every corner of the whole box still lies between the clip planes (the rest of the model is drawn around it).
TEST(Camera, FramingAPartFillsTheViewWithItAndKeepsTheWholeBoxBetweenTheClipPlanes) {
  const Vec3 lo(-0.05, -0.04, 0.0), hi(0.05, 0.04, 0.06), at(0.04, -0.03, 0.05), from(0.3, -1.0, 0.8);
  const double r = 0.01, aspect = 4.0 / 3.0;
  const Camera cam = Camera::framing_part(lo, hi, aspect, from, at, r);
  EXPECT_TRUE(cam.target_m.isApprox(at));
  EXPECT_GT((cam.eye_m - at).normalized().dot(from.normalized()), 1.0 - 1e-12);
  // the sphere's edge beside the target, up in the image, lands at cos(half fov) / 1.05 of the half height (its
  // silhouette at the edge of the view less the framing's 5 % margin)
  const Eigen::Matrix4d pv = cam.projection_matrix(aspect) * cam.view_matrix();
  const Vec3 up = (cam.eye_m - at).cross(cam.up).cross(cam.eye_m - at).normalized();
  const Eigen::Vector4d edge = pv * (at + r * up).homogeneous();
  EXPECT_NEAR(edge.y() / edge.w(), std::cos(0.5 * cam.fov_y_deg * M_PI / 180.0) / 1.05, 1e-9);
  for (int c = 0; c < 8; ++c) {
    const Vec3 p(c & 1 ? hi.x() : lo.x(), c & 2 ? hi.y() : lo.y(), c & 4 ? hi.z() : lo.z());
    const double depth_m = (p - cam.eye_m).dot((at - cam.eye_m).normalized());
    EXPECT_GT(depth_m, cam.near_m) << p.transpose();
    EXPECT_LT(depth_m, cam.far_m) << p.transpose();
  }
  // no radius: the whole box, as framing()
  EXPECT_TRUE(Camera::framing_part(lo, hi, aspect, from, at, 0.0).eye_m.isApprox(Camera::framing(lo, hi, aspect, from).eye_m));
}

TEST(Camera, ViewMatrixPutsEyeAtOriginLookingDownMinusZ) {
  const Camera cam = Camera::framing(Vec3(0, 0, 0), Vec3(1, 2, 3), 1.0);
  const Eigen::Matrix4d v = cam.view_matrix();
  EXPECT_LT((v * cam.eye_m.homogeneous()).head<3>().norm(), 1e-12);
  const Vec3 target_eye = (v * cam.target_m.homogeneous()).head<3>();
  EXPECT_NEAR(target_eye.x(), 0.0, 1e-12);
  EXPECT_NEAR(target_eye.y(), 0.0, 1e-12);
  EXPECT_NEAR(target_eye.z(), -(cam.target_m - cam.eye_m).norm(), 1e-12);
  // world up stays up in the image
  EXPECT_GT((v.block<3, 3>(0, 0) * Vec3::UnitZ()).y(), 0.0);
}

TEST(Camera, DegenerateBoxStillGivesAFiniteCamera) {
  const Camera cam = Camera::framing(Vec3(1, 1, 1), Vec3(1, 1, 1), 0.0);
  EXPECT_TRUE(cam.eye_m.allFinite());
  EXPECT_GT((cam.eye_m - cam.target_m).norm(), 0.0);
  EXPECT_GT(cam.far_m, cam.near_m);
  EXPECT_GT(cam.near_m, 0.0);
}

TEST(Camera, ProjectOfFramedBoxCentreIsImageCentreAndCornersInside) {
  auto ctx = create_gl_context(kWidth, kHeight, RenderBackend::kOsmesa);
  ASSERT_TRUE(ctx.ok()) << ctx.error().message;
  for (const Vec3& hi : {Vec3(0.1, 0.08, 0.06), Vec3(0.01, 0.3, 0.02), Vec3(2.0, 0.1, 0.5)}) {
    const Vec3 lo = -0.5 * hi + Vec3(0.3, -0.2, 0.1);
    const Vec3 top = lo + hi;
    const Camera cam = Camera::framing(lo, top, static_cast<double>(kWidth) / kHeight);
    Renderer renderer(ctx.value().get(), RenderStyle::kSolid, cam);
    const Eigen::Vector2d c = renderer.project(0.5 * (lo + top));
    EXPECT_NEAR(c.x(), kWidth / 2.0, 0.5);
    EXPECT_NEAR(c.y(), kHeight / 2.0, 0.5);
    for (int i = 0; i < 8; ++i) {
      const Vec3 corner((i & 1) ? top.x() : lo.x(), (i & 2) ? top.y() : lo.y(), (i & 4) ? top.z() : lo.z());
      const Eigen::Vector2d p = renderer.project(corner);
      EXPECT_GT(p.x(), 0.0) << "corner " << i;
      EXPECT_LT(p.x(), kWidth) << "corner " << i;
      EXPECT_GT(p.y(), 0.0) << "corner " << i;
      EXPECT_LT(p.y(), kHeight) << "corner " << i;
    }
    // higher z is higher in the image (smaller y)
    EXPECT_LT(renderer.project(0.5 * (lo + top) + Vec3(0, 0, 0.01)).y(), c.y());
  }
}

}  // namespace
}  // namespace palpate
