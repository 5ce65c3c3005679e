#include "sim/contact/contact_load.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "sim/lattice/deformer.h"

namespace palpate {
namespace {

// Unit normal of rest triangle `tri` (non-finite for a degenerate one).
Vec3 rest_normal(const TriMesh& mesh, int32_t tri) {
  const auto& t = mesh.triangles[static_cast<std::size_t>(tri)];
  const Vec3& a0 = mesh.vertices_m[t[0]];
  return (mesh.vertices_m[t[1]] - a0).cross(mesh.vertices_m[t[2]] - a0).normalized();
}

}  // namespace

Vec3 surface_point(const std::vector<Vec3>& vertices_m, const std::array<int32_t, 3>& tri, const Vec3& bary) {
  Vec3 p = Vec3::Zero();
  for (int c = 0; c < 3; ++c) p += bary[c] * vertices_m[tri[c]];
  return p;
}

PointWeights point_weights(const Lattice& lat, const RestObject& rest, int32_t tri_id, const Vec3& bary) {
  PointWeights w;
  const auto& tri = rest.mesh->triangles[static_cast<std::size_t>(tri_id)];
  for (int c = 0; c < 3; ++c) {
    const VertexBinding& b = (*rest.bindings)[static_cast<std::size_t>(tri[c])];
    const int32_t slot = lat.slot_of_cell[b.cell];
    if (slot < 0) continue;
    // a refined lattice's coarse cell spans several cells of the binding's level: local coordinates in it
    const auto tw = trilinear_weights(lat.cell_span.empty() ? b.local
                                                            : lat.local_in_cell(static_cast<std::size_t>(slot),
                                                                                rest.mesh->vertices_m[tri[c]]));
    for (int k = 0; k < 8; ++k) {
      w.node[w.count] = lat.cell_nodes[slot][k];
      w.weight[w.count] = bary[c] * tw[k];
      ++w.count;
    }
  }
  return w;
}

PointWeights hertz_patch_weights(const Lattice& lat, const RestObject& rest, const ToolContact& c) {
  const double radius = c.radius_m;
  const auto& tri = rest.mesh->triangles[static_cast<std::size_t>(c.tri)];
  const Vec3& a0 = rest.mesh->vertices_m[tri[0]];
  const Vec3 n = rest_normal(*rest.mesh, c.tri);
  PointWeights w;
  if (!n.allFinite()) return w;
  // the patch is centred under the sphere's centre (its foot on the contact face's rest plane), not on the
  // servo's nearest surface point, which wanders over a patch the sphere has pressed into its own shape
  const double height = (c.centre_m - a0).dot(n);
  const Vec3 centre = c.centre_m - height * n;
  // depth of the sphere's lowest point below the rest surface, and the contact radius it gives
  const double depth = std::clamp(radius - height, 0.0, radius);
  const double a = std::sqrt(radius * depth);
  // the rings' orientation from a world axis, not the triangle: the same patch whichever triangle at a shared
  // vertex or edge holds the contact point this frame
  const Vec3 axis = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 t1 = (axis - axis.dot(n) * n).normalized(), t2 = n.cross(t1);
  const int level = lat.level;
  const double cell = lat.cell_m;
  // a hair inside the surface, so a sample on a face that lies on a cell plane lands in the solid cell
  const Vec3 in = -1e-3 * cell * n;
  double total = 0.0;
  auto sample = [&](const Vec3& p, double weight) {
    const int32_t slot = lat.slot_of_cell[rest.grid->linear_index(rest.grid->cell_of(p, level), level)];
    if (slot < 0 || !(weight > 0.0)) return;
    const auto& nodes = lat.cell_nodes[static_cast<std::size_t>(slot)];
    const auto tw = trilinear_weights(lat.local_in_cell(static_cast<std::size_t>(slot), p));
    for (int k = 0; k < 8; ++k)
      if (!w.add(nodes[k], weight * tw[k])) return;
    total += weight;
  };
  // rings of samples, kRings annuli of equal width, each sample carrying pressure x its share of the area
  constexpr int kRings = 6;
  constexpr double kPi = std::numbers::pi;
  const double h = a / (kRings + 0.5);
  sample(centre + in, 0.25 * h * h * kPi);
  for (int k = 1; k <= kRings && a > 0.0; ++k) {
    const double rho = k * h;
    const int count = 6 * k;
    const double share = 2.0 * kPi * rho * h / count;
    const double pressure = std::sqrt(std::max(0.0, 1.0 - rho * rho / (a * a)));
    for (int j = 0; j < count; ++j) {
      const double phi = 2.0 * kPi * (j + 0.5 * (k % 2)) / count;
      sample(centre + in + rho * (std::cos(phi) * t1 + std::sin(phi) * t2), share * pressure);
    }
  }
  if (!(total > 0.0)) return point_weights(lat, rest, c.tri, c.bary);
  for (int i = 0; i < w.count; ++i) w.weight[i] /= total;
  return w;
}

Vec3 contact_patch_centre(const RestObject& rest, const ToolContact& c) {
  const auto& tri = rest.mesh->triangles[static_cast<std::size_t>(c.tri)];
  const Vec3 n = rest_normal(*rest.mesh, c.tri);
  if (!c.sphere || !n.allFinite()) return surface_point(rest.mesh->vertices_m, tri, c.bary);
  return c.centre_m - (c.centre_m - rest.mesh->vertices_m[tri[0]]).dot(n) * n;
}

PointWeights contact_load_weights(const Lattice& lat, const RestObject& rest, const ToolContact& c) {
  return c.sphere ? hertz_patch_weights(lat, rest, c) : point_weights(lat, rest, c.tri, c.bary);
}

Vec3 object_force(const RestObject& rest, const ToolContact& c, const Vec3& reaction_N) {
  if (!c.sphere || c.tri < 0) return reaction_N;
  const Vec3 n = rest_normal(*rest.mesh, c.tri);
  return n.allFinite() ? Vec3(n.dot(reaction_N) * n) : reaction_N;
}

}  // namespace palpate
