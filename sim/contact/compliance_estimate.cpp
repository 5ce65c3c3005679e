#include "sim/contact/compliance_estimate.h"

namespace palpate {

Mat3 estimate_compliance(const Lattice& lat, const PointWeights& w, std::vector<double>* scratch) {
  // stiffness (trace of the diagonal block) of the loaded nodes only: mark them, then sum what reaches them
  std::vector<double>& k = *scratch;
  k.assign(lat.num_nodes(), -1.0);
  double w_free = 0.0;
  for (int i = 0; i < w.count; ++i) {
    const auto n = static_cast<std::size_t>(w.node[i]);
    if (n >= k.size() || lat.fixed[n]) continue;
    k[n] = 0.0;
    w_free += w.weight[i];
  }
  if (!(w_free > 0.0)) return Mat3::Zero();
  for (const Spring& s : lat.springs) {
    // a spring along d adds k d d^T to both ends' blocks: trace k
    if (k[static_cast<std::size_t>(s.a)] >= 0.0) k[static_cast<std::size_t>(s.a)] += s.k_N_per_m;
    if (k[static_cast<std::size_t>(s.b)] >= 0.0) k[static_cast<std::size_t>(s.b)] += s.k_N_per_m;
  }
  if (lat.neo_mu_Pa > 0.0) {
    // a cell's Neo-Hookean term holds a load on one node far less than springs of the same shear would (9/4 mu l on
    // each corner's trace): its one point in the middle of the cell leaves the cell's hourglass modes to the springs.
    // kNeoHookeanCornerStiffness is what keeps the estimate above the factored compliance (the test)
    for (std::size_t c = 0; c < lat.cell_nodes.size(); ++c)
      for (int32_t n : lat.cell_nodes[c])
        if (k[static_cast<std::size_t>(n)] >= 0.0)
          k[static_cast<std::size_t>(n)] += kNeoHookeanCornerStiffness * lat.neo_mu_Pa * lat.cell_edge_m(c);
  }
  double k_mean = 0.0;
  for (int i = 0; i < w.count; ++i) {
    const auto n = static_cast<std::size_t>(w.node[i]);
    if (n < k.size() && !lat.fixed[n]) k_mean += w.weight[i] * k[n] / 3.0;
  }
  k_mean /= w_free;
  if (!(k_mean > 0.0)) return Mat3::Zero();
  return Mat3::Identity() * (kNodeComplianceTimesStiffness * w_free * w_free / k_mean);
}

}  // namespace palpate
