#include "sim/contact/solved_contact.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/LU>

namespace palpate {
namespace {

// a point's approach per unit move of the sphere below which it does not face the push (its normal is more than
// about 84 degrees from it): it cannot be the first to touch
constexpr double kMinApproach = 0.1;
// points per reach across the sampled disc's radius: about pi 3.5^2 = 38 points inside, under kMaxPoints
constexpr double kPointsPerReach = 3.5;
// the contact's own give, per the stiffest point's compliance: the penalty of sim/contact/sphere_contact.h gives about a
// thousandth of what the lattice under it does
constexpr double kGiveFraction = 1e-3;
// the reach grows when the loaded points come this close to its edge, and shrinks when they stay well inside
constexpr double kGrowAt = 0.7, kShrinkAt = 0.35, kGrow = 1.6, kShrink = 0.85;
// solves a frame may take when the contact reaches the edge of the sampled disc
constexpr int kMaxSolves = 3;

}  // namespace

bool solve_contact_lcp(const Eigen::MatrixXd& c, const Eigen::VectorXd& g, const Eigen::VectorXd& a, double force_N,
                       double give_m_per_N, ContactLcpResult* out) {
  const auto m = g.size();
  if (m == 0 || !(force_N > 0.0) || c.rows() != m || c.cols() != m || a.size() != m) return false;
  // the first point to touch as the sphere moves along the push
  Eigen::Index first = -1;
  double first_at = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < m; ++i)
    if (a[i] > kMinApproach && g[i] / a[i] < first_at) first_at = g[i] / a[i], first = i;
  if (first < 0) return false;
  std::vector<Eigen::Index> act{first};
  std::vector<uint8_t> in(static_cast<std::size_t>(m), 0);
  in[static_cast<std::size_t>(first)] = 1;
  const double gap_tol = 1e-12 + 1e-9 * g.cwiseAbs().maxCoeff();
  Eigen::VectorXd p = Eigen::VectorXd::Zero(m);
  double delta = 0.0;
  const int max_changes = 4 * static_cast<int>(m) + 8;
  for (int it = 0; it <= max_changes; ++it) {
    // the active points touch (g - delta a + C p = 0) and carry the push (a^T p = force):
    // [C_AA + give I, a_A; a_A^T, 0] [p_A; -delta] = [-g_A; force]
    const auto k = static_cast<Eigen::Index>(act.size());
    Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(k + 1, k + 1);
    Eigen::VectorXd rhs(k + 1);
    for (Eigen::Index r = 0; r < k; ++r) {
      for (Eigen::Index q = 0; q < k; ++q) kkt(r, q) = c(act[static_cast<std::size_t>(r)], act[static_cast<std::size_t>(q)]);
      kkt(r, r) += give_m_per_N;
      kkt(r, k) = kkt(k, r) = a[act[static_cast<std::size_t>(r)]];
      rhs[r] = -g[act[static_cast<std::size_t>(r)]];
    }
    rhs[k] = force_N;
    const Eigen::VectorXd sol = kkt.partialPivLu().solve(rhs);
    if (!sol.allFinite()) return false;
    p.setZero();
    for (Eigen::Index r = 0; r < k; ++r) p[act[static_cast<std::size_t>(r)]] = sol[r];
    delta = -sol[k];
    // a point pulling on the sphere leaves the contact (the most negative first)
    Eigen::Index worst = -1;
    for (Eigen::Index r = 0; r < k; ++r)
      if (sol[r] < 0.0 && (worst < 0 || sol[r] < sol[worst])) worst = r;
    if (worst >= 0 && k > 1) {
      in[static_cast<std::size_t>(act[static_cast<std::size_t>(worst)])] = 0;
      act.erase(act.begin() + worst);
      continue;
    }
    // a point the loaded surface pushes into the sphere joins it (the deepest first)
    const Eigen::VectorXd gap = g - delta * a + c * p;
    Eigen::Index enter = -1;
    for (Eigen::Index i = 0; i < m; ++i)
      if (!in[static_cast<std::size_t>(i)] && gap[i] < -gap_tol && (enter < 0 || gap[i] < gap[enter])) enter = i;
    if (enter < 0) {
      out->p = p.cwiseMax(0.0);
      out->delta_m = delta;
      out->active = static_cast<int>(k);
      out->iterations = it;
      return true;
    }
    in[static_cast<std::size_t>(enter)] = 1;
    act.push_back(enter);
  }
  return false;
}

void contact_points(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles,
                    const std::vector<int32_t>& tris, const Vec3& centre_m, const Vec3& push, double radius_m,
                    double reach_m, double spacing_m, int max_points, std::vector<ContactPoint>* out) {
  out->clear();
  if (!(reach_m > 0.0) || !(spacing_m > 0.0) || max_points <= 0) return;
  // the plane across the push, and one slot per spacing-sized square of it within the reach: each keeps the point
  // nearest the sphere along the push (a fold or the far side behind it is not what the sphere meets)
  const Vec3 e1 = push.unitOrthogonal(), e2 = push.cross(e1);
  const int half = static_cast<int>(std::ceil(reach_m / spacing_m));
  const int side = 2 * half + 1;
  struct Slot {
    double along = std::numeric_limits<double>::infinity(), lateral = 0.0, off_centre = 0.0;
    ContactPoint point;
  };
  std::vector<Slot> slots(static_cast<std::size_t>(side) * static_cast<std::size_t>(side));
  auto offer = [&](int32_t tri, const Vec3& bary, const Vec3& p) {
    const Vec3 d = p - centre_m;
    const double u = d.dot(e1), v = d.dot(e2), lateral = std::hypot(u, v);
    if (lateral > reach_m) return;
    const int iu = std::clamp(static_cast<int>(std::floor(u / spacing_m + 0.5)) + half, 0, side - 1);
    const int iv = std::clamp(static_cast<int>(std::floor(v / spacing_m + 0.5)) + half, 0, side - 1);
    Slot& s = slots[static_cast<std::size_t>(iu) * static_cast<std::size_t>(side) + static_cast<std::size_t>(iv)];
    // the point nearest the slot's middle (so the choice does not flicker as the surface moves along the push),
    // unless another layer lies nearer the sphere by more than a spacing
    const double along = d.dot(push);
    // behind the sphere's far side: the sphere moving along the push never meets it
    if (along < -std::sqrt(std::max(radius_m * radius_m - lateral * lateral, 0.0))) return;
    const double off = std::hypot(u - (iu - half) * spacing_m, v - (iv - half) * spacing_m);
    const bool nearer_layer = along < s.along - spacing_m;
    const bool same_layer = std::abs(along - s.along) <= spacing_m;
    if (nearer_layer || (same_layer && off < s.off_centre)) s = {along, lateral, off, {tri, bary}};
  };
  for (int32_t t : tris) {
    const auto& tr = triangles[static_cast<std::size_t>(t)];
    const Vec3& a = vertices_m[static_cast<std::size_t>(tr[0])];
    const Vec3& b = vertices_m[static_cast<std::size_t>(tr[1])];
    const Vec3& c = vertices_m[static_cast<std::size_t>(tr[2])];
    if ((b - a).cross(c - a).dot(push) >= 0.0) continue;  // faces away from the sphere
    const Vec3 mid = (a + b + c) / 3.0;
    const double size = std::max({(a - mid).norm(), (b - mid).norm(), (c - mid).norm()});
    const Vec3 d = mid - centre_m;
    if ((d - d.dot(push) * push).norm() > reach_m + size) continue;
    // the centroids of the triangle's k x k sub-triangles (k: its longest edge over the spacing)
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int k = std::clamp(static_cast<int>(std::ceil(longest / spacing_m)), 1, 2 * side);
    for (int i = 0; i < k; ++i)
      for (int j = 0; i + j < k; ++j)
        for (int down = 0; down < (i + j < k - 1 ? 2 : 1); ++down) {
          const double s = (i + (down ? 2.0 : 1.0) / 3.0) / k, r = (j + (down ? 2.0 : 1.0) / 3.0) / k;
          const Vec3 bary(1.0 - s - r, s, r);
          offer(t, bary, bary[0] * a + bary[1] * b + bary[2] * c);
        }
  }
  for (const Slot& s : slots)
    if (s.point.tri >= 0) out->push_back(s.point);
  // the nearest to the line first, as many as allowed
  std::vector<std::pair<double, std::size_t>> order;
  for (std::size_t i = 0, k = 0; i < slots.size(); ++i)
    if (slots[i].point.tri >= 0) order.emplace_back(slots[i].lateral, k++);
  std::stable_sort(order.begin(), order.end());
  std::vector<ContactPoint> kept;
  for (std::size_t i = 0; i < order.size() && static_cast<int>(i) < max_points; ++i) kept.push_back((*out)[order[i].second]);
  *out = std::move(kept);
}

void SolvedContactLoad::reset() {
  reach_m_ = 0.0;
  last_load_N_.clear();
}

bool SolvedContactLoad::weights(const Lattice& lat, const RestObject& rest, const std::vector<Vec3>& vertices_m,
                                const std::vector<int32_t>& tris, const Vec3& centre_m, double radius_m,
                                const Vec3& f_obj_N, ContactCompliance* compliance, PointWeights* w) {
  const double force = f_obj_N.norm();
  if (!(force > 0.0) || !(radius_m > 0.0) || !compliance->ready(lat)) return false;
  const Vec3 push = f_obj_N / force;
  const std::size_t n = lat.num_nodes();
  // the surface as it would stand without the last load
  if (last_load_N_.size() != n) last_load_N_.assign(n, Vec3::Zero());
  if (!compliance->solve(last_load_N_, &unload_m_)) return false;
  if (reach_m_ <= 0.0) reach_m_ = std::min(radius_m, 2.0 * lat.cell_m);
  for (int solve = 0; solve < kMaxSolves; ++solve) {
    contact_points(vertices_m, rest.mesh->triangles, tris, centre_m, push, radius_m, reach_m_, reach_m_ / kPointsPerReach,
                   kMaxPoints, &points_);
    point_w_.clear();
    dirs_.clear();
    std::vector<Vec3> base;
    std::vector<double> gap;
    std::vector<ContactPoint> used;
    for (const ContactPoint& cp : points_) {
      PointWeights pw = point_weights(lat, rest, cp.tri, cp.bary);
      if (pw.count == 0) continue;
      Vec3 b = surface_point(vertices_m, rest.mesh->triangles[static_cast<std::size_t>(cp.tri)], cp.bary);
      for (int i = 0; i < pw.count; ++i) b -= pw.weight[i] * unload_m_[static_cast<std::size_t>(pw.node[i])];
      const Vec3 d = b - centre_m;
      const double along = d.dot(push), lateral = (d - along * push).norm();
      if (lateral >= radius_m) continue;
      // the push is frictionless and the load goes along it (the frame applies the push itself): each point's gap is
      // its distance along the push from the sphere's surface, as in Hertz's theory (small slopes)
      point_w_.push_back(pw);
      dirs_.push_back(push);
      base.push_back(b);
      gap.push_back(along - std::sqrt(radius_m * radius_m - lateral * lateral));
      used.push_back(cp);
    }
    const auto m = static_cast<Eigen::Index>(used.size());
    if (m == 0 || !compliance->condense(point_w_, dirs_, &c_)) return false;
    g_ = Eigen::Map<const Eigen::VectorXd>(gap.data(), m);
    a_ = Eigen::VectorXd::Ones(m);
    if (!solve_contact_lcp(c_, g_, a_, force, kGiveFraction * c_.diagonal().maxCoeff(), &lcp_)) return false;
    // the loaded points' reach decides the next one's
    double radius = 0.0;
    for (Eigen::Index i = 0; i < m; ++i)
      if (lcp_.p[i] > 0.0) {
        const Vec3 d = base[static_cast<std::size_t>(i)] - centre_m;
        radius = std::max(radius, (d - d.dot(push) * push).norm());
      }
    report_ = {static_cast<int>(m), lcp_.active, radius, lcp_.delta_m};
    const bool at_edge = radius > kGrowAt * reach_m_ && reach_m_ < radius_m;
    if (at_edge) reach_m_ = std::min(radius_m, kGrow * reach_m_);
    else if (radius < kShrinkAt * reach_m_) reach_m_ = std::max(std::min(radius_m, 0.5 * lat.cell_m), kShrink * reach_m_);
    if (at_edge && solve + 1 < kMaxSolves) continue;
    PointWeights out;
    for (Eigen::Index i = 0; i < m; ++i) {
      if (!(lcp_.p[i] > 0.0)) continue;
      const double share = lcp_.p[i] * a_[i] / force;
      const PointWeights& pw = point_w_[static_cast<std::size_t>(i)];
      for (int q = 0; q < pw.count; ++q)
        if (!out.add(pw.node[q], share * pw.weight[q])) return false;
    }
    *w = out;
    std::fill(last_load_N_.begin(), last_load_N_.end(), Vec3::Zero());
    for (int q = 0; q < out.count; ++q) last_load_N_[static_cast<std::size_t>(out.node[q])] += out.weight[q] * f_obj_N;
    return true;
  }
  return false;
}

}  // namespace palpate
