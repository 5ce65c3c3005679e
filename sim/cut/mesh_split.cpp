#include "sim/cut/mesh_split.h"

#include "core/pair_key.h"

#include <algorithm>
#include <map>
#include <unordered_map>

namespace palpate {
namespace {

// The two vertices made on one crossed edge: copy[0] on the side of the lower index, copy[1] on the higher.
struct EdgeCut {
  std::array<int32_t, 2> copy{-1, -1};
  int32_t lo = 0;
  // the copy on the side of vertex v (one of the edge's ends)
  int32_t side_of(int32_t v) const { return v == lo ? copy[0] : copy[1]; }
};

}  // namespace

MeshSplitReport split_mesh(const std::vector<BladeQuad>& quads, std::vector<Vec3>* rest_m, std::vector<Vec3>* current_m,
                           std::vector<std::array<int32_t, 3>>* triangles, std::vector<SplitVertex>* created,
                           std::vector<TipTriangle>* tips, TriangleGrid* grid, const IncisionShape& incision,
                           std::vector<TriangleChange>* changes) {
  MeshSplitReport rep;
  created->clear();
  if (changes) changes->clear();
  if (quads.empty()) return rep;
  const std::size_t count_before = triangles->size();
  const CutQuads set(quads);

  // the triangles near the sweep: those registered in the cubes each quad's box overlaps
  std::vector<int32_t> near;
  {
    std::vector<Vec3> lo, hi;
    for (const CutBox& b : set.quad_box) lo.push_back(b.lo_m), hi.push_back(b.hi_m);
    grid->query_all(lo, hi, 0.0, &near);
  }

  // the work: each near triangle, with a crack tip's two halves taken back to the original triangle (its
  // crossing kept), in slot order so the numbering of new vertices is deterministic
  struct Work {
    std::array<int32_t, 3> tri;
    std::array<int32_t, 2> slot;  // slot[1] < 0: one slot
  };
  std::unordered_map<int32_t, std::size_t> tip_of_slot;
  for (std::size_t i = 0; i < tips->size(); ++i)
    for (int32_t sl : (*tips)[i].slot) tip_of_slot.emplace(sl, i);
  std::unordered_map<uint64_t, EdgeCut> cuts;
  std::vector<uint8_t> reopened(tips->size(), 0);
  std::vector<Work> work;
  work.reserve(near.size());
  for (int32_t t : near) {
    const auto it = tip_of_slot.find(t);
    if (it == tip_of_slot.end()) {
      work.push_back({(*triangles)[t], {t, -1}});
      continue;
    }
    if (reopened[it->second]) continue;
    reopened[it->second] = 1;
    const TipTriangle& tip = (*tips)[it->second];
    work.push_back({tip.tri, tip.slot});
    EdgeCut c;
    c.lo = tip.edge_lo;
    c.copy = {tip.copy_lo, tip.copy_hi};
    cuts.emplace(unordered_pair_key(tip.edge_lo, tip.edge_hi), c);
    ++rep.tips_reopened;
  }
  rep.triangles_tested = static_cast<int>(work.size());
  const std::vector<Vec3>& x = *rest_m;

  std::unordered_map<uint64_t, uint8_t> tested;  // 0 = not crossed
  for (const Work& w : work) {
    for (int k = 0; k < 3; ++k) {
      const int32_t a = std::min(w.tri[k], w.tri[(k + 1) % 3]), b = std::max(w.tri[k], w.tri[(k + 1) % 3]);
      if (!set.box.overlaps_segment(x[a], x[b], 0.0)) continue;
      const uint64_t key = unordered_pair_key(a, b);
      if (tested.count(key) || cuts.count(key)) continue;
      double t = 0.0;
      std::size_t quad = 0;
      const bool hit = segment_crosses_any(x[a], x[b], set, &t, &quad) && t > kSplitEdgeEps && t < 1.0 - kSplitEdgeEps;
      tested.emplace(key, hit ? 1 : 0);
      if (!hit) continue;
      EdgeCut c;
      c.lo = a;
      const Vec3 rest = x[a] + t * (x[b] - x[a]);
      const Vec3 cur = (*current_m)[a] + t * ((*current_m)[b] - (*current_m)[a]);
      const Vec3 normal = (x[w.tri[1]] - x[w.tri[0]]).cross(x[w.tri[2]] - x[w.tri[0]]).normalized();
      // both copies below the crossing, on the swept surface: the incision's groove; each set apart to its own
      // side by half the blade's width
      const Vec3 at = incision_point(set.quads[quad], rest, normal, (x[b] - x[a]).norm(), incision);
      for (int side = 0; side < 2; ++side) {
        const Vec3 p = incision_side_point(set.quads[quad], at, x[side == 0 ? a : b] - rest, incision);
        c.copy[side] = static_cast<int32_t>(rest_m->size());
        rest_m->push_back(p);
        current_m->push_back(cur + (p - rest));
        created->push_back(side == 0 ? SplitVertex{a, b, t} : SplitVertex{b, a, 1.0 - t});
      }
      cuts.emplace(key, c);
      ++rep.edges_cut;
    }
  }
  if (rep.edges_cut == 0 && rep.tips_reopened == 0) return rep;

  // the tips not reopened stay; reopened ones become tips again, or are split through
  std::vector<TipTriangle> kept;
  for (std::size_t i = 0; i < tips->size(); ++i)
    if (!reopened[i]) kept.push_back((*tips)[i]);
  auto place = [&](const Work& w, const std::vector<std::array<int32_t, 3>>& pieces, std::vector<int32_t>* slots) {
    slots->clear();
    for (std::size_t i = 0; i < pieces.size(); ++i) {
      int32_t sl;
      if (i == 0 || (i == 1 && w.slot[1] >= 0)) {
        sl = w.slot[i];
        if (changes) changes->push_back({sl, (*triangles)[sl]});
        (*triangles)[sl] = pieces[i];
      } else {
        sl = static_cast<int32_t>(triangles->size());
        if (changes) changes->push_back({sl, {-1, -1, -1}});
        triangles->push_back(pieces[i]);
        const auto& p = pieces[i];
        grid->add(sl, (*rest_m)[p[0]], (*rest_m)[p[1]], (*rest_m)[p[2]]);
      }
      slots->push_back(sl);
    }
  };
  std::vector<std::array<int32_t, 3>> pieces;
  std::vector<int32_t> slots;
  for (const Work& w : work) {
    const auto& tri = w.tri;
    const EdgeCut* e[3];
    int n = 0;
    for (int k = 0; k < 3; ++k) {
      const auto it = cuts.find(unordered_pair_key(tri[k], tri[(k + 1) % 3]));
      e[k] = it == cuts.end() ? nullptr : &it->second;
      n += e[k] ? 1 : 0;
    }
    pieces.clear();
    if (n == 0) continue;  // a near triangle the sweep missed (a reopened tip always has its crossing)
    if (n == 1) {
      // rotate so the crossed edge is a -> b; the opening runs from the crossing to the far corner c
      int k = 0;
      while (!e[k]) ++k;
      const int32_t a = tri[k], b = tri[(k + 1) % 3], c = tri[(k + 2) % 3];
      pieces.push_back({a, e[k]->side_of(a), c});
      pieces.push_back({e[k]->side_of(b), b, c});
      place(w, pieces, &slots);
      const int32_t lo = std::min(a, b), hi = std::max(a, b);
      kept.push_back({tri, lo, hi, e[k]->side_of(lo), e[k]->side_of(hi), {slots[0], slots[1]}});
      ++rep.tris_one_cut;
    } else if (n == 2) {
      // rotate so the uncrossed edge is a -> b: b -> c crossed at q, c -> a at r; c alone on its side
      int k = 0;
      while (e[k]) ++k;
      const int32_t a = tri[k], b = tri[(k + 1) % 3], c = tri[(k + 2) % 3];
      const EdgeCut& q = *e[(k + 1) % 3];
      const EdgeCut& r = *e[(k + 2) % 3];
      pieces.push_back({q.side_of(c), c, r.side_of(c)});
      const int32_t qb = q.side_of(b), ra = r.side_of(a);
      // the quad a, b, q, r split along its shorter diagonal
      if (((*rest_m)[a] - (*rest_m)[qb]).squaredNorm() <= ((*rest_m)[b] - (*rest_m)[ra]).squaredNorm()) {
        pieces.push_back({a, b, qb});
        pieces.push_back({a, qb, ra});
      } else {
        pieces.push_back({a, b, ra});
        pieces.push_back({b, qb, ra});
      }
      place(w, pieces, &slots);
      ++rep.tris_two_cut;
    } else {
      const int32_t a = tri[0], b = tri[1], c = tri[2];
      pieces.push_back({a, e[0]->side_of(a), e[2]->side_of(a)});
      pieces.push_back({e[0]->side_of(b), b, e[1]->side_of(b)});
      pieces.push_back({e[1]->side_of(c), c, e[2]->side_of(c)});
      place(w, pieces, &slots);
      ++rep.tris_three_cut;
    }
  }
  *tips = std::move(kept);
  rep.triangles_added = static_cast<int>(triangles->size()) - static_cast<int>(count_before);
  rep.vertices_added = 2 * rep.edges_cut;
  return rep;
}

std::string mesh_problem(const std::vector<Vec3>& v, const std::vector<std::array<int32_t, 3>>& triangles) {
  const auto n_v = static_cast<int64_t>(v.size());
  std::map<std::array<int32_t, 3>, std::size_t> seen;
  std::unordered_map<uint64_t, std::size_t> directed;
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const auto& t = triangles[i];
    const std::string who = "triangle " + std::to_string(i);
    for (int32_t idx : t)
      if (idx < 0 || idx >= n_v) return who + ": vertex index " + std::to_string(idx) + " out of range";
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return who + ": repeated vertex";
    const Vec3 e1 = v[t[1]] - v[t[0]], e2 = v[t[2]] - v[t[0]];
    const double longest2 = std::max({e1.squaredNorm(), e2.squaredNorm(), (v[t[2]] - v[t[1]]).squaredNorm()});
    if (!(e1.cross(e2).norm() > 1e-9 * longest2)) return who + ": zero area";
    std::array<int32_t, 3> sorted = t;
    std::sort(sorted.begin(), sorted.end());
    if (const auto [it, fresh] = seen.emplace(sorted, i); !fresh)
      return who + ": same vertices as triangle " + std::to_string(it->second);
    for (int k = 0; k < 3; ++k) {
      const uint64_t key = ordered_pair_key(t[k], t[(k + 1) % 3]);
      if (const auto [it, fresh] = directed.emplace(key, i); !fresh)
        return who + ": edge " + std::to_string(t[k]) + "->" + std::to_string(t[(k + 1) % 3]) + " also used by triangle " +
               std::to_string(it->second);
    }
  }
  return "";
}

int triangle_components(std::size_t num_vertices, const std::vector<std::array<int32_t, 3>>& triangles,
                        std::vector<int32_t>* label) {
  std::vector<int32_t> parent(num_vertices);
  for (std::size_t i = 0; i < num_vertices; ++i) parent[i] = static_cast<int32_t>(i);
  auto find = [&](int32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const auto& t : triangles)
    for (int k = 1; k < 3; ++k) {
      const int32_t a = find(t[0]), b = find(t[k]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  std::unordered_map<int32_t, int32_t> id;
  if (label) label->resize(triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const int32_t root = find(triangles[i][0]);
    const auto it = id.emplace(root, static_cast<int32_t>(id.size())).first;
    if (label) (*label)[i] = it->second;
  }
  return static_cast<int>(id.size());
}

}  // namespace palpate
