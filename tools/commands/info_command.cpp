#include "tools/commands/info_command.h"

#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "core/aabb.h"
#include "core/binding.h"
#include "core/grid_hierarchy.h"
#include "core/mesh_io.h"
#include "core/mesh_orientation.h"

namespace palpate {

int run_info(const std::string& path, int levels, bool json) {
  auto mesh_r = load_mesh(path);
  if (!mesh_r) {
    std::fprintf(stderr, "palpate: %s\n", mesh_r.error().message.c_str());
    return 1;
  }
  TriMesh mesh = std::move(mesh_r).value();
  // as a scene loads it: faces turned outward
  const MeshOrientation turned = orient_outward(&mesh);
  const Aabb raw = Aabb::of(mesh.vertices_m);
  auto norm = normalize_mesh(&mesh, 1.0, path);
  if (!norm) {
    std::fprintf(stderr, "palpate: %s\n", norm.error().message.c_str());
    return 1;
  }
  auto grid_r = GridHierarchy::build(mesh, norm.value().cube, levels);
  if (!grid_r) {
    std::fprintf(stderr, "palpate: mesh '%s': %s\n", path.c_str(), grid_r.error().message.c_str());
    return 1;
  }
  const GridHierarchy& grid = grid_r.value();
  nlohmann::json j;
  j["mesh"] = path;
  j["vertices"] = mesh.num_vertices();
  j["triangles"] = mesh.num_triangles();
  j["parts"] = turned.components;
  j["closed_parts"] = turned.closed_components;
  j["triangles_turned"] = turned.triangles_flipped;
  if (!turned.notice().empty()) j["orientation"] = turned.notice();
  j["box_min"] = {raw.min_m.x(), raw.min_m.y(), raw.min_m.z()};
  j["box_max"] = {raw.max_m.x(), raw.max_m.y(), raw.max_m.z()};
  j["normalization_scale"] = norm.value().scale;
  j["levels"] = nlohmann::json::array();
  for (int l = 1; l <= grid.levels(); ++l) {
    // every vertex is bound at every level; report how many distinct cells hold vertices
    const auto b = bind_vertices(grid, l, mesh.vertices_m);
    std::vector<uint8_t> holds(static_cast<std::size_t>(grid.num_cells(l)), 0);
    for (const auto& vb : b) holds[static_cast<std::size_t>(vb.cell)] = 1;
    int64_t vertex_cells = 0;
    for (uint8_t h : holds) vertex_cells += h;
    j["levels"].push_back({{"level", l},
                           {"cells_per_axis", grid.cells_per_axis(l)},
                           {"cells", grid.num_cells(l)},
                           {"occupied_cells", grid.surface_cells(l)},
                           {"solid_cells", grid.solid_cells(l)},
                           {"cells_with_vertices", vertex_cells},
                           {"bound_vertices", b.size()},
                           {"cell_size_rel", grid.cell_size_m(l)}});
  }
  if (json) {
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::printf("mesh       %s\n", path.c_str());
  std::printf("vertices   %zu\ntriangles  %zu\n", mesh.num_vertices(), mesh.num_triangles());
  std::printf("parts      %lld (%lld closed)\n", static_cast<long long>(turned.components),
              static_cast<long long>(turned.closed_components));
  if (!turned.notice().empty()) std::printf("faces      %s\n", turned.notice().c_str());
  std::printf("box        [%.6g, %.6g, %.6g] .. [%.6g, %.6g, %.6g] (extent %.6g x %.6g x %.6g)\n", raw.min_m.x(),
              raw.min_m.y(), raw.min_m.z(), raw.max_m.x(), raw.max_m.y(), raw.max_m.z(), raw.extent().x(),
              raw.extent().y(), raw.extent().z());
  std::printf("\n%5s %8s %10s %10s %10s %12s %10s\n", "level", "per_axis", "cells", "occupied", "solid", "vertex_cells",
              "bound_v");
  for (const auto& l : j["levels"])
    std::printf("%5d %8d %10lld %10lld %10lld %12lld %10zu\n", l["level"].get<int>(), l["cells_per_axis"].get<int>(),
                l["cells"].get<long long>(), l["occupied_cells"].get<long long>(), l["solid_cells"].get<long long>(),
                l["cells_with_vertices"].get<long long>(), l["bound_vertices"].get<std::size_t>());
  return 0;
}

}  // namespace palpate
