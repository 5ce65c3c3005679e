#include "sim/cut/cut.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/pair_key.h"

namespace palpate {
namespace {

// Segment p->q against triangle a, b, c with an inclusive barycentric tolerance, so a segment through a shared
// edge of two quad triangles is never missed; false for a degenerate triangle or a parallel segment.
bool segment_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c, double* t) {
  constexpr double kBaryTol = 1e-9;
  const Vec3 d = q - p;
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 n = e1.cross(e2);
  const double area2 = n.norm();
  if (!(area2 > 1e-18)) return false;
  const Vec3 pv = d.cross(e2);
  const double det = e1.dot(pv);
  // parallel (or nearly): the segment does not pass through the plane at one point
  if (std::abs(det) <= 1e-12 * area2 * d.norm()) return false;
  const double inv = 1.0 / det;
  const Vec3 s = p - a;
  const double u = s.dot(pv) * inv;
  if (u < -kBaryTol || u > 1.0 + kBaryTol) return false;
  const Vec3 qv = s.cross(e1);
  const double v = d.dot(qv) * inv;
  if (v < -kBaryTol || u + v > 1.0 + kBaryTol) return false;
  const double tt = e2.dot(qv) * inv;
  if (tt < 0.0 || tt > 1.0) return false;
  *t = tt;
  return true;
}

}  // namespace

void CutBox::add(const BladeQuad& q) {
  for (const Vec3* p : {&q.tip0_m, &q.end0_m, &q.tip1_m, &q.end1_m}) {
    lo_m = lo_m.cwiseMin(*p);
    hi_m = hi_m.cwiseMax(*p);
  }
}

bool CutBox::overlaps_segment(const Vec3& p, const Vec3& q, double margin_m) const {
  const Vec3 lo = p.cwiseMin(q), hi = p.cwiseMax(q);
  return (lo.array() <= hi_m.array() + margin_m).all() && (hi.array() >= lo_m.array() - margin_m).all();
}

bool segment_crosses_quad(const Vec3& p_m, const Vec3& q_m, const BladeQuad& quad, double* t) {
  double t1 = 2.0, t2 = 2.0;
  const bool h1 = segment_triangle(p_m, q_m, quad.tip0_m, quad.end0_m, quad.end1_m, &t1);
  const bool h2 = segment_triangle(p_m, q_m, quad.tip0_m, quad.end1_m, quad.tip1_m, &t2);
  if (!h1 && !h2) return false;
  if (t) *t = std::min(h1 ? t1 : 2.0, h2 ? t2 : 2.0);
  return true;
}

CutQuads::CutQuads(const std::vector<BladeQuad>& q) : quads(q), quad_box(q.size()) {
  chunk_box.resize((q.size() + kChunk - 1) / kChunk);
  for (std::size_t i = 0; i < q.size(); ++i) {
    quad_box[i].add(q[i]);
    chunk_box[i / kChunk].add(q[i]);
    box.add(q[i]);
  }
}

bool segment_crosses_any(const Vec3& p_m, const Vec3& q_m, const CutQuads& quads, double* t, std::size_t* quad) {
  // a quad is tested only where the segment's box overlaps the quad's, so a run's box culls its quads at once
  if (quads.quads.empty() || !quads.box.overlaps_segment(p_m, q_m, 0.0)) return false;
  bool hit = false;
  double best = 2.0;
  std::size_t best_quad = 0;
  const std::size_t n = quads.quads.size();
  for (std::size_t c = 0; c < quads.chunk_box.size(); ++c) {
    if (!quads.chunk_box[c].overlaps_segment(p_m, q_m, 0.0)) continue;
    for (std::size_t i = c * CutQuads::kChunk; i < std::min(n, (c + 1) * CutQuads::kChunk); ++i) {
      if (!quads.quad_box[i].overlaps_segment(p_m, q_m, 0.0)) continue;
      double tq = 2.0;
      if (segment_crosses_quad(p_m, q_m, quads.quads[i], &tq)) {
        hit = true;
        if (tq < best) best = tq, best_quad = i;
        if (!t) return true;
      }
    }
  }
  if (hit && t) *t = best;
  if (hit && t && quad) *quad = best_quad;
  return hit;
}

namespace {

// Erases the springs `gone` picks (in order, once each, keeping the others' order), recounts the families and
// touches the lattice when any went. Returns how many went.
template <typename Pred>
int erase_springs(Lattice* lat, Pred gone) {
  const std::size_t before = lat->springs.size();
  lat->springs.erase(std::remove_if(lat->springs.begin(), lat->springs.end(), gone), lat->springs.end());
  const int removed = static_cast<int>(before - lat->springs.size());
  if (removed > 0) {
    lat->springs_per_family = {};
    for (const Spring& s : lat->springs) lat->springs_per_family[static_cast<int>(s.family)]++;
    lat->touch();
  }
  return removed;
}

}  // namespace

int cut_springs(Lattice* lat, const std::vector<BladeQuad>& quads) {
  if (quads.empty()) return 0;
  const CutQuads set(quads);
  return erase_springs(lat, [&](const Spring& s) { return segment_crosses_any(lat->rest_m[s.a], lat->rest_m[s.b], set); });
}

int cut_springs_capped(Lattice* lat, const std::vector<BladeQuad>& quads, int max_removed,
                       std::vector<uint64_t>* deferred) {
  const std::size_t n_now = std::min(deferred->size(), static_cast<std::size_t>(std::max(max_removed, 0)));
  // the oldest deferred go now, the rest stay deferred; both sorted for lookups
  std::vector<uint64_t> now(deferred->begin(), deferred->begin() + static_cast<std::ptrdiff_t>(n_now));
  std::vector<uint64_t> still(deferred->begin() + static_cast<std::ptrdiff_t>(n_now), deferred->end());
  deferred->erase(deferred->begin(), deferred->begin() + static_cast<std::ptrdiff_t>(n_now));
  std::sort(now.begin(), now.end());
  std::sort(still.begin(), still.end());
  int room = max_removed - static_cast<int>(n_now);
  const std::optional<CutQuads> set = quads.empty() ? std::nullopt : std::optional<CutQuads>(CutQuads(quads));
  return erase_springs(lat, [&](const Spring& s) {
    const uint64_t k = unordered_pair_key(s.a, s.b);
    if (std::binary_search(now.begin(), now.end(), k)) return true;
    if (!set || std::binary_search(still.begin(), still.end(), k)) return false;
    if (!segment_crosses_any(lat->rest_m[s.a], lat->rest_m[s.b], *set)) return false;
    if (room > 0) {
      --room;
      return true;
    }
    deferred->push_back(k);
    return false;
  });
}

int spring_components(const Lattice& lat, std::vector<int32_t>* label) {
  // union-find over the springs, then dense ids in node order
  const auto n = static_cast<int32_t>(lat.num_nodes());
  std::vector<int32_t> parent(static_cast<std::size_t>(n));
  for (int32_t i = 0; i < n; ++i) parent[i] = i;
  auto find = [&](int32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const Spring& s : lat.springs) {
    const int32_t a = find(s.a), b = find(s.b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  label->assign(static_cast<std::size_t>(n), -1);
  std::vector<int32_t> id_of_root(static_cast<std::size_t>(n), -1);
  int count = 0;
  for (int32_t i = 0; i < n; ++i) {
    int32_t& id = id_of_root[find(i)];
    if (id < 0) id = count++;
    (*label)[i] = id;
  }
  return count;
}

int free_nodes(const Lattice& lat) {
  std::vector<int32_t> label;
  const int count = spring_components(lat, &label);
  std::vector<uint8_t> anchored(static_cast<std::size_t>(count), 0);
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (lat.fixed[i]) anchored[label[i]] = 1;
  int n = 0;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) n += anchored[label[i]] ? 0 : 1;
  return n;
}

int apply_floor(Lattice* lat, double floor_z_m) {
  int held = 0;
  for (std::size_t i = 0; i < lat->num_nodes(); ++i) {
    if (lat->fixed[i]) continue;
    Vec3& x = lat->x_m[i];
    Vec3& v = lat->v_m_per_s[i];
    if (!x.allFinite() || !v.allFinite()) {
      x = lat->rest_m[i];
      v.setZero();
      continue;
    }
    if (x.z() >= floor_z_m) continue;
    x.z() = floor_z_m;
    v.z() = std::max(0.0, v.z());
    v.x() *= 0.5;
    v.y() *= 0.5;
    ++held;
  }
  return held;
}

}  // namespace palpate
