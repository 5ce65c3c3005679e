#include "tools/commands/scene_trajectory.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "render/camera.h"
#include "runtime/session/surface_queries.h"

namespace palpate {
namespace {

constexpr double kNear_m = 0.003;        // it slows down this far out before pressing
constexpr double kGrabGap_m = 0.002;     // pull: the button is pressed this far out (within grab_radius_m)
constexpr double kRunStep_m = 0.001;     // the blade's path is probed every millimetre
constexpr double kRunGap_m = 0.002;      // a gap this long in it (a probe through an edge) is bridged
constexpr int kStrokeDirections = 16;    // directions across the approach a cut's stroke is chosen from
constexpr double kCutViewTurn = 0.6;     // a cut scene's view: from the blade's side, this much of the default view
constexpr double kCutViewMinCos = 0.5;   // ... seeing the face at the entry point at 60 degrees or less
constexpr double kFrameContext = 2.0;    // a cut's frame: the incision's sphere this many times as large ...
constexpr double kFrameMin_m = 0.015;    // ... and at least this large
constexpr double kFrameOfModel = 0.5;    // ... framed only when under this fraction of the model's sphere

double round_um(double x_m) { return std::round(x_m * 1e6) / 1e6; }

nlohmann::ordered_json vec_json(const Vec3& v) { return {round_um(v.x()), round_um(v.y()), round_um(v.z())}; }

nlohmann::ordered_json key(double t_s, const Vec3& p_m, bool button, const std::optional<Quat>& q = std::nullopt) {
  nlohmann::ordered_json k;
  k["t_s"] = t_s;
  k["pos_m"] = vec_json(p_m);
  if (button) k["button"] = true;
  if (q) k["orientation_wxyz"] = {q->w(), q->x(), q->y(), q->z()};
  return k;
}

// distance from P along the unit s to the box's face it leaves by
double to_face(const Aabb& box, const Vec3& P, const Vec3& s) {
  double t = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a)
    if (std::abs(s[a]) > 1e-9) t = std::min(t, ((s[a] > 0 ? box.max_m[a] : box.min_m[a]) - P[a]) / s[a]);
  return std::max(t, 0.0);
}

}  // namespace

double thickness_under(const Model& model, const Vec3& point_m, const Vec3& d, double reach_m) {
  // from just inside: the face the point lies on is behind the ray's start
  const double start_m = 1e-6;
  const auto exit = first_ray_hit(model, point_m + start_m * d, d, reach_m, false);
  return exit ? exit->distance_m + start_m : std::numeric_limits<double>::infinity();
}

double blade_run_m(const Model& model, const Vec3& P, const Vec3& d, const Vec3& across, double depth_m,
                   double clearance_m, double limit_m) {
  double run_m = 0.0;
  for (double t = 0.0; t <= limit_m && t - run_m <= kRunGap_m; t += kRunStep_m) {
    // the blade at t spans clearance_m above P's plane to depth_m below it; it cuts a visible incision where it
    // crosses a surface facing the way it came in
    const Vec3 top = P + t * across - clearance_m * d;
    if (first_ray_hit(model, top, d, clearance_m + depth_m, true)) run_m = t;
  }
  return run_m;
}

CutStroke choose_cut_stroke(const Model& model, const Aabb& box, const Vec3& P, const Vec3& d, double depth_m,
                            double clearance_m) {
  // first candidate: the box's longest side across d, toward its farther face (the stroke before the run counted)
  Vec3 first = Vec3::Zero();
  double best = -1.0;
  for (int a = 0; a < 3; ++a) {
    const Vec3 s = Vec3::Unit(a) - d[a] * d;
    if (s.norm() < 0.5) continue;
    if (box.extent()[a] * s.norm() > best) {
      best = box.extent()[a] * s.norm();
      first = s.normalized();
    }
  }
  if (to_face(box, P, -first) > to_face(box, P, first)) first = -first;
  const Vec3 second = d.cross(first).normalized();
  CutStroke stroke;
  stroke.run_m = -1.0;
  for (int k = 0; k < kStrokeDirections; ++k) {
    const double angle = 2.0 * M_PI * k / kStrokeDirections;
    const Vec3 s = (std::cos(angle) * first + std::sin(angle) * second).normalized();
    const double run_m = blade_run_m(model, P, d, s, depth_m, clearance_m, to_face(box, P, s));
    if (run_m > stroke.run_m + kRunStep_m) stroke = {s, run_m};
  }
  return stroke;
}

Vec3 cut_view_from(const Vec3& d, const Vec3& normal) {
  const Vec3 v = (-d.normalized() + kCutViewTurn * kDefaultViewFrom.normalized()).normalized();
  return v.dot(normal) >= kCutViewMinCos ? v : normal.normalized();
}

std::optional<CutFrame> cut_frame(const Vec3& P, const Vec3& d, const CutStroke& stroke, double depth_m, const Aabb& box) {
  // the incision: the blade's path on the surface, from the entry point along the stroke, as deep as the blade goes
  const CutFrame f{P + 0.5 * stroke.run_m * stroke.across + 0.5 * depth_m * d,
                   std::max(kFrameMin_m, kFrameContext * 0.5 * std::hypot(stroke.run_m, depth_m))};
  if (!(f.radius_m < kFrameOfModel * 0.5 * box.extent().norm())) return std::nullopt;
  return f;
}

double incision_px(const Model& model, const Camera& cam, int width, int height, const Vec3& in, const Vec3& out,
                   const Vec3& d, double blade_length_m) {
  const double aspect = static_cast<double>(width) / height;
  const Eigen::Matrix4d clip = cam.projection_matrix(aspect) * cam.view_matrix();
  auto pixel = [&](const Vec3& p) {
    const Eigen::Vector4d c = clip * Eigen::Vector4d(p.x(), p.y(), p.z(), 1.0);
    return Eigen::Vector2d(0.5 * (c.x() / c.w() + 1.0) * width, 0.5 * (1.0 - c.y() / c.w()) * height);
  };
  double px = 0.0;
  Eigen::Vector2d last = Eigen::Vector2d::Zero();
  bool crossed = false;  // the previous probe crossed the surface, at pixel `last`
  const int n = std::max(1, static_cast<int>(std::ceil((out - in).norm() / 5e-4)));
  for (int i = 0; i <= n; ++i) {
    const Vec3 tip = in + (out - in) * (static_cast<double>(i) / n);
    const auto hit = first_ray_hit(model, tip - blade_length_m * d, d, blade_length_m, true);
    if (!hit) {
      crossed = false;
      continue;
    }
    const Eigen::Vector2d at = pixel(hit->point_m);
    if (crossed) px += (at - last).norm();
    last = at;
    crossed = true;
  }
  return px;
}

double add_trajectory(InteractionMode mode, const Vec3& P, const Vec3& d, double clearance_m, double depth_m,
                      const CutStroke& stroke, const Aabb& box, nlohmann::ordered_json* j) {
  const Vec3 start = P - clearance_m * d;
  nlohmann::ordered_json traj = nlohmann::ordered_json::array();
  double duration_s = 3.5;
  if (mode == InteractionMode::kTouch) {
    (*j)["interaction"] = {{"mode", "touch"}, {"grab_radius_m", kGrabRadius_m}};
    const Vec3 pressed = P + depth_m * d;
    traj = {key(0.0, start, false), key(0.4, start, false), key(1.2, P - kNear_m * d, false), key(2.0, pressed, false),
            key(2.6, pressed, false), key(3.2, start, false)};
  } else if (mode == InteractionMode::kPull) {
    (*j)["interaction"] = {{"mode", "pull"}, {"grab_radius_m", kGrabRadius_m}};
    const Vec3 grab = P - kGrabGap_m * d;
    const Vec3 pulled = grab - depth_m * d;
    traj = {key(0.0, start, false), key(0.8, grab, false), key(1.0, grab, true), key(2.0, pulled, true),
            key(2.6, pulled, true), key(2.8, pulled, false), key(3.2, pulled - kNear_m * d, false)};
  } else {
    // the blade points back out of the surface; it goes in by depth, then along the stroke to the box's far side
    const Quat q = Quat::FromTwoVectors(Vec3::UnitZ(), -d);
    const Vec3 in = P + depth_m * d;
    const Vec3 out = in + (to_face(box, P, stroke.across) + 0.01) * stroke.across;
    (*j)["interaction"] = {{"mode", "cut"}, {"blade_length_m", round_um(depth_m + clearance_m + 0.01)},
                           {"cut_resistance_Ns_per_m", 4.0}};
    traj = {key(0.0, start, false, q), key(0.2, start, true, q), key(1.0, in, true, q), key(2.2, out, true, q),
            key(2.4, out, false, q),  key(2.8, out - (depth_m + clearance_m) * d, false, q)};
    duration_s = 3.0;
  }
  (*j)["trajectory"] = traj;
  return duration_s;
}

}  // namespace palpate
