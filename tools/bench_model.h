#pragma once
/// `palpate bench material`: the model's error against the continuum it stands for, per lattice level — uniaxial
/// compression (F = E A d / L), a cantilever's tip deflection (F L^3 / (3 E I)) and Hertz indentation by a rigid
/// sphere (F = 4/3 E* sqrt(R) d^(3/2)), each solved for static equilibrium — beside the cost of one 60 Hz frame of that lattice (symplectic Euler, automatic substeps, and
/// local/global), so speed can be read against model error as `bench sim` reads it against integration error.

#include <string>
#include <vector>

#include "core/result.h"

namespace palpate {

/// What to run. Plain data.
struct BenchMaterialOptions {
  std::vector<int> compression_levels{2, 3, 4, 5};  ///< levels of the 4 cm cube (level 5: 4913 nodes)
  std::vector<int> cantilever_levels{4, 5, 6, 7};   ///< levels of the 8 cm x 1 cm beam (needs >= 4; 7: 5265 nodes)
  std::vector<int> hertz_levels{3, 4, 5};           ///< levels of the indented block (6: 35937 nodes, ~2 min)
  double young_modulus_Pa = 1e5;                     ///< E of every case
  double density_kg_per_m3 = 1070.0;                 ///< rho (sets the frame cost through the stable step)
  double stiffness_damping_s = 2e-4;                 ///< Rayleigh beta (sets the frame cost too)
  int timed_frames = 5;                              ///< frames timed per row, after 2 warm-up frames
  std::string json_path;                             ///< write the rows as JSON here when not empty
};

/// Runs every case; returns the table as text. Errors name the case, its level or the output path.
Result<std::string> run_bench_material(const BenchMaterialOptions& options);

}  // namespace palpate
