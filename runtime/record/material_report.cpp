#include "runtime/record/material_report.h"

#include <filesystem>
#include <fstream>
#include <algorithm>
#include <cstdio>
#include <sstream>

#include "sim/contact/contact_model_error.h"
#include "sim/material/material.h"

namespace palpate {

nlohmann::json material_summary(const Scene& scene, const GridHierarchy& grid) {
  const MaterialSpec& m = scene.lattice.material;
  if (!m.enabled) return nullptr;
  const double cell_m = grid.cell_size_m(scene.lattice.level);
  const LatticeCalibration cal = calibrate_lattice(m, cell_m);
  const double volume_m3 = solid_volume_m3(grid);
  // the model error the contact carries: the bench's Hertz calibration read at the scene's tool and cell size
  const ContactModelError err =
      contact_model_error(m, scene.device.sphere_tool, scene.device.tool_radius_m, cell_m, scene.device.solved_contact);
  const nlohmann::json contact = {
      {"hertz_force_error", err.defined ? nlohmann::json(err.hertz_force_error) : nlohmann::json()},
      {"contact_radius_cells", err.defined ? nlohmann::json(err.contact_radius_cells) : nlohmann::json()},
      {"within_calibration", err.within_calibration},
      {"source", scene.device.solved_contact ? "palpate bench model --contact solved (Hertz calibration), not measured in this run"
                                             : "palpate bench model (Hertz calibration), not measured in this run"},
      {"contact", scene.device.solved_contact ? "solved" : "prescribed"},
      {"basis", err.basis}};
  return {{"young_modulus_Pa", m.young_modulus_Pa},
          {"poisson_ratio_asked", m.poisson_ratio},
          {"poisson_ratio_represented", cal.poisson_represented},
          {"density_kg_per_m3", m.density_kg_per_m3},
          {"stiffness_damping_s", m.stiffness_damping_s},
          {"solid_volume_m3", volume_m3},
          {"total_mass_kg", m.density_kg_per_m3 * volume_m3},
          {"level", scene.lattice.level},
          {"cell_m", cell_m},
          {"edge_N_per_m_per_cell", cal.edge_N_per_m},
          {"diagonal_N_per_m_per_cell", cal.diagonal_N_per_m},
          {"spring_damping_Ns_per_m", cal.damping_Ns_per_m},
          {"model", name_of(m.model)},
          {"contact_model_error", contact},
          {"warning", cal.warning}};
}

std::string material_line(const nlohmann::json& m) {
  if (!m.is_object()) return "";
  char text[400];
  std::snprintf(text, sizeof text, "%s, E %g Pa, nu %g (lattice %g), %g kg/m^3, %.3g mm cells",
                m.value("model", "?").c_str(), m.value("young_modulus_Pa", 0.0), m.value("poisson_ratio_asked", 0.0),
                m.value("poisson_ratio_represented", 0.0), m.value("density_kg_per_m3", 0.0),
                1e3 * m.value("cell_m", 0.0));
  std::string line = text;
  const nlohmann::json& c = m.value("contact_model_error", nlohmann::json::object());
  const std::string contact = c.value("contact", "prescribed");
  if (c.contains("hertz_force_error") && c["hertz_force_error"].is_number()) {
    std::snprintf(text, sizeof text, "; contact %s: force %+.0f %% against Hertz at %.2g cells (bench model's "
                  "calibration%s, not this run)", contact.c_str(), 100.0 * c["hertz_force_error"].get<double>(),
                  c.value("contact_radius_cells", 0.0), c.value("within_calibration", false) ? "" : ", nearest row");
    line += text;
  } else {
    line += "; contact " + contact + ": a point load, no Hertz figure";
  }
  return line;
}

std::vector<std::string> material_warnings(const Scene& scene) {
  const MaterialSpec& m = scene.lattice.material;
  if (!m.enabled) return {};
  std::vector<std::string> out;
  if (std::string w = calibrate_lattice(m, 1.0).warning; !w.empty()) out.push_back(std::move(w));
  return out;
}

std::string self_weight_notice(const Scene& scene, const std::vector<Vec3>& rest_vertices_m) {
  const MaterialSpec& m = scene.lattice.material;
  const Vec3& g = scene.lattice.gravity_m_per_s2;
  if (!m.enabled || !(g.norm() > 0.0) || rest_vertices_m.empty()) return "";
  // the body's height along gravity: the rest mesh's extent along g
  const Vec3 down = g.normalized();
  double lo = rest_vertices_m.front().dot(down), hi = lo;
  for (const Vec3& v : rest_vertices_m) {
    lo = std::min(lo, v.dot(down));
    hi = std::max(hi, v.dot(down));
  }
  std::ostringstream said;
  said.precision(3);
  said << "the " << hi - lo << " m tall " << (scene.mesh.file.empty() ? "box" : "model");
  return self_weight_warning(m, hi - lo, g.norm(), said.str());
}

std::string mesh_resolution_notice(const Scene& scene, const TriMesh& rest, const GridHierarchy& grid) {
  if (scene.mode == InteractionMode::kCut || rest.triangles.empty()) return "";
  const int finest = std::max(scene.lattice.level, scene.lattice.refine.level);
  const double cell_m = grid.cell_size_m(finest);
  const double median_m = median_longest_edge_m(rest);
  if (!(median_m > kCoarseMeshEdgeCells * cell_m)) return "";
  std::ostringstream s;
  s.precision(3);
  s << "mesh: its triangles (median longest edge " << 1e3 * median_m << " mm) are coarser than the lattice's finest cells ("
    << 1e3 * cell_m << " mm at level " << finest << "): the surface the tool meets moves only at the triangles' corners, "
    << "so the finer cells add cost, not accuracy, and a push lands on the corners of the triangle it meets (a point "
    << "tool's force then depends on where on the triangle it presses); use a mesh with edges under "
    << 1e3 * kCoarseMeshEdgeCells * cell_m << " mm (a box: mesh.box_subdivisions) or a coarser lattice level";
  return s.str();
}

}  // namespace palpate
