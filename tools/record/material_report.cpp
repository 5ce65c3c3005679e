#include "tools/record/material_report.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "sim/contact_model_error.h"
#include "sim/material.h"

namespace palpate {

nlohmann::json material_summary(const Scene& scene, const GridHierarchy& grid) {
  const MaterialSpec& m = scene.lattice.material;
  if (!m.enabled) return nullptr;
  const double cell_m = grid.cell_size_m(scene.lattice.level);
  const LatticeCalibration cal = calibrate_lattice(m, cell_m);
  const double volume_m3 = solid_volume_m3(grid);
  // the model error the contact carries: the bench's Hertz calibration read at the scene's tool and cell size
  const ContactModelError err =
      contact_model_error(m, scene.device.sphere_tool, scene.device.tool_radius_m, cell_m);
  const nlohmann::json contact = {
      {"hertz_force_error", err.defined ? nlohmann::json(err.hertz_force_error) : nlohmann::json()},
      {"contact_radius_cells", err.defined ? nlohmann::json(err.contact_radius_cells) : nlohmann::json()},
      {"within_calibration", err.within_calibration},
      {"source", "palpate bench model (Hertz calibration), not measured in this run"},
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

std::string material_warning(const Scene& scene) {
  if (!scene.lattice.material.enabled) return "";
  return calibrate_lattice(scene.lattice.material, 1.0).warning;
}


}  // namespace palpate
