#include "sim/contact/sphere_contact.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "sim/lattice/forces.h"
#include "sim/solvers/free_coords.h"
#include "sim/lattice/hanging.h"
#include "sim/solvers/local_global.h"
#include "sim/solvers/static_solve.h"

namespace palpate {
namespace {

// One sample inside the sphere at the current positions: its outward direction from the centre and depth inside.
struct Touch {
  std::size_t sample = 0;
  Vec3 n = Vec3::Zero();   // from the centre to the sample (unit)
  double pen_m = 0.0;      // radius minus distance (> 0)
  double dist_m = 0.0;     // distance from the centre
};

// Whether the rest point p_m lies in a cell of lat (slot_of_cell at lat.level, whose grid has its origin at origin_m).
bool in_some_cell(const Lattice& lat, const Vec3& origin_m, const Vec3& p_m) {
  const int n = lat.cells_per_axis;
  int g[3];
  for (int a = 0; a < 3; ++a) {
    g[a] = static_cast<int>(std::floor((p_m[a] - origin_m[a]) / lat.cell_m));
    if (g[a] < 0 || g[a] >= n) return false;
  }
  return lat.slot_of_cell[static_cast<std::size_t>(g[0] + n * (g[1] + n * g[2]))] >= 0;
}

}  // namespace

std::vector<SurfaceSample> lattice_surface_samples(const Lattice& lat, int per_edge, const Vec3& facing) {
  // corner bits: dx + 2 dy + 4 dz; a face is the 4 corners with one bit fixed
  struct Face {
    std::size_t slot;
    int axis, side;
  };
  std::map<std::array<int32_t, 4>, std::vector<Face>> faces;
  for (std::size_t slot = 0; slot < lat.cell_nodes.size(); ++slot)
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        std::array<int32_t, 4> key{};
        int k = 0;
        for (int corner = 0; corner < 8; ++corner)
          if (((corner >> axis) & 1) == side) key[k++] = lat.cell_nodes[slot][corner];
        std::sort(key.begin(), key.end());
        faces[key].push_back({slot, axis, side});
      }
  std::vector<SurfaceSample> out;
  const int m = std::max(per_edge, 1);
  // on a refined lattice a face of one cell may still be inside, against smaller or larger cells across it: a sample
  // with a cell half a fine cell beyond it is left out. The grid's origin from node 0 (grid_node at lat.level)
  const bool refined = !lat.cell_span.empty();
  Vec3 origin_m = Vec3::Zero();
  if (refined) {
    const int nv = lat.cells_per_axis + 1, g0 = lat.grid_node[0];
    origin_m = lat.rest_m[0] - lat.cell_m * Vec3(g0 % nv, (g0 / nv) % nv, g0 / (nv * nv));
  }
  for (const auto& [key, list] : faces) {
    if (list.size() != 1) continue;  // shared by two cells: inside
    const Face& f = list.front();
    Vec3 outward = Vec3::Zero();
    outward[f.axis] = f.side == 0 ? -1.0 : 1.0;
    if (facing.squaredNorm() > 0.0 && outward.dot(facing) < 0.5) continue;
    bool all_fixed = true;
    for (int32_t node : key) all_fixed = all_fixed && lat.fixed[static_cast<std::size_t>(node)] != 0;
    if (all_fixed) continue;
    const int b = (f.axis + 1) % 3, c = (f.axis + 2) % 3;
    // the face's corners by (u, v) along axes b and c
    std::array<int32_t, 4> corner{};
    for (int u = 0; u < 2; ++u)
      for (int v = 0; v < 2; ++v)
        corner[u + 2 * v] = lat.cell_nodes[f.slot][(f.side << f.axis) | (u << b) | (v << c)];
    const double edge = lat.cell_edge_m(f.slot);
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) {
        const double u = (i + 0.5) / m, v = (j + 0.5) / m;
        SurfaceSample s;
        s.count = 4;
        const double w[4] = {(1 - u) * (1 - v), u * (1 - v), (1 - u) * v, u * v};
        for (int q = 0; q < 4; ++q) s.node[q] = corner[q], s.weight[q] = w[q];
        if (refined && in_some_cell(lat, origin_m, sample_position(s, lat.rest_m) + 0.5 * lat.cell_m * outward)) continue;
        s.area_m2 = edge * edge / (m * m);
        out.push_back(s);
      }
  }
  return out;
}

Vec3 sample_position(const SurfaceSample& s, const std::vector<Vec3>& x_m) {
  Vec3 p = Vec3::Zero();
  for (int k = 0; k < s.count; ++k) p += s.weight[k] * x_m[static_cast<std::size_t>(s.node[k])];
  return p;
}

double contact_penalty_Pa_per_m(double young_modulus_Pa, double cell_m) {
  return kContactPenaltyFactor * young_modulus_Pa / cell_m;
}

Result<SphereContactResult> solve_sphere_contact(Lattice* lat, const std::vector<uint8_t>& held_dof,
                                                 const std::vector<SurfaceSample>& samples, const Vec3& centre_m,
                                                 double radius_m, const SphereContactOptions& options) {
  if (!(options.penalty_Pa_per_m > 0.0) || !(radius_m > 0.0))
    return make_error("sphere contact: penalty ", std::to_string(options.penalty_Pa_per_m), " Pa/m and radius ",
                      std::to_string(radius_m), " m must be > 0");
  const std::size_t n = lat->num_nodes();
  const bool free_sphere = options.coupling_N_per_m > 0.0;
  // the lattice's free coordinates (hanging nodes eliminated), then the centre's when free
  const FreeCoords fc = free_coords(*lat, held_dof, free_sphere ? 3 : 0);
  const std::vector<int>& col = fc.col;
  const int dofs = fc.free, sphere_row = fc.lattice_rows;
  SphereContactResult rep;
  rep.centre_m = centre_m;
  if (dofs == 0) return rep;
  // nested dissection (fill about half of minimum degree's on a 3D lattice); the pattern is analysed again only when
  // the samples near the sphere change
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, NestedDissectionOrdering<int>> ldlt;
  std::vector<uint8_t> near(samples.size(), 0), analysed;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper, Eigen::IncompleteCholesky<double>> cg;
  cg.setTolerance(1e-12);
  cg.setMaxIterations(20000);
  std::vector<Eigen::Triplet<double>> trip;
  std::vector<Touch> touch;
  std::vector<uint8_t> active(samples.size(), 0), was_active(samples.size(), 0);
  Eigen::VectorXd r(dofs), dx = Eigen::VectorXd::Zero(dofs);
  Vec3 c = centre_m;
  bool stable = false;
  // the energy Newton descends: the lattice's, the penalty's, the coupling spring's
  auto energy_J = [&](const Vec3& centre) {
    double e = lattice_energy_J(*lat);
    for (const SurfaceSample& smp : samples) {
      const double pen = radius_m - (sample_position(smp, lat->x_m) - centre).norm();
      if (pen > 0.0) e += 0.5 * options.penalty_Pa_per_m * smp.area_m2 * pen * pen;
    }
    if (free_sphere) e += 0.5 * options.coupling_N_per_m * (options.device_m - centre).squaredNorm();
    return e;
  };
  std::vector<Vec3> x_before;
  spread_hanging(*lat, &lat->x_m);
  for (int it = 0; it <= options.max_iterations; ++it) {
    // the samples inside the sphere now
    touch.clear();
    std::swap(active, was_active);
    std::fill(active.begin(), active.end(), 0);
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const Vec3 g = sample_position(samples[i], lat->x_m) - c;
      const double dist = g.norm();
      near[i] = dist < radius_m + 2.0 * lat->cell_m ? 1 : 0;
      if (dist < radius_m && dist > 0.0) {
        touch.push_back({i, g / dist, radius_m - dist, dist});
        active[i] = 1;
      }
    }
    stable = it > 0 && active == was_active;
    // residual: the lattice's forces, gravity, the samples' reactions, the coupling on the centre
    std::vector<Vec3> f = spring_forces_N(*lat, lat->x_m);
    for (std::size_t i = 0; i < n; ++i) f[i] += lat->mass_kg[i] * lat->gravity_m_per_s2;
    Vec3 on_sphere = Vec3::Zero();
    double deepest = 0.0;
    for (const Touch& t : touch) {
      const SurfaceSample& s = samples[t.sample];
      const Vec3 fs = options.penalty_Pa_per_m * s.area_m2 * t.pen_m * t.n;
      for (int k = 0; k < s.count; ++k) f[static_cast<std::size_t>(s.node[k])] += s.weight[k] * fs;
      on_sphere -= fs;
      deepest = std::max(deepest, t.pen_m);
    }
    reduce_forces(*lat, fc, &f, &r);
    if (free_sphere) r.tail<3>() = on_sphere + options.coupling_N_per_m * (options.device_m - c);
    rep.force_N = on_sphere;
    rep.centre_m = c;
    rep.active = static_cast<int>(touch.size());
    rep.max_penetration_m = deepest;
    rep.max_residual_N = r.cwiseAbs().maxCoeff();
    if (stable && (dx.cwiseAbs().maxCoeff() < options.step_tol_m || rep.max_residual_N < options.residual_tol_N)) return rep;
    if (it == options.max_iterations) break;
    // tangent: the lattice's, each touching sample's kappa A n n^T spread by its weights (and on the centre, with
    // the opposite sign across), the coupling spring on the centre. The sample's exact tangent also has
    // -kappa A pen / dist (I - n n^T) across the normal; left out (Gauss-Newton), as with kappa >> E l it would make
    // the matrix indefinite for a sample pressed a few per mille of the radius deep
    trip.clear();
    // compressed springs' transverse terms dropped: a deep press squashes cells enough to make the exact tangent
    // indefinite; the energy's line search keeps the step a descent
    add_stiffness_triplets(*lat, col, &trip, true);
    auto add_block = [&](int row0, int col0, const Mat3& blk) {
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) trip.emplace_back(row0 + i, col0 + j, blk(i, j));
    };
    // every sample near the sphere enters the pattern (zero when not touching), so it changes only when they do
    std::vector<Touch> blocks = touch;
    for (std::size_t i = 0; i < samples.size(); ++i)
      if (near[i] && !active[i]) blocks.push_back({i, Vec3::Zero(), 0.0, 0.0});
    for (const Touch& t : blocks) {
      const SurfaceSample& s = samples[t.sample];
      const Mat3 nn = t.n * t.n.transpose();
      const Mat3 k = options.penalty_Pa_per_m * s.area_m2 * nn;
      for (int p = 0; p < s.count; ++p) {
        const auto np = static_cast<std::size_t>(s.node[p]);
        for (int q = 0; q < s.count; ++q) {
          const auto nq = static_cast<std::size_t>(s.node[q]);
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
              const int ri = col[3 * np + i], cj = col[3 * nq + j];
              if (ri >= 0 && cj >= 0) trip.emplace_back(ri, cj, s.weight[p] * s.weight[q] * k(i, j));
            }
        }
        if (!free_sphere) continue;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            const int ri = col[3 * np + i];
            if (ri < 0) continue;
            trip.emplace_back(ri, sphere_row + j, -s.weight[p] * k(i, j));
            trip.emplace_back(sphere_row + j, ri, -s.weight[p] * k(j, i));
          }
      }
      if (free_sphere) add_block(sphere_row, sphere_row, k);
    }
    if (free_sphere) add_block(sphere_row, sphere_row, options.coupling_N_per_m * Mat3::Identity());
    Eigen::SparseMatrix<double> assembled(fc.assembled(), fc.assembled());
    assembled.setFromTriplets(trip.begin(), trip.end());
    const Eigen::SparseMatrix<double> k = reduce_stiffness(fc, std::move(assembled));
    if (options.iterative) {
      cg.compute(k);
      dx = cg.solve(r);
      if (cg.info() != Eigen::Success || !dx.allFinite())
        return make_error("sphere contact: conjugate gradients did not converge (", std::to_string(dofs),
                          " DOFs) at Newton step ", std::to_string(it));
    } else {
      if (near != analysed) {
        ldlt.analyzePattern(k);
        analysed = near;
      }
      ldlt.factorize(k);
      dx = ldlt.solve(r);
      if (ldlt.info() != Eigen::Success || !dx.allFinite() || (ldlt.vectorD().array() <= 0.0).any())
        return make_error("sphere contact: stiffness (", std::to_string(dofs), " DOFs) is singular or not positive "
                          "definite at Newton step ", std::to_string(it), "; hold enough DOFs to remove rigid motion");
    }
    // the step, halved until the energy does not rise (a sample entering or leaving the sphere is a kink in it: a full
    // step can overshoot, e.g. a free sphere falling through the surface to its device and thrown back)
    const double e0 = energy_J(c);
    x_before = lat->x_m;
    const Vec3 c_before = c;
    double step = 1.0;
    for (int halving = 0; halving < 30; ++halving, step *= 0.5) {
      move_free(fc, x_before, dx, step, lat);
      if (free_sphere) c = c_before + step * dx.tail<3>();
      if (energy_J(c) <= e0 + 1e-12 * std::abs(e0)) break;
    }
    dx *= step;
    rep.iterations = it + 1;
  }
  return make_error("sphere contact: no convergence after ", std::to_string(options.max_iterations), " Newton steps (",
                    stable ? "active set stable" : "active set still changing", ", ", std::to_string(rep.active),
                    " samples in contact, largest force imbalance ", std::to_string(rep.max_residual_N * 1e9), " nN)");
}

}  // namespace palpate
