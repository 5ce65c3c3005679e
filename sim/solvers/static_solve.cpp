#include "sim/solvers/static_solve.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "sim/lattice/forces.h"
#include "sim/solvers/free_coords.h"
#include "sim/lattice/hanging.h"
#include "sim/material/neo_hookean_term.h"
#include "sim/material/volume_term.h"

namespace palpate {

std::vector<Vec3> spring_forces_N(const Lattice& lat, const std::vector<Vec3>& x_m) {
  std::vector<Vec3> f(lat.num_nodes(), Vec3::Zero());
  for (const Spring& s : lat.springs) {
    const Vec3 fa = spring_force_on_a(s, x_m[s.b] - x_m[s.a]);
    f[s.a] += fa;
    f[s.b] -= fa;
  }
  add_volume_forces(lat, x_m, &f);
  add_neo_hookean_forces(lat, x_m, &f);
  return f;
}

void add_stiffness_triplets(const Lattice& lat, const std::vector<int>& col, std::vector<Eigen::Triplet<double>>* trip,
                            bool clamp_compression) {
  std::vector<std::array<Vec3, 8>> cell_c;
  std::vector<double> cell_w;
  std::vector<NeoHookeanCell> neo;
  for (const Spring& s : lat.springs) {
    const Mat3 blk = spring_stiffness_block(s, lat.x_m[s.b] - lat.x_m[s.a], clamp_compression);
    const int32_t ends[2] = {s.a, s.b};
    for (int p = 0; p < 2; ++p)
      for (int q = 0; q < 2; ++q) {
        const double sign = p == q ? 1.0 : -1.0;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            const int ri = col[3 * static_cast<std::size_t>(ends[p]) + i];
            const int cj = col[3 * static_cast<std::size_t>(ends[q]) + j];
            if (ri >= 0 && cj >= 0) trip->emplace_back(ri, cj, sign * blk(i, j));
          }
      }
  }
  // the cells' volume terms: Gauss-Newton blocks w c_a c_b^T
  if (lat.volume_Pa != 0.0) {
    volume_gradients(lat, lat.x_m, &cell_c, &cell_w);
    for (std::size_t cell = 0; cell < cell_c.size(); ++cell)
      for (int p = 0; p < 8; ++p)
        for (int q = 0; q < 8; ++q) {
          const Mat3 blk = cell_w[cell] * cell_c[cell][p] * cell_c[cell][q].transpose();
          const auto np = static_cast<std::size_t>(lat.cell_nodes[cell][p]), nq = static_cast<std::size_t>(lat.cell_nodes[cell][q]);
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
              const int ri = col[3 * np + i], cj = col[3 * nq + j];
              if (ri >= 0 && cj >= 0) trip->emplace_back(ri, cj, blk(i, j));
            }
        }
  }
  // the cells' Neo-Hookean terms: their tangent blocks
  if (lat.neo_mu_Pa != 0.0) {
    neo_hookean_cells(lat, lat.x_m, &neo);
    for (std::size_t cell = 0; cell < neo.size(); ++cell)
      for (int p = 0; p < 8; ++p)
        for (int q = 0; q < 8; ++q) {
          const Mat3 blk = neo_hookean_block(lat, neo[cell], p, q);
          const auto np = static_cast<std::size_t>(lat.cell_nodes[cell][p]), nq = static_cast<std::size_t>(lat.cell_nodes[cell][q]);
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
              const int ri = col[3 * np + i], cj = col[3 * nq + j];
              if (ri >= 0 && cj >= 0) trip->emplace_back(ri, cj, blk(i, j));
            }
        }
  }
}

Result<StaticReport> solve_static(Lattice* lat, const std::vector<uint8_t>& held_dof, const std::vector<Vec3>& f_ext_N,
                                  const StaticOptions& options) {
  const std::size_t n = lat->num_nodes();
  const FreeCoords fc = free_coords(*lat, held_dof);
  const int free = fc.free;
  StaticReport rep;
  if (free == 0) return rep;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                           Eigen::IncompleteCholesky<double>> cg;
  cg.setTolerance(options.cg_tolerance);
  cg.setMaxIterations(20000);
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::VectorXd r(free), dx(free);
  spread_hanging(*lat, &lat->x_m);
  for (int it = 0; it <= options.max_iterations; ++it) {
    // residual: spring + gravity + external force on the free DOFs
    std::vector<Vec3> f = spring_forces_N(*lat, lat->x_m);
    for (std::size_t i = 0; i < n; ++i) {
      f[i] += lat->mass_kg[i] * lat->gravity_m_per_s2;
      if (!f_ext_N.empty()) f[i] += f_ext_N[i];
    }
    reduce_forces(*lat, fc, &f, &r);
    rep.max_residual_N = r.cwiseAbs().maxCoeff();
    if (it > 0 && dx.cwiseAbs().maxCoeff() < options.step_tol_m) return rep;
    if (it == options.max_iterations) break;
    // tangent stiffness K (f(x + dx) ~ f(x) - K dx), assembled over the DOFs not held, reduced to the free ones
    trip.clear();
    add_stiffness_triplets(*lat, fc.col, &trip);
    Eigen::SparseMatrix<double> assembled(fc.assembled(), fc.assembled());
    assembled.setFromTriplets(trip.begin(), trip.end());
    const Eigen::SparseMatrix<double> k = reduce_stiffness(fc, std::move(assembled));
    if (options.iterative) {
      cg.compute(k);
      dx = cg.solve(r);
      if (cg.info() != Eigen::Success || !dx.allFinite())
        return make_error("static solve: conjugate gradients did not converge (", std::to_string(free), " free DOFs, ",
                          std::to_string(cg.iterations()), " iterations, error ", std::to_string(cg.error()),
                          ") at Newton step ", std::to_string(it));
      move_free(fc, lat->x_m, dx, 1.0, lat);
      rep.iterations = it + 1;
      continue;
    }
    ldlt.compute(k);
    if (ldlt.info() != Eigen::Success)
      return make_error("static solve: stiffness matrix (", std::to_string(free), " free DOFs) is singular at Newton step ",
                        std::to_string(it), "; hold enough DOFs to remove rigid motion");
    dx = ldlt.solve(r);
    if (!dx.allFinite() || (ldlt.vectorD().array() <= 0.0).any())
      return make_error("static solve: stiffness matrix (", std::to_string(free), " free DOFs) is not positive definite at Newton step ",
                        std::to_string(it), "; hold enough DOFs to remove rigid motion");
    move_free(fc, lat->x_m, dx, 1.0, lat);
    rep.iterations = it + 1;
  }
  return make_error("static solve: no convergence after ", std::to_string(options.max_iterations),
                    " Newton steps (largest force imbalance ", std::to_string(rep.max_residual_N), " N)");
}

}  // namespace palpate
