// GridHierarchy's leaf solid fractions: how much of each leaf cell crossed by the surface lies inside the mesh.

#include <algorithm>
#include <cmath>

#include "core/grid_hierarchy.h"

namespace palpate {
namespace {

// Lines per leaf along each of y and z; the offsets are nudged off the cell's centre lines so that a line does not
// run through the edges and vertices of grid-aligned meshes (a crossing counted twice would flip the parity).
constexpr int kLinesPerAxis = 4;
constexpr double kNudge = 0.0123;

// x where the line {(x, y, z)} crosses triangle (a, b, c), if it does (projection onto yz contains (y, z)).
bool crossing_x(const Vec3& a, const Vec3& b, const Vec3& c, double y, double z, double* x) {
  const double d = (b.y() - a.y()) * (c.z() - a.z()) - (c.y() - a.y()) * (b.z() - a.z());
  if (d == 0.0) return false;  // triangle parallel to x
  const double u = ((y - a.y()) * (c.z() - a.z()) - (c.y() - a.y()) * (z - a.z())) / d;
  const double v = ((b.y() - a.y()) * (z - a.z()) - (y - a.y()) * (b.z() - a.z())) / d;
  if (u < 0.0 || v < 0.0 || u + v > 1.0) return false;
  *x = a.x() + u * (b.x() - a.x()) + v * (c.x() - a.x());
  return true;
}

}  // namespace

double GridHierarchy::leaf_solid_fraction(int32_t leaf) const {
  return static_cast<double>(leaf_solid_fraction_[static_cast<std::size_t>(leaf)]);
}

void GridHierarchy::build_solid_fractions(const TriMesh& mesh) {
  const int n = cells_per_axis(levels_);
  const std::vector<uint8_t>& solid = solid_[static_cast<std::size_t>(levels_ - 1)];
  const std::vector<uint8_t>& surface = surface_[static_cast<std::size_t>(levels_ - 1)];
  leaf_solid_fraction_.assign(solid.size(), 0.0f);
  for (std::size_t c = 0; c < solid.size(); ++c) leaf_solid_fraction_[c] = solid[c] ? 1.0f : 0.0f;
  if (mesh.triangles.empty()) return;
  const double l = cell_size_m(levels_);
  const Vec3 o = cube_.min_m;
  std::vector<int32_t> tris;
  std::vector<std::vector<double>> xs(kLinesPerAxis * kLinesPerAxis);  // crossings of each line of a row
  std::vector<double> inside(static_cast<std::size_t>(n));  // inside length per leaf of the row, summed over lines
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j) {
      // rows (lines of leaves along x) with a surface leaf: their triangles, then kLinesPerAxis^2 lines through them
      bool any = false;
      for (int i = 0; i < n && !any; ++i) any = surface[static_cast<std::size_t>(linear_index({i, j, k}, levels_))] != 0;
      if (!any) continue;
      tris.clear();
      for (int i = 0; i < n; ++i) {
        const std::span<const int32_t> ids = leaf_triangles(linear_index({i, j, k}, levels_));
        tris.insert(tris.end(), ids.begin(), ids.end());
      }
      std::sort(tris.begin(), tris.end());
      tris.erase(std::unique(tris.begin(), tris.end()), tris.end());
      std::fill(inside.begin(), inside.end(), 0.0);
      // crossings per line; a triangle is tested only against the lines its yz bounds reach
      for (auto& v : xs) v.clear();
      const auto line_y = [&](int sy) { return o.y() + l * (j + (sy + 0.5 + kNudge) / kLinesPerAxis); };
      const auto line_z = [&](int sz) { return o.z() + l * (k + (sz + 0.5 + 2.0 * kNudge) / kLinesPerAxis); };
      for (int32_t t : tris) {
        const auto& tri = mesh.triangles[static_cast<std::size_t>(t)];
        const Vec3& a = mesh.vertices_m[tri[0]];
        const Vec3& b = mesh.vertices_m[tri[1]];
        const Vec3& c = mesh.vertices_m[tri[2]];
        const double ylo = std::min({a.y(), b.y(), c.y()}), yhi = std::max({a.y(), b.y(), c.y()});
        const double zlo = std::min({a.z(), b.z(), c.z()}), zhi = std::max({a.z(), b.z(), c.z()});
        double x = 0.0;
        for (int sz = 0; sz < kLinesPerAxis; ++sz) {
          const double z = line_z(sz);
          if (z < zlo || z > zhi) continue;
          for (int sy = 0; sy < kLinesPerAxis; ++sy) {
            const double y = line_y(sy);
            if (y >= ylo && y <= yhi && crossing_x(a, b, c, y, z, &x)) xs[static_cast<std::size_t>(sy + kLinesPerAxis * sz)].push_back(x);
          }
        }
      }
      for (auto& line : xs) {
        std::sort(line.begin(), line.end());
        const bool closed = line.size() % 2 == 0;
        for (int i = 0; i < n; ++i) {
          const double lo = o.x() + l * i, hi = lo + l;
          if (!closed) {
            inside[static_cast<std::size_t>(i)] += l;  // unknown: count the cell whole
            continue;
          }
          for (std::size_t p = 0; p + 1 < line.size(); p += 2)
            inside[static_cast<std::size_t>(i)] += std::max(0.0, std::min(hi, line[p + 1]) - std::max(lo, line[p]));
        }
      }
      for (int i = 0; i < n; ++i) {
        const auto leaf = static_cast<std::size_t>(linear_index({i, j, k}, levels_));
        if (surface[leaf])
          leaf_solid_fraction_[leaf] =
              static_cast<float>(std::clamp(inside[static_cast<std::size_t>(i)] / (l * kLinesPerAxis * kLinesPerAxis), 0.0, 1.0));
      }
    }
}

}  // namespace palpate
