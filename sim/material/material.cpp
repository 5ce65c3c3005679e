#include "sim/material/material.h"

#include <cmath>
#include <sstream>

namespace palpate {

LatticeCalibration calibrate_lattice(const MaterialSpec& material, double cell_m) {
  LatticeCalibration c;
  double springs_E_Pa = material.young_modulus_Pa;
  const double nu = material.poisson_ratio, e = material.young_modulus_Pa;
  const double mu = e / (2.0 * (1.0 + nu)), lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  const bool volumetric = material.model == MaterialModel::kVolumetric;
  if (material.model == MaterialModel::kNeoHookean || (volumetric && nu < kLatticePoissonRatio)) {
    // a share of mu in the springs (their lambda is that share too), the rest in the cells' Neo-Hookean term; below
    // nu = 1/4 the volumetric model takes this split too (its cell term is, at small strain, the linear solid)
    const double s = volumetric ? kVolumetricSplitSpringShare : kNeoHookeanSpringShare;
    springs_E_Pa = 2.5 * s * mu;
    c.neo_mu_Pa = (1.0 - s) * mu;
    c.neo_lambda_Pa = lambda - s * mu;
    c.poisson_represented = nu;
  } else if (volumetric) {
    // springs for the shear modulus, the volume term for the rest of lambda
    springs_E_Pa = 2.5 * mu;
    c.volume_Pa = lambda - mu;
    c.poisson_represented = nu;
  }
  const double e_l = springs_E_Pa * cell_m;
  c.edge_N_per_m = 7.0 * e_l / 50.0;
  c.diagonal_N_per_m = 3.0 * e_l / 25.0;
  // damping for the whole shear modulus (beta mu l / 9), also where the springs carry only a share of it
  const double damping_E_Pa = material.model == MaterialModel::kSprings ? springs_E_Pa : 2.5 * mu;
  c.damping_Ns_per_m = 2.0 / 45.0 * material.stiffness_damping_s * (damping_E_Pa * cell_m);
  if (material.model == MaterialModel::kSprings && std::abs(material.poisson_ratio - kLatticePoissonRatio) > 1e-9) {
    std::ostringstream s;
    s << "material.poisson_ratio " << material.poisson_ratio << " is not representable: a cubic lattice of central "
      << "springs has nu = 0.25 only (Cauchy relation); Young's modulus " << material.young_modulus_Pa
      << " Pa is matched and the lattice's Poisson ratio is 0.25 (material.model 'volumetric' represents it)";
    c.warning = s.str();
  }
  return c;
}

double self_weight_strain(const MaterialSpec& material, double height_m, double g_m_per_s2) {
  return material.density_kg_per_m3 * std::abs(g_m_per_s2) * height_m / material.young_modulus_Pa;
}

std::string self_weight_warning(const MaterialSpec& material, double height_m, double g_m_per_s2,
                                const std::string& height_said) {
  const double strain = self_weight_strain(material, height_m, g_m_per_s2);
  const bool large = material.model == MaterialModel::kNeoHookean;
  const double limit = large ? 0.3 : 0.1;
  if (!(strain > limit)) return "";
  std::ostringstream s;
  s.precision(3);
  s << "material: under its own weight (lattice.gravity_m_per_s2, " << std::abs(g_m_per_s2) << " m/s^2) the foot of "
    << height_said << " takes a strain rho g H / E = " << strain * 100.0 << " % (rho " << material.density_kg_per_m3
    << " kg/m^3, H " << height_m << " m, E " << material.young_modulus_Pa << " Pa); ";
  if (strain >= 1.0)
    s << "at 100 % or more it cannot carry itself and the lattice folds under it";
  else
    s << "material.model '" << name_of(material.model) << "' is calibrated to " << limit * 100.0 << " % strain"
      << (large ? " (its checked range)" : " (small strain)") << ", so the sag is not the material's";
  s << ": raise young_modulus_Pa, lower density_kg_per_m3 or set lattice.gravity_m_per_s2 to [0, 0, 0]";
  return s.str();
}

double cell_solid_fraction(const GridHierarchy& grid, int32_t index, int level) {
  if (!grid.solid_cell(index, level)) return 0.0;
  const int leaf_level = grid.levels();
  if (level == leaf_level) return grid.leaf_solid_fraction(index);
  // mean over the cell's block of leaf cells
  const int per = 1 << (leaf_level - level);
  const CellCoord c = grid.coord_of(index, level);
  double solid = 0.0;
  for (int k = 0; k < per; ++k)
    for (int j = 0; j < per; ++j)
      for (int i = 0; i < per; ++i)
        solid += grid.leaf_solid_fraction(grid.linear_index({c.i * per + i, c.j * per + j, c.k * per + k}, leaf_level));
  return solid / (static_cast<double>(per) * per * per);
}

double solid_volume_m3(const GridHierarchy& grid) {
  double leaves = 0.0;
  for (int64_t c = 0; c < grid.num_cells(grid.levels()); ++c) leaves += grid.leaf_solid_fraction(static_cast<int32_t>(c));
  return leaves * std::pow(grid.cell_size_m(grid.levels()), 3);
}

}  // namespace palpate
