#include "runtime/session/model.h"

#include "core/scene_controls.h"

#include <algorithm>
#include <cstdio>
#include <vector>

#include "core/limits.h"
#include "core/mesh_io.h"
#include "sim/lattice/lattice_estimate.h"
#include "sim/solvers/stability.h"

namespace palpate {

Vec3 file_to_world_axes(const Vec3& v, char up_axis) {
  if (up_axis == 'y') return {v.x(), -v.z(), v.y()};
  if (up_axis == 'x') return {v.y(), v.z(), v.x()};
  return v;
}

Result<Model> load_model(const Scene& scene) {
  Model m;
  std::string name = scene.mesh.file;
  if (scene.mesh.file.empty()) {
    m.rest = make_box_mesh(scene.mesh.box_size_m, scene.mesh.box_subdivisions);
    name = "box";
  } else {
    auto mesh = load_mesh(scene.mesh.file);
    if (!mesh) return mesh.error();
    m.rest = std::move(mesh).value();
    if (static_cast<int64_t>(m.rest.triangles.size()) > max_triangles())
      return make_error("mesh '", name, "': ", std::to_string(m.rest.triangles.size()), " triangles, more than the ",
                        triangle_limit_text());
    // contact starts on a face's front: faces wound inward or against their neighbours are turned first
    m.orientation = orient_outward(&m.rest);
  }
  // triangles after subdividing, bounded before any subdivision allocates them
  const int asked = std::max(scene.mesh.subdivisions, 0);
  const auto triangles = static_cast<int64_t>(m.rest.triangles.size()) << (2 * asked);
  if (triangles > max_triangles())
    return make_error("mesh '", name, "': ", std::to_string(m.rest.triangles.size()), " triangles with mesh.subdivisions ",
                      std::to_string(asked), " make ", std::to_string(triangles), ", more than the ", triangle_limit_text());
  for (int i = 0; i < asked; ++i) m.rest = subdivide_midpoint(m.rest);
  for (Vec3& v : m.rest.vertices_m) v = file_to_world_axes(v, scene.mesh.up_axis);
  auto norm = normalize_mesh(&m.rest, scene.mesh.size_m, name);
  if (!norm) return norm.error();
  m.normalization = norm.value();
  auto grid = GridHierarchy::build(m.rest, m.normalization.cube, scene.grid_levels);
  if (!grid) return make_error("mesh '", name, "': ", grid.error().message);
  m.grid = std::move(grid).value();
  // "auto": a mesh file coarser than the lattice's finest cells (touch, pull) is subdivided until it is not, so the
  // surface can dent where the tool presses; the subdivided surface is the same, its grid built again
  const int finest = std::max(scene.lattice.level, scene.lattice.refine.level);
  if (scene.mesh.subdivisions == kAutoSubdivisions && !scene.mesh.file.empty() && scene.mode != InteractionMode::kCut &&
      finest <= m.grid.levels()) {
    const double edge_m = median_longest_edge_m(m.rest);
    m.auto_subdivisions =
        auto_subdivisions(edge_m, m.grid.cell_size_m(finest), static_cast<int64_t>(m.rest.triangles.size()));
    if (m.auto_subdivisions > 0) {
      m.coarse_edge_m = edge_m;
      for (int i = 0; i < m.auto_subdivisions; ++i) m.rest = subdivide_midpoint(m.rest);
      auto fine = GridHierarchy::build(m.rest, m.normalization.cube, scene.grid_levels);
      if (!fine) return make_error("mesh '", name, "': ", fine.error().message);
      m.grid = std::move(fine).value();
    }
  }
  // the lattice the scene can reach, bounded before any lattice or output exists
  if (auto st = check_lattice_limits(m.grid, scene); !st) return make_error("scene '", scene.path, "': ", st.error().message);
  // an explicit scheme that cannot be stable on this material's cells: refused before any lattice or output exists
  if (auto st = check_material_integrator(scene.lattice, m.grid.cell_size_m(scene.lattice.level),
                                          scene.rates.frame_period_s());
      !st)
    return make_error("scene '", scene.path, "': ", st.error().message);
  // a refined lattice indexes its cells at the fine level
  m.bindings = bind_vertices(m.grid, scene.lattice.refine.level > 0 ? scene.lattice.refine.level : scene.lattice.level,
                             m.rest.vertices_m);
  m.leaf_cell_m = m.grid.cell_size_m(m.grid.levels());
  m.adjacency = VertexTriangles::build(m.rest.vertices_m.size(), m.rest.triangles);
  // (asked only in touch, where the tool's side of the surface is checked every tick: O(edges x degree) at load)
  m.closed = scene.mode == InteractionMode::kTouch && closed_surface(m.rest, m.adjacency);
  if (scene.mode == InteractionMode::kTouch && !m.closed) m.part_of = triangle_parts(m.rest, m.adjacency);
  return m;
}

std::vector<int32_t> triangle_parts(const TriMesh& mesh, const VertexTriangles& adjacency) {
  const std::size_t n = mesh.triangles.size();
  std::vector<int32_t> part(n, -1), stack;
  int32_t next = 0;
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (part[seed] >= 0) continue;
    part[seed] = next;
    stack.assign(1, static_cast<int32_t>(seed));
    while (!stack.empty()) {
      const int32_t t = stack.back();
      stack.pop_back();
      for (const int32_t v : mesh.triangles[static_cast<std::size_t>(t)])
        for (int32_t k = adjacency.offsets[static_cast<std::size_t>(v)]; k < adjacency.offsets[static_cast<std::size_t>(v) + 1];
             ++k) {
          const int32_t u = adjacency.triangles[static_cast<std::size_t>(k)];
          if (part[static_cast<std::size_t>(u)] < 0) {
            part[static_cast<std::size_t>(u)] = next;
            stack.push_back(u);
          }
        }
    }
    ++next;
  }
  return part;
}

Status check_control_range(const Scene& scene, const Model& model) {
  Controls stiffest = scene_controls(scene);
  stiffest.stiffness_scale = scene.device.browser_stiffness_hi;
  const Scene s = scene_with_controls(scene, stiffest);
  char key[96];
  std::snprintf(key, sizeof key, "device.browser_stiffness_range: its high end %g", stiffest.stiffness_scale);
  if (auto st = check_material_integrator(s.lattice, model.grid.cell_size_m(s.lattice.level), s.rates.frame_period_s()); !st)
    return make_error("scene '", scene.path, "': ", key, " is not stable: ", st.error().message);
  if (integrator_warning(scene.lattice, scene.rates.frame_period_s()).empty())
    if (const std::string w = integrator_warning(s.lattice, s.rates.frame_period_s()); !w.empty())
      return make_error("scene '", scene.path, "': ", key, " is not stable: ", w);
  return Ok{};
}

double median_longest_edge_m(const TriMesh& mesh) {
  if (mesh.triangles.empty()) return 0.0;
  std::vector<double> edge;
  edge.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const Vec3 &a = mesh.vertices_m[static_cast<std::size_t>(t[0])], &b = mesh.vertices_m[static_cast<std::size_t>(t[1])],
               &c = mesh.vertices_m[static_cast<std::size_t>(t[2])];
    edge.push_back(std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()}));
  }
  const auto mid = edge.begin() + static_cast<std::ptrdiff_t>(edge.size() / 2);
  std::nth_element(edge.begin(), mid, edge.end());
  return *mid;
}

int auto_subdivisions(double median_edge_m, double cell_m, int64_t triangles) {
  int k = 0;
  for (double edge = median_edge_m; edge > kCoarseMeshEdgeCells * cell_m && k < 5 &&
                                    (triangles << (2 * (k + 1))) <= kAutoSubdivisionTriangles;
       edge *= 0.5)
    ++k;
  return k;
}

bool closed_surface(const TriMesh& mesh, const VertexTriangles& adjacency) {
  // each edge from each of its triangles: the triangles at its first vertex that also hold its second
  for (const auto& tri : mesh.triangles)
    for (int c = 0; c < 3; ++c) {
      const int32_t a = tri[c], b = tri[(c + 1) % 3];
      int sharing = 0;
      for (int32_t k = adjacency.offsets[a]; k < adjacency.offsets[a + 1]; ++k) {
        const auto& u = mesh.triangles[static_cast<std::size_t>(adjacency.triangles[k])];
        sharing += u[0] == b || u[1] == b || u[2] == b;
      }
      if (sharing != 2) return false;
    }
  return true;
}

}  // namespace palpate
