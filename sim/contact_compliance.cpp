#include "sim/contact_compliance.h"

#include <algorithm>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

namespace palpate {

namespace {
constexpr double kSingularPivot = 1e-10;  // relative pivot below which K is taken as singular
}  // namespace

struct ContactCompliance::Impl {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  std::vector<int32_t> dof_of_node;  // first dof of each free node, -1 for fixed (n)
  std::size_t nodes = 0, springs = 0;
  bool ok = false;
};

ContactCompliance::ContactCompliance() : impl_(std::make_unique<Impl>()) {}
ContactCompliance::~ContactCompliance() = default;

bool ContactCompliance::compute(const Lattice& lat, const PointWeights& w, bool refactor, Mat3* c_m_per_N) {
  Impl& m = *impl_;
  const std::size_t n = lat.num_nodes();
  if (refactor || n != m.nodes || lat.springs.size() != m.springs || !m.ok) {
    m.nodes = n;
    m.springs = lat.springs.size();
    m.dof_of_node.assign(n, -1);
    // number free nodes consecutively, 3 dofs each
    int32_t dofs = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (!lat.fixed[i]) m.dof_of_node[i] = 3 * dofs++;
    const int32_t size = 3 * dofs;
    if (size == 0) return m.ok = false;
    // material stiffness k u u^T per spring (positive semi-definite), assembled over free dofs
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(lat.springs.size() * 36);
    for (const Spring& s : lat.springs) {
      const Vec3 d = lat.x_m[s.b] - lat.x_m[s.a];
      const double len = d.norm();
      if (!(len > 0.0)) continue;
      const Vec3 u = d / len;
      const Mat3 k = s.k_N_per_m * u * u.transpose();
      const int32_t da = m.dof_of_node[s.a], db = m.dof_of_node[s.b];
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
          if (da >= 0) trip.emplace_back(da + r, da + c, k(r, c));
          if (db >= 0) trip.emplace_back(db + r, db + c, k(r, c));
          if (da >= 0 && db >= 0) {
            trip.emplace_back(da + r, db + c, -k(r, c));
            trip.emplace_back(db + r, da + c, -k(r, c));
          }
        }
    }
    Eigen::SparseMatrix<double> kmat(size, size);
    kmat.setFromTriplets(trip.begin(), trip.end());
    m.ldlt.compute(kmat);
    m.ok = m.ldlt.info() == Eigen::Success;
    if (!m.ok) return false;
    // a pivot at round-off level of the largest means a free motion (nothing fixed, a piece cut free): the
    // system is singular even when the factorisation "succeeds"
    const Eigen::VectorXd d = m.ldlt.vectorD();
    double d_max = 0.0, d_min = 0.0;
    for (Eigen::Index i = 0; i < d.size(); ++i) {
      d_max = i == 0 ? d[i] : std::max(d_max, d[i]);
      d_min = i == 0 ? d[i] : std::min(d_min, d[i]);
    }
    m.ok = d_max > 0.0 && d_min > kSingularPivot * d_max;
    if (!m.ok) return false;
  }
  // W: the point force's share on each free dof (3 columns, one per force direction)
  Eigen::MatrixXd wmat = Eigen::MatrixXd::Zero(m.ldlt.rows(), 3);
  for (int i = 0; i < w.count; ++i) {
    const int32_t d = m.dof_of_node[static_cast<std::size_t>(w.node[i])];
    if (d < 0) continue;
    for (int r = 0; r < 3; ++r) wmat(d + r, r) += w.weight[i];
  }
  const Eigen::MatrixXd x = m.ldlt.solve(wmat);
  if (m.ldlt.info() != Eigen::Success || !x.allFinite()) return false;
  const Mat3 c = wmat.transpose() * x;
  // symmetric by construction up to round-off
  *c_m_per_N = 0.5 * (c + c.transpose());
  return true;
}

}  // namespace palpate
