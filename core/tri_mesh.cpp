#include "core/tri_mesh.h"

#include "core/pair_key.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <unordered_map>

namespace palpate {

void compute_vertex_normals(const std::vector<Vec3>& vertices_m,
                            const std::vector<std::array<int32_t, 3>>& triangles,
                            std::vector<Vec3>* normals) {
  normals->assign(vertices_m.size(), Vec3::Zero());
  // cross product length is twice the area: area weighting comes for free
  for (const auto& t : triangles) {
    const Vec3 n = (vertices_m[t[1]] - vertices_m[t[0]]).cross(vertices_m[t[2]] - vertices_m[t[0]]);
    for (int c = 0; c < 3; ++c) (*normals)[t[c]] += n;
  }
  for (Vec3& n : *normals) {
    const double len = n.norm();
    if (len > 0.0) n /= len;
  }
}

TriMesh subdivide_midpoint(const TriMesh& mesh) {
  // Every edge gets one midpoint, numbered in the order a walk over the triangles first meets the edge (so the
  // result does not depend on how the edges are found). The edges are found by sorting the triangles' 3 n_t edge
  // slots by their key: no hash map, whose one node per edge dominated a million-triangle mesh's subdivision.
  const std::size_t n_t = mesh.triangles.size();
  struct Slot {
    uint64_t key;
    uint32_t at;  // 3 t + k: edge k of triangle t, (t[k], t[k + 1])
  };
  std::vector<Slot> slots(3 * n_t);
  for (std::size_t t = 0; t < n_t; ++t)
    for (int k = 0; k < 3; ++k) {
      const auto& tri = mesh.triangles[t];
      slots[3 * t + static_cast<std::size_t>(k)] = {unordered_pair_key(tri[k], tri[(k + 1) % 3]),
                                                    static_cast<uint32_t>(3 * t + static_cast<std::size_t>(k))};
    }
  std::sort(slots.begin(), slots.end(),
            [](const Slot& a, const Slot& b) { return a.key != b.key ? a.key < b.key : a.at < b.at; });
  // first[at] = the first slot of at's edge (the walk meets the edge there); each slot names its edge's first
  std::vector<uint32_t> first(3 * n_t);
  for (std::size_t i = 0; i < slots.size();) {
    std::size_t j = i;
    while (j < slots.size() && slots[j].key == slots[i].key) first[slots[j++].at] = slots[i].at;
    i = j;
  }
  TriMesh out;
  out.vertices_m = mesh.vertices_m;
  out.vertices_m.reserve(mesh.vertices_m.size() + slots.size() / 2 + 1);
  out.triangles.reserve(4 * n_t);
  std::vector<int32_t> vertex_of(3 * n_t, -1);  // by the edge's first slot
  auto mid = [&](std::size_t t, int k) {
    const uint32_t f = first[3 * t + static_cast<std::size_t>(k)];
    if (vertex_of[f] < 0) {
      const auto& tri = mesh.triangles[t];
      vertex_of[f] = static_cast<int32_t>(out.vertices_m.size());
      out.vertices_m.push_back(0.5 * (mesh.vertices_m[tri[k]] + mesh.vertices_m[tri[(k + 1) % 3]]));
    }
    return vertex_of[f];
  };
  for (std::size_t i = 0; i < n_t; ++i) {
    const auto& t = mesh.triangles[i];
    const int32_t ab = mid(i, 0), bc = mid(i, 1), ca = mid(i, 2);
    out.triangles.push_back({t[0], ab, ca});
    out.triangles.push_back({ab, t[1], bc});
    out.triangles.push_back({ca, bc, t[2]});
    out.triangles.push_back({ab, bc, ca});
  }
  return out;
}

namespace {

// twice the signed area of the 2D triangle (a, b, c)
double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

// whether p lies inside or on the counter-clockwise triangle (a, b, c)
bool inside(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return cross2(a, b, p) >= 0.0 && cross2(b, c, p) >= 0.0 && cross2(c, a, p) >= 0.0;
}

struct CellKey {
  int64_t x, y, z;
  bool operator==(const CellKey&) const = default;
};

struct CellKeyHash {
  std::size_t operator()(const CellKey& k) const {
    uint64_t h = static_cast<uint64_t>(k.x) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<uint64_t>(k.y) + 0x7F4A7C159E3779B9ull + (h << 6) + (h >> 2);
    h ^= static_cast<uint64_t>(k.z) + 0x94D049BB133111EBull + (h << 6) + (h >> 2);
    // (splitmix64's finish: the table takes the low bits)
    h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
    h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
    return static_cast<std::size_t>(h ^ (h >> 31));
  }
};

}  // namespace

void append_polygon(const std::vector<Vec3>& vertices_m, std::span<const int32_t> polygon,
                    std::vector<std::array<int32_t, 3>>* triangles) {
  const std::size_t n = polygon.size();
  if (n < 3) return;
  if (n == 3) {
    triangles->push_back({polygon[0], polygon[1], polygon[2]});
    return;
  }
  auto fan = [&] {
    for (std::size_t i = 1; i + 1 < n; ++i) triangles->push_back({polygon[0], polygon[i], polygon[i + 1]});
  };
  // Newell's normal: the polygon's area vector, whatever its shape
  Vec3 normal = Vec3::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& a = vertices_m[static_cast<std::size_t>(polygon[i])];
    const Vec3& b = vertices_m[static_cast<std::size_t>(polygon[(i + 1) % n])];
    normal += a.cross(b);
  }
  int drop = 0;
  normal.cwiseAbs().maxCoeff(&drop);
  if (normal[drop] == 0.0 || n > 1024) {
    fan();
    return;
  }
  // projected on the plane of the two other axes, counter-clockwise (the sign of the dropped axis flips it)
  const int u = (drop + 1) % 3, v = (drop + 2) % 3;
  const double sign = normal[drop] > 0.0 ? 1.0 : -1.0;
  std::vector<Eigen::Vector2d> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& q = vertices_m[static_cast<std::size_t>(polygon[i])];
    p[i] = Eigen::Vector2d(q[u], sign * q[v]);
  }
  bool convex = true;
  for (std::size_t i = 0; i < n && convex; ++i) convex = cross2(p[i], p[(i + 1) % n], p[(i + 2) % n]) >= 0.0;
  if (convex) {
    fan();
    return;
  }
  // ear clipping: a corner whose triangle turns left and holds no other corner is cut off, until three are left
  std::vector<std::size_t> left(n);
  for (std::size_t i = 0; i < n; ++i) left[i] = i;
  std::vector<std::array<int32_t, 3>> ears;
  while (left.size() > 3) {
    const std::size_t m = left.size();
    bool cut = false;
    for (std::size_t i = 0; i < m && !cut; ++i) {
      const std::size_t a = left[(i + m - 1) % m], b = left[i], c = left[(i + 1) % m];
      if (cross2(p[a], p[b], p[c]) <= 0.0) continue;
      bool empty = true;
      for (std::size_t k : left)
        if (k != a && k != b && k != c && inside(p[k], p[a], p[b], p[c])) {
          empty = false;
          break;
        }
      if (!empty) continue;
      ears.push_back({polygon[a], polygon[b], polygon[c]});
      left.erase(left.begin() + static_cast<std::ptrdiff_t>(i));
      cut = true;
    }
    if (!cut) {  // self-intersecting or collinear corners: no ear; the fan keeps every corner in some triangle
      fan();
      return;
    }
  }
  triangles->insert(triangles->end(), ears.begin(), ears.end());
  triangles->push_back({polygon[left[0]], polygon[left[1]], polygon[left[2]]});
}

std::size_t weld_vertices(TriMesh* mesh, double tolerance_m) {
  const double tol = std::isfinite(tolerance_m) && tolerance_m > 0.0 ? tolerance_m : 0.0;
  // cells far wider than the tolerance: a vertex's match lies in its own cell but where it is within tol of a face
  // (a few in a thousand), so one cell is looked in, seldom two to eight
  const double cell = tol > 0.0 ? 1024.0 * tol : 1.0;
  std::vector<Vec3>& v = mesh->vertices_m;
  std::vector<int32_t> remap(v.size());
  std::vector<Vec3> kept;
  kept.reserve(v.size());
  std::vector<int32_t> next;  // each kept vertex's predecessor in its cell (-1: the cell's first)
  next.reserve(v.size());
  auto key_of = [&](const Vec3& p) -> CellKey {
    if (tol == 0.0)  // exact: the bit patterns themselves are the key
      return {static_cast<int64_t>(std::bit_cast<uint64_t>(p.x())), static_cast<int64_t>(std::bit_cast<uint64_t>(p.y())),
              static_cast<int64_t>(std::bit_cast<uint64_t>(p.z()))};
    const Eigen::Array3d c = (p / cell).array().floor().cwiseMax(-4e18).cwiseMin(4e18);
    return {static_cast<int64_t>(c.x()), static_cast<int64_t>(c.y()), static_cast<int64_t>(c.z())};
  };
  // open addressing on the cells' keys, each slot the last kept vertex of its cell (its key is that vertex's)
  std::size_t capacity = 16;
  while (capacity < 2 * v.size()) capacity *= 2;
  std::vector<int32_t> slots(capacity, -1);
  auto slot_of = [&](const CellKey& key) {
    std::size_t s = CellKeyHash{}(key) & (capacity - 1);
    while (slots[s] >= 0 && !(key_of(kept[static_cast<std::size_t>(slots[s])]) == key)) s = (s + 1) & (capacity - 1);
    return s;
  };
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Vec3 p = v[i] + Vec3::Zero();  // -0.0 -> +0.0
    if (!p.allFinite()) {  // never welded
      remap[i] = static_cast<int32_t>(kept.size());
      kept.push_back(p);
      next.push_back(-1);
      continue;
    }
    const CellKey key = key_of(p);
    int32_t found = -1;
    auto look = [&](const CellKey& k) {
      for (int32_t at = slots[slot_of(k)]; at >= 0; at = next[static_cast<std::size_t>(at)])
        if ((kept[static_cast<std::size_t>(at)] - p).cwiseAbs().maxCoeff() <= tol && (found < 0 || at < found)) found = at;
    };
    look(key);
    if (tol > 0.0) {
      // the neighbouring cells across the faces p is within tol of, and their edges' and corner's
      int side[3] = {0, 0, 0};
      for (int a = 0; a < 3; ++a) {
        const double f = p[a] / cell - static_cast<double>(a == 0 ? key.x : a == 1 ? key.y : key.z);
        side[a] = f * cell <= tol ? -1 : (1.0 - f) * cell <= tol ? 1 : 0;
      }
      for (int mask = 1; mask < 8; ++mask) {
        if (((mask & 1) && side[0] == 0) || ((mask & 2) && side[1] == 0) || ((mask & 4) && side[2] == 0)) continue;
        look({key.x + ((mask & 1) ? side[0] : 0), key.y + ((mask & 2) ? side[1] : 0), key.z + ((mask & 4) ? side[2] : 0)});
      }
    }
    if (found < 0) {
      found = static_cast<int32_t>(kept.size());
      const std::size_t s = slot_of(key);
      kept.push_back(p);
      next.push_back(slots[s]);
      slots[s] = found;
    }
    remap[i] = found;
  }
  for (auto& t : mesh->triangles)
    for (int32_t& id : t) id = remap[static_cast<std::size_t>(id)];
  const std::size_t merged = v.size() - kept.size();
  v = std::move(kept);
  return merged;
}

}  // namespace palpate
