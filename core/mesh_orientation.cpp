#include "core/mesh_orientation.h"

#include <cmath>
#include <utility>
#include <vector>


namespace palpate {
namespace {

using Tri = std::array<int32_t, 3>;

// Each triangle's neighbour across each of its edges, found vertex by vertex: the corners around a vertex (every
// triangle holding it, with the vertices after and before it in that triangle's winding) are listed together, and
// an edge's other triangle is among its first vertex's corners. So the triangles themselves are read in their own
// order, and each vertex's corners once, together: on a model of millions of triangles in no spatial order, a walk
// reading each neighbour's corners would miss the cache on every edge.
// across[3 t + e], for the edge from corner e of t to the next: 2 u + 1 when u runs the other way (the two agree),
// 2 u when u runs the same way, kOpen for an open edge, kNonManifold for one of more than two triangles.
constexpr int32_t kOpen = -1, kNonManifold = -2;
std::vector<int32_t> neighbours(std::size_t vertices, const std::vector<Tri>& tris) {
  struct Corner {
    int32_t tri_corner;  // 4 t + e (t < 2^29)
    int32_t next, prev;
  };
  std::vector<int64_t> offsets(vertices + 1, 0);
  for (const Tri& t : tris)
    for (int32_t v : t) ++offsets[static_cast<std::size_t>(v) + 1];
  for (std::size_t v = 0; v < vertices; ++v) offsets[v + 1] += offsets[v];
  std::vector<Corner> around(3 * tris.size());
  {
    std::vector<int64_t> at(offsets.begin(), offsets.end() - 1);
    for (std::size_t t = 0; t < tris.size(); ++t)
      for (int c = 0; c < 3; ++c) {
        const Tri& tr = tris[t];
        around[static_cast<std::size_t>(at[static_cast<std::size_t>(tr[c])]++)] = {
            static_cast<int32_t>(4 * t + static_cast<std::size_t>(c)), tr[(c + 1) % 3], tr[(c + 2) % 3]};
      }
  }
  std::vector<int32_t> across(3 * tris.size(), kOpen);
  for (std::size_t a = 0; a < vertices; ++a) {
    const auto begin = static_cast<std::size_t>(offsets[a]), end = static_cast<std::size_t>(offsets[a + 1]);
    for (std::size_t i = begin; i < end; ++i) {
      const Corner& c = around[i];
      const int32_t t = c.tri_corner >> 2, b = c.next;
      int32_t found = kOpen;
      bool same = false;
      for (std::size_t j = begin; j < end; ++j) {
        const Corner& o = around[j];
        const int32_t u = o.tri_corner >> 2;
        if (u == t || u == found || (o.next != b && o.prev != b)) continue;
        if (found >= 0) {
          found = kNonManifold;
          break;
        }
        found = u;
        same = o.next == b;
      }
      across[3 * static_cast<std::size_t>(t) + static_cast<std::size_t>(c.tri_corner & 3)] =
          found >= 0 ? 2 * found + (same ? 0 : 1) : found;
    }
  }
  return across;
}

// the triangle's corners, in its winding or reversed
std::array<Vec3, 3> corners(const TriMesh& m, int32_t t, bool reversed) {
  const Tri& tr = m.triangles[static_cast<std::size_t>(t)];
  const Vec3& a = m.vertices_m[static_cast<std::size_t>(tr[0])];
  const Vec3& b = m.vertices_m[static_cast<std::size_t>(tr[1])];
  const Vec3& c = m.vertices_m[static_cast<std::size_t>(tr[2])];
  return reversed ? std::array<Vec3, 3>{a, c, b} : std::array<Vec3, 3>{a, b, c};
}

// whether the ray from p along d crosses triangle (a, b, c) ahead of p (either side)
bool ray_crosses(const Vec3& p, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 h = d.cross(e2);
  const double det = e1.dot(h);
  if (det == 0.0) return false;
  const Vec3 s = p - a;
  const double u = s.dot(h) / det;
  if (u < 0.0 || u > 1.0) return false;
  const Vec3 q = s.cross(e1);
  const double v = d.dot(q) / det;
  if (v < 0.0 || u + v > 1.0) return false;
  return e2.dot(q) / det > 0.0;
}

// one part: its triangles' range in the walk's order, whether it is closed and whether its windings agree
struct Part {
  std::size_t begin = 0, end = 0;
  bool closed = true;
  bool orientable = true;
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);  // the part's box

  // whether other's box lies within this one's
  bool holds_box(const Part& other) const {
    return (lo.array() <= other.lo.array()).all() && (hi.array() >= other.hi.array()).all();
  }
};

}  // namespace

std::string MeshOrientation::notice() const {
  if (triangles_flipped == 0 && not_orientable == 0) return "";
  std::string s;
  if (triangles_flipped > 0) {
    s = "turned " + std::to_string(triangles_flipped) + " of " + std::to_string(triangles) + " triangles outward:";
    std::string sep = " ";
    if (turned_inside_out > 0) {
      s += sep + std::to_string(turned_inside_out) + " closed part" + (turned_inside_out > 1 ? "s" : "") +
           " wound inside out";
      sep = "; ";
    }
    if (made_consistent > 0)
      s += sep + std::to_string(made_consistent) + " part" + (made_consistent > 1 ? "s" : "") +
           " with faces wound against their neighbours across shared edges";
  }
  if (not_orientable > 0)
    s += std::string(s.empty() ? "" : "; ") + std::to_string(not_orientable) + " part" +
         (not_orientable > 1 ? "s" : "") + " left as read (no winding agrees across all its edges)";
  return s;
}

MeshOrientation orient_outward(TriMesh* mesh) {
  MeshOrientation r;
  const std::vector<Tri>& tris = mesh->triangles;
  const auto n = static_cast<int32_t>(tris.size());
  r.triangles = n;
  // (none, or more than the corners' numbering holds: core/limits.h's max_triangles() refuses such a model)
  if (n == 0 || static_cast<int64_t>(n) > (int64_t{1} << 29)) return r;
  const std::vector<int32_t> across = neighbours(mesh->vertices_m.size(), tris);

  // walk each part across its manifold edges: flip[u] makes u run against its neighbour t along their edge
  std::vector<int32_t> part_of(static_cast<std::size_t>(n), -1), order;
  std::vector<uint8_t> flip(static_cast<std::size_t>(n), 0);
  std::vector<Part> parts;
  order.reserve(static_cast<std::size_t>(n));
  for (int32_t seed = 0; seed < n; ++seed) {
    if (part_of[static_cast<std::size_t>(seed)] >= 0) continue;
    Part p;
    p.begin = order.size();
    const auto id = static_cast<int32_t>(parts.size());
    part_of[static_cast<std::size_t>(seed)] = id;
    order.push_back(seed);
    for (std::size_t q = p.begin; q < order.size(); ++q) {
      const int32_t t = order[q];
      for (int e = 0; e < 3; ++e) {
        const int32_t nb = across[3 * static_cast<std::size_t>(t) + static_cast<std::size_t>(e)];
        // an open or non-manifold edge is not walked, and the part has no inside of its own
        if (nb < 0) {
          p.closed = false;
          continue;
        }
        const int32_t u = nb >> 1;
        const uint8_t want = flip[static_cast<std::size_t>(t)] ^ ((nb & 1) ? 0 : 1);
        if (part_of[static_cast<std::size_t>(u)] < 0) {
          part_of[static_cast<std::size_t>(u)] = id;
          flip[static_cast<std::size_t>(u)] = want;
          order.push_back(u);
        } else if (flip[static_cast<std::size_t>(u)] != want) {
          p.orientable = false;
        }
      }
    }
    p.end = order.size();
    parts.push_back(p);
  }
  r.components = static_cast<int64_t>(parts.size());
  // the parts' boxes, and below their volumes and areas, summed over the triangles in their own order (the walk's
  // order jumps about a large model's arrays)
  for (int32_t t = 0; t < n; ++t) {
    Part& p = parts[static_cast<std::size_t>(part_of[static_cast<std::size_t>(t)])];
    for (int32_t v : tris[static_cast<std::size_t>(t)]) {
      p.lo = p.lo.cwiseMin(mesh->vertices_m[static_cast<std::size_t>(v)]);
      p.hi = p.hi.cwiseMax(mesh->vertices_m[static_cast<std::size_t>(v)]);
    }
  }

  // a closed part nested in an odd number of other closed parts is a cavity's wall: it faces into the cavity
  std::vector<int32_t> closed_ids;
  for (std::size_t i = 0; i < parts.size(); ++i)
    if (parts[i].closed) closed_ids.push_back(static_cast<int32_t>(i));
  r.closed_components = static_cast<int64_t>(closed_ids.size());
  std::vector<uint8_t> cavity(parts.size(), 0);
  if (closed_ids.size() > 1 && static_cast<int64_t>(closed_ids.size()) <= kMaxNestedParts) {
    const Vec3 dir = Vec3(0.5773, 0.5774, 0.5775).normalized();  // off every axis and diagonal
    for (int32_t i : closed_ids) {
      const Part& inner = parts[static_cast<std::size_t>(i)];
      const Vec3 p = mesh->vertices_m[static_cast<std::size_t>(tris[static_cast<std::size_t>(order[inner.begin])][0])];
      int depth = 0;
      for (int32_t j : closed_ids) {
        const Part& outer = parts[static_cast<std::size_t>(j)];
        if (j == i || !outer.holds_box(inner)) continue;
        int crossings = 0;
        for (std::size_t q = outer.begin; q < outer.end; ++q) {
          const auto c = corners(*mesh, order[q], false);
          crossings += ray_crosses(p, dir, c[0], c[1], c[2]) ? 1 : 0;
        }
        depth += crossings % 2;
      }
      cavity[static_cast<std::size_t>(i)] = static_cast<uint8_t>(depth % 2);
    }
  }

  // the winding the walk agreed on, or its reverse: a closed part by its volume's sign, an open one by the larger
  // area already wound that way
  std::vector<double> volume(parts.size(), 0.0), area_kept(parts.size(), 0.0), area_flipped(parts.size(), 0.0);
  for (int32_t t = 0; t < n; ++t) {
    const auto i = static_cast<std::size_t>(part_of[static_cast<std::size_t>(t)]);
    if (!parts[i].orientable) continue;
    const Vec3 o = 0.5 * (parts[i].lo + parts[i].hi);
    const bool flipped = flip[static_cast<std::size_t>(t)] != 0;
    const auto c = corners(*mesh, t, flipped);
    volume[i] += (c[0] - o).dot((c[1] - o).cross(c[2] - o));
    (flipped ? area_flipped[i] : area_kept[i]) += (c[1] - c[0]).cross(c[2] - c[0]).norm();
  }
  std::vector<uint8_t> reverse(parts.size(), 0);
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const Part& p = parts[i];
    if (!p.orientable) {
      ++r.not_orientable;
      continue;
    }
    r.cavities += cavity[i];
    reverse[i] = p.closed ? (cavity[i] ? volume[i] > 0.0 : volume[i] < 0.0) : area_flipped[i] > area_kept[i];
  }
  std::vector<int64_t> flipped(parts.size(), 0);
  for (int32_t t = 0; t < n; ++t) {
    const auto i = static_cast<std::size_t>(part_of[static_cast<std::size_t>(t)]);
    uint8_t& f = flip[static_cast<std::size_t>(t)];
    f = parts[i].orientable ? static_cast<uint8_t>(f ^ reverse[i]) : uint8_t{0};
    flipped[i] += f;
  }
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (!parts[i].orientable) continue;
    r.triangles_flipped += flipped[i];
    if (flipped[i] == static_cast<int64_t>(parts[i].end - parts[i].begin))
      ++r.turned_inside_out;
    else if (flipped[i] > 0)
      ++r.made_consistent;
  }
  for (int32_t t = 0; t < n; ++t)
    if (flip[static_cast<std::size_t>(t)]) std::swap(mesh->triangles[static_cast<std::size_t>(t)][1], mesh->triangles[static_cast<std::size_t>(t)][2]);
  return r;
}

}  // namespace palpate
