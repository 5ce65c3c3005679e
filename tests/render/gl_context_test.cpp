#include "render/gl_context.h"
#include "render/gl_context_factory.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "render_test_util.h"
#include "render/renderer.h"

namespace palpate {
namespace {

// EGL may be absent from a build or a machine; anything else is a failure.
bool egl_unavailable(const std::string& message) {
  return message.find("egl") != std::string::npos && message.find("not available") != std::string::npos;
}

TEST(GlContext, OsMesaReportsSizeAndBackend) {
  auto ctx = create_gl_context(64, 48, RenderBackend::kOsmesa);
  ASSERT_TRUE(ctx.ok()) << ctx.error().message;
  EXPECT_EQ(ctx.value()->width(), 64);
  EXPECT_EQ(ctx.value()->height(), 48);
  EXPECT_STREQ(ctx.value()->backend_name(), "osmesa");
  EXPECT_NE(std::getenv("LP_NUM_THREADS"), nullptr);
}

TEST(GlContext, EglReportsSizeAndBackend) {
  auto ctx = create_gl_context(64, 48, RenderBackend::kEgl);
  if (!ctx.ok() && egl_unavailable(ctx.error().message)) GTEST_SKIP() << ctx.error().message;
  ASSERT_TRUE(ctx.ok()) << ctx.error().message;
  EXPECT_EQ(ctx.value()->width(), 64);
  EXPECT_EQ(ctx.value()->height(), 48);
  EXPECT_STREQ(ctx.value()->backend_name(), "egl");
}

TEST(GlContext, AutoPicksABackend) {
  auto ctx = create_gl_context(32, 32, RenderBackend::kAuto);
  ASSERT_TRUE(ctx.ok()) << ctx.error().message;
  const std::string name = ctx.value()->backend_name();
  EXPECT_TRUE(name == "osmesa" || name == "egl") << name;
}

TEST(GlContext, BadSizeIsRejected) {
  auto ctx = create_gl_context(0, 480, RenderBackend::kOsmesa);
  ASSERT_FALSE(ctx.ok());
  EXPECT_NE(ctx.error().message.find("0x480"), std::string::npos) << ctx.error().message;
}

// Renders a box in a fresh context of the backend and returns the image.
std::vector<uint8_t> render_box_once(const std::string& backend) {
  constexpr int kW = 80, kH = 60;
  auto ctx = create_gl_context(kW, kH, from_name<RenderBackend>(backend).value());
  if (!ctx.ok()) {
    ADD_FAILURE() << ctx.error().message;
    return {};
  }
  const Vec3 lo(0, 0, 0), hi(0.1, 0.1, 0.1);
  const TriMesh box = test::make_box_mesh(lo, hi);
  Renderer renderer(ctx.value().get(), RenderStyle::kBoth, Camera::framing(lo, hi, double(kW) / kH));
  FrameView view;
  view.vertices_m = &box.vertices_m;
  view.triangles = &box.triangles;
  std::vector<uint8_t> rgba(kW * kH * 4);
  renderer.draw(view, rgba.data());
  return rgba;
}

TEST(GlContext, ContextsInSequenceRenderTheSameImage) {
  std::vector<std::string> backends = {"osmesa"};
  auto egl = create_gl_context(8, 8, RenderBackend::kEgl);
  if (egl.ok()) backends.push_back("egl");
  egl = make_error("released");  // destroy before the loop
  for (const std::string& backend : backends) {
    const auto first = render_box_once(backend);
    const auto second = render_box_once(backend);
    const auto third = render_box_once(backend);
    ASSERT_FALSE(first.empty());
    EXPECT_EQ(first, second) << backend;
    EXPECT_EQ(first, third) << backend;
  }
}

TEST(GlContext, BothBackendsLiveInOneProcess) {
  auto osmesa = create_gl_context(40, 30, RenderBackend::kOsmesa);
  ASSERT_TRUE(osmesa.ok()) << osmesa.error().message;
  auto egl = create_gl_context(40, 30, RenderBackend::kEgl);
  if (!egl.ok() && egl_unavailable(egl.error().message)) GTEST_SKIP() << egl.error().message;
  ASSERT_TRUE(egl.ok()) << egl.error().message;
  const Vec3 lo(0, 0, 0), hi(0.1, 0.1, 0.1);
  const TriMesh box = test::make_box_mesh(lo, hi);
  const Camera cam = Camera::framing(lo, hi, 40.0 / 30.0);
  Renderer r_osmesa(osmesa.value().get(), RenderStyle::kSolid, cam);
  Renderer r_egl(egl.value().get(), RenderStyle::kSolid, cam);
  FrameView view;
  view.vertices_m = &box.vertices_m;
  view.triangles = &box.triangles;
  std::vector<uint8_t> a(40 * 30 * 4), b(40 * 30 * 4), a2(40 * 30 * 4);
  r_osmesa.draw(view, a.data());
  r_egl.draw(view, b.data());
  r_osmesa.draw(view, a2.data());
  EXPECT_EQ(a, a2);
  // same rasteriser underneath: the images agree closely
  int differing = 0;
  for (std::size_t i = 0; i < a.size(); ++i) differing += std::abs(int(a[i]) - int(b[i])) > 8;
  EXPECT_LT(differing, static_cast<int>(a.size() / 50));
}

}  // namespace
}  // namespace palpate
