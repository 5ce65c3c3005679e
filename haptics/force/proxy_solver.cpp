#include "haptics/force/proxy_solver.h"

#include <algorithm>
#include <cmath>

#include "haptics/force/triangle_queries.h"

namespace palpate {
namespace {

constexpr int kMaxActive = 3;
constexpr int kMaxRounds = 64;
constexpr int kMaxSkipped = 8;
constexpr double kStill_m2 = 1e-26;  // moves shorter than 1e-13 m are none
constexpr double kInto = 1e-9;       // a move enters a plane when n . d < -kInto |d| (tangential slides do not)

struct Plane {
  Vec3 n = Vec3::UnitZ();  // unit; the centre keeps n . x >= n . at
  Vec3 at = Vec3::Zero();
  int tri = -1;            // the patch triangle it stands for
};

// the projection of goal onto the active planes, all through c
Vec3 project(const Vec3& goal, const Vec3& c, const Plane* w, int nw) noexcept {
  if (nw == 0) return goal;
  if (nw == 1) return goal - (goal - c).dot(w[0].n) * w[0].n;
  if (nw == 2) {
    const Vec3 e = w[0].n.cross(w[1].n);
    return c + (goal - c).dot(e) / e.squaredNorm() * e;
  }
  return c;
}

// the active plane whose multiplier for min |x - goal|^2 (x - goal = sum lambda_i n_i) is most negative, or -1
int most_negative(const Vec3& goal, const Vec3& c, const Plane* w, int nw) noexcept {
  const Vec3 g = c - goal;
  double lambda[kMaxActive] = {0.0, 0.0, 0.0};
  if (nw == 1) {
    lambda[0] = g.dot(w[0].n);
  } else if (nw == 2) {
    const double ab = w[0].n.dot(w[1].n), det = 1.0 - ab * ab;
    const double ga = g.dot(w[0].n), gb = g.dot(w[1].n);
    lambda[0] = (ga - ab * gb) / det;
    lambda[1] = (gb - ab * ga) / det;
  } else if (nw == 3) {
    Mat3 n;
    for (int i = 0; i < 3; ++i) n.col(i) = w[i].n;
    const Vec3 l = n.inverse() * g;
    for (int i = 0; i < 3; ++i) lambda[i] = l[i];
  }
  int worst = -1;
  double low = -1e-15;
  for (int i = 0; i < nw; ++i)
    if (lambda[i] < low) {
      low = lambda[i];
      worst = i;
    }
  return worst;
}

bool independent(const Plane* w, int nw, const Vec3& n) noexcept {
  if (nw == 0) return true;
  if (nw == 1) return w[0].n.cross(n).squaredNorm() > 1e-12;
  if (nw == 2) return std::abs(w[0].n.cross(w[1].n).dot(n)) > 1e-9;
  return false;
}

// earliest t in [0, 1] at which |p + t d - centre| = r while closing in (a vertex, or an edge's axis point)
bool sweep_ball(const Vec3& p, const Vec3& d, const Vec3& centre, double r, double* t) noexcept {
  const Vec3 m = p - centre;
  const double a = d.squaredNorm(), b = 2.0 * m.dot(d), c = m.squaredNorm() - r * r;
  if (a <= 0.0 || c < 0.0 || b >= 0.0) return false;
  const double disc = b * b - 4.0 * a * c;
  if (disc <= 0.0) return false;  // grazing or missing
  *t = (-b - std::sqrt(disc)) / (2.0 * a);
  return *t <= 1.0;
}

// earliest t in [0, 1] at which the centre p + t d comes within r of triangle (a, b, c), entering; *n: the
// contact normal there. A centre already within r (1e-9 relative) that moves in counts at t = 0.
bool sweep_triangle(const Vec3& p, const Vec3& d, double r, const std::array<Vec3, 3>& tri, double* t_hit,
                    Vec3* n_hit) noexcept {
  const double dl = d.norm();
  Vec3 bary = Vec3::Zero();
  const Vec3 q = closest_point_on_triangle(p, tri[0], tri[1], tri[2], &bary);
  const Vec3 face = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalized();
  const Vec3 e = p - q;
  const double dist = e.norm();
  if (dist <= r * (1.0 + 1e-9)) {
    const Vec3 n = dist > 1e-12 && (bary.minCoeff() <= 1e-12 || e.dot(face) > 0.0) ? Vec3(e / dist) : face;
    if (n.dot(d) < -kInto * dl) {
      *t_hit = 0.0;
      *n_hit = n;
      return true;
    }
    return false;
  }
  double best = INFINITY;
  Vec3 bn = Vec3::Zero();
  // the face, from its front
  const double h0 = face.dot(p - tri[0]), h1 = face.dot(d);
  if (h0 >= r && h1 < 0.0) {
    const double t = (h0 - r) / -h1;
    if (t <= 1.0) {
      const Vec3 at = p + t * d - r * face;
      Vec3 b = Vec3::Zero();
      const Vec3 on = closest_point_on_triangle(at, tri[0], tri[1], tri[2], &b);
      if ((on - at).squaredNorm() <= 1e-24 + 1e-18 * r * r) {
        best = t;
        bn = face;
      }
    }
  }
  // the edges: a cylinder of radius r round each, between its ends
  for (int k = 0; k < 3; ++k) {
    const Vec3& a = tri[k];
    const Vec3 ab = tri[(k + 1) % 3] - a;
    const double len = ab.norm();
    if (!(len > 0.0)) continue;
    const Vec3 u = ab / len;
    const Vec3 m = p - a, mp = m - m.dot(u) * u, dp = d - d.dot(u) * u;
    const double qa = dp.squaredNorm(), qb = 2.0 * mp.dot(dp), qc = mp.squaredNorm() - r * r;
    if (qa <= 0.0 || qc < 0.0 || qb >= 0.0) continue;
    const double disc = qb * qb - 4.0 * qa * qc;
    if (disc <= 0.0) continue;
    const double t = (-qb - std::sqrt(disc)) / (2.0 * qa);
    if (t > 1.0 || t >= best) continue;
    const Vec3 x = p + t * d;
    const double s = (x - a).dot(u);
    if (s < 0.0 || s > len) continue;
    best = t;
    bn = (x - (a + s * u)).normalized();
  }
  // the corners
  for (int k = 0; k < 3; ++k) {
    double t = 0.0;
    if (sweep_ball(p, d, tri[k], r, &t) && t < best) {
      best = t;
      bn = (p + t * d - tri[k]).normalized();
    }
  }
  if (!(best <= 1.0)) return false;
  *t_hit = std::max(0.0, best);
  *n_hit = bn;
  return true;
}

bool far_side(const std::array<Vec3, 3>& t, const Vec3& side) noexcept {
  const Vec3 face = (t[1] - t[0]).cross(t[2] - t[0]);
  return !(face.squaredNorm() > 0.0) || face.dot(side) < -0.5 * face.norm();
}

}  // namespace

Vec3 god_object_move(const LocalModel& m, const Vec3& from, const Vec3& goal, double r, const Vec3& side,
                     int* active, double max_path_m) noexcept {
  Vec3 c = from;
  Plane w[kMaxActive];
  int nw = 0;
  int skipped[kMaxSkipped];
  int ns = 0;
  double left_m = max_path_m > 0.0 ? max_path_m : INFINITY;
  bool cut_short = false;
  bool settled = false;  // the loop ended on an answer (the goal, or planes the goal presses c into), not on the limit
  for (int round = 0; round < kMaxRounds && !cut_short; ++round) {
    // a plane whose triangle the slide has left (past a convex edge, off a corner) holds nothing any more
    int gone = -1;
    for (int k = 0; k < nw && gone < 0; ++k) {
      const auto& t = m.tri_m[w[k].tri];
      Vec3 b = Vec3::Zero();
      const double dist = (c - closest_point_on_triangle(c, t[0], t[1], t[2], &b)).norm();
      if (dist > r * (1.0 + 1e-6) + 1e-10) gone = k;
    }
    if (gone >= 0) {
      w[gone] = w[--nw];
      ns = 0;  // with a plane fewer, the sweep may meet what it passed over
      continue;
    }
    Vec3 d = project(goal, c, w, nw) - c;
    if (d.norm() > left_m) {
      d *= std::max(0.0, left_m) / d.norm();
      cut_short = true;
    }
    if (d.squaredNorm() <= kStill_m2) {
      const int drop = most_negative(goal, c, w, nw);
      if (drop < 0) {
        settled = true;  // the goal presses c into every plane holding it (or none holds it: c is the goal)
        break;
      }
      w[drop] = w[--nw];
      ns = 0;
      continue;
    }
    // the first triangle the sweep along d meets (triangles far from the swept capsule are passed over)
    const Vec3 mid = c + 0.5 * d;
    const double reach = 0.5 * d.norm() + r;
    double t_first = INFINITY;
    Vec3 n_first = Vec3::Zero();
    int first = -1;
    for (int i = 0; i < m.num_triangles; ++i) {
      const auto& t = m.tri_m[i];
      const Vec3 g = (t[0] + t[1] + t[2]) / 3.0;
      const double rad = std::sqrt(std::max({(t[0] - g).squaredNorm(), (t[1] - g).squaredNorm(),
                                             (t[2] - g).squaredNorm()}));
      if ((g - mid).norm() > reach + rad) continue;
      if (std::find(skipped, skipped + ns, i) != skipped + ns) continue;
      double th = 0.0;
      Vec3 nh = Vec3::Zero();
      bool hit = false;
      if (far_side(t, side)) {
        // the far side of a thin part never stops a sphere that reaches it; but a centre whose own path enters a face
        // from its front (a fold in a scanned surface, turned against the contact's side) stops there as at any
        // face, a radius short of it along the path, or it would go through the surface
        double u = 0.0;
        Vec3 b = Vec3::Zero();
        hit = segment_enters_triangle(c, c + d, t[0], t[1], t[2], &u, &b);
        if (hit) {
          th = std::max(0.0, u - r / d.norm());
          nh = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
        }
      } else {
        hit = sweep_triangle(c, d, r, t, &th, &nh);
      }
      if (hit && th < t_first) {
        t_first = th;
        n_first = nh;
        first = i;
      }
    }
    if (first < 0) {
      c += d;
      left_m -= d.norm();
      continue;
    }
    c += t_first * d;
    left_m -= t_first * d.norm();
    cut_short = false;  // the sweep stopped on the surface before the bound
    if (nw < kMaxActive && independent(w, nw, n_first)) {
      w[nw].n = n_first;
      w[nw].at = c;
      w[nw].tri = first;
      ++nw;
    } else if (ns < kMaxSkipped) {
      skipped[ns++] = first;  // a plane the held ones already stand for (or a fourth): pass it over
    } else {
      settled = true;  // wedged: stay here
      break;
    }
  }
  if (cut_short) {
    // stopped by the bound, perhaps off the surface (past a convex edge): down onto it the shortest way, to r from
    // the nearest point of a face on the contact's side (toward the goal instead, a goal deep under a face the slide
    // runs nearly parallel to drew the centre along that face: a snap of 1.5 mm in one tick on a coarse ball)
    double best = INFINITY;
    Vec3 q = c;
    for (int i = 0; i < m.num_triangles; ++i) {
      const auto& t = m.tri_m[i];
      if (far_side(t, side)) continue;
      Vec3 b = Vec3::Zero();
      const Vec3 p = closest_point_on_triangle(c, t[0], t[1], t[2], &b);
      const double dist = (c - p).squaredNorm();
      if (dist < best) {
        best = dist;
        q = p;
      }
    }
    if (best < INFINITY && std::sqrt(best) > r) c = q + r * (c - q).normalized();
    nw = std::max(nw, 1);
  }
  // out of rounds (rolling along a crease of edge contacts creeps on a little each round): c is where the slide got
  // to, on the surface, never the goal, even when the round that ran out had just let go of a plane
  if (!settled && !cut_short) nw = std::max(nw, 1);
  *active = nw;
  return c;
}

double push_out(const LocalModel& m, double r, const Vec3& side, int rounds, Vec3* c) noexcept {
  double worst = 0.0;
  for (int round = 0; round < rounds; ++round) {
    worst = 0.0;
    Vec3 push = Vec3::Zero();
    for (int i = 0; i < m.num_triangles; ++i) {
      const auto& t = m.tri_m[i];
      if (far_side(t, side)) continue;
      Vec3 b = Vec3::Zero();
      const Vec3 q = closest_point_on_triangle(*c, t[0], t[1], t[2], &b);
      const Vec3 e = *c - q;
      const double dist = e.norm();
      if (dist >= r) continue;
      const Vec3 face = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
      const bool in_front = e.dot(face) > 0.0 || b.minCoeff() <= 1e-12;
      const double depth = in_front ? r - dist : r + dist;
      if (depth > worst) {
        worst = depth;
        push = (in_front && dist > 1e-12 ? Vec3(e / dist) : face) * depth;
      }
    }
    if (worst <= 1e-12 * r) return 0.0;
    *c += push;
  }
  return worst;
}

bool convex_contact(const LocalModel& m, const Vec3& c, double reach, const Vec3& side, bool point) noexcept {
  Vec3 first_q = Vec3::Zero();
  int first = -1;
  for (int i = 0; i < m.num_triangles; ++i) {
    const auto& t = m.tri_m[i];
    if (far_side(t, side)) continue;
    Vec3 b = Vec3::Zero();
    const Vec3 q = closest_point_on_triangle(c, t[0], t[1], t[2], &b);
    if ((c - q).norm() > reach) continue;
    if (first < 0) {
      first_q = q;
      first = i;
      continue;
    }
    if (point) {
      // faces that turn toward each other (a concave edge or corner): a vertex of one in front of the other's plane
      const auto& f = m.tri_m[first];
      const Vec3 fn = (f[1] - f[0]).cross(f[2] - f[0]).normalized();
      const Vec3 tn = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
      for (int k = 0; k < 3; ++k)
        if ((t[k] - f[0]).dot(fn) > 1e-9 || (f[k] - t[0]).dot(tn) > 1e-9) return false;
    } else if ((q - first_q).norm() > 1e-3 * reach) {
      return false;  // a sphere touching two places
    }
  }
  return true;
}

}  // namespace palpate
