#include "sim/contact/contact_compliance.h"

#include "sim/material/neo_hookean_term.h"
#include "sim/material/volume_term.h"

#include <algorithm>
#include <limits>
#include <vector>

#include <Eigen/Sparse>
#include <Eigen/OrderingMethods>

namespace palpate {

namespace {
constexpr double kSingularPivot = 1e-10;  // relative pivot below which K is taken as singular
// Free nodes from which a budgeted factorisation is spread over calls: the bunny's and cube_press's regions (169 and
// 196 free nodes) factor whole in 3-5 ms; phantom_press's and block_stroke's (320-488) took 14-27 ms of one frame.
constexpr int kSlicedFromFreeNodes = 256;
// reserve(): at most this many nodes' storage; each node's share of K's pairs (a cell's 56 ordered corner pairs) and of
// L's fill
constexpr int64_t kReserveMaxNodes = 4096;
constexpr std::size_t kCellPairs = 56, kFillPerNode = 48;

// K's block (row, col), row != col, of one spring (two springs on one pair give two entries, summed when used)
struct OffBlock {
  int32_t col = 0, row = 0;
  Mat3 k = Mat3::Zero();
};
}  // namespace

// K is assembled and factorised as n x n 3x3 blocks (one per node pair), K = L D L^T with L block unit lower
// triangular and D block diagonal: every operation is a fixed-size 3x3 product instead of a scalar one with its own
// index, and the ordering and elimination tree are those of the node graph (9 times fewer entries than the dofs').
// The scalar pivots are those of an LDL^T of K with each node's three dofs eliminated together.
struct ContactCompliance::Impl {
  std::vector<int32_t> free_of_node;  // free-node number of each node, -1 for fixed or hanging (n)
  // a hanging node's free masters and weights (x = P q): entries [hang_ptr[i], hang_ptr[i + 1]) of hang_free and
  // hang_w for node i; empty for the others (free: itself, fixed: nothing)
  std::vector<int32_t> hang_ptr, hang_free;
  std::vector<double> hang_w;
  std::vector<int32_t> order;         // order[k] = the free node eliminated k-th (nf)
  std::vector<int32_t> pos;           // pos[f] = when free node f is eliminated (nf)
  // K's strict upper triangle in elimination order, by column: rows up_row[up_ptr[k] .. up_ptr[k+1]) < k
  std::vector<int32_t> up_ptr, up_row;
  std::vector<Mat3> up_val, diag;     // its blocks, and K's diagonal blocks (nf)
  // L's strict lower triangle by column (rows l_row[l_ptr[j] ..+ l_nz[j]) > j) and D^-1
  std::vector<int32_t> parent, l_ptr, l_nz, l_row, flag, pattern;
  std::vector<Mat3> l_val, d_inv, y;
  std::vector<Vec3> x;     // solve()'s vector in elimination order (nf)
  Eigen::MatrixXd z, dz;   // condense()'s L^-1 W and D^-1 L^-1 W (3 nf x loads)
  std::vector<OffBlock> off;
  uint64_t revision = 0;  // the factored lattice's
  std::size_t nodes = 0, springs = 0;
  bool ok = false;
  // the factorisation in slices: its next stage, the next column to eliminate, the pivots' range so far
  enum class Stage { kNone, kOrder, kSymbolic, kNumeric } stage = Stage::kNone;
  bool pending = false, sliced = false;
  int32_t next_k = 0;
  double d_max = 0.0, d_min = std::numeric_limits<double>::infinity();

  std::vector<std::array<Vec3, 8>> cell_c;  // volume term: cof(F) g_a per cell corner (sim/material/volume_term.h)
  std::vector<double> cell_w;               // and its weight per cell
  std::vector<NeoHookeanCell> neo;          // Neo-Hookean term: each cell's tangent state
  // K's blocks at the lattice's current positions, sorted by column (false: no free node)
  bool assemble(const Lattice& lat);
  // calls fn(free node, weight) for what node i moves with: itself when free, its masters when it hangs
  template <typename Fn>
  void for_each_free(std::size_t i, Fn&& fn) const {
    if (free_of_node[i] >= 0) return fn(free_of_node[i], 1.0);
    if (hang_ptr.empty()) return;
    for (int32_t e = hang_ptr[i]; e < hang_ptr[i + 1]; ++e)
      fn(hang_free[static_cast<std::size_t>(e)], hang_w[static_cast<std::size_t>(e)]);
  }
  // adds block k at (row node r, column node c) of K, folded onto the free nodes they move with (P^T K P)
  void add_block(int32_t r, int32_t c, const Mat3& k);
  // the fill-reducing elimination order and K's upper triangle in it
  void order_nodes();
  // the elimination tree, L's column counts and storage
  void symbolic();
  // the stages after assemble(): one per call when sliced (the numeric one by work_blocks), else all at once; true
  // when the factor is done
  bool advance(int64_t work_blocks);
  // eliminates columns until done or work_blocks 3x3 block updates are spent (<= 0: no limit); true when done
  bool eliminate(int64_t work_blocks);
  // the pivots' verdict once every column is eliminated
  bool well_conditioned() const;
};

void ContactCompliance::Impl::add_block(int32_t r, int32_t c, const Mat3& k) {
  for_each_free(static_cast<std::size_t>(r), [&](int32_t fr, double wr) {
    for_each_free(static_cast<std::size_t>(c), [&](int32_t fc, double wc) {
      const double w = wr * wc;
      if (fr == fc) diag[static_cast<std::size_t>(fr)] += w == 1.0 ? k : Mat3(w * k);
      else off.push_back({fc, fr, w == 1.0 ? k : Mat3(w * k)});
    });
  });
}

bool ContactCompliance::Impl::assemble(const Lattice& lat) {
  const std::size_t n = lat.num_nodes();
  free_of_node.assign(n, -1);
  std::vector<uint8_t> hangs(n, 0);
  for (const HangingNode& h : lat.hanging) hangs[static_cast<std::size_t>(h.node)] = 1;
  int32_t nf = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!lat.fixed[i] && !hangs[i]) free_of_node[i] = nf++;
  // each hanging node's free masters (masters hanging themselves come first in the list: theirs are known)
  hang_ptr.clear();
  hang_free.clear();
  hang_w.clear();
  if (!lat.hanging.empty()) {
    std::vector<std::vector<std::pair<int32_t, double>>> exp(n);
    for (const HangingNode& h : lat.hanging)
      for (int k = 0; k < h.count; ++k) {
        const auto m = static_cast<std::size_t>(h.master[static_cast<std::size_t>(k)]);
        const double w = h.weight[static_cast<std::size_t>(k)];
        if (free_of_node[m] >= 0) exp[static_cast<std::size_t>(h.node)].emplace_back(free_of_node[m], w);
        for (const auto& [f, wm] : exp[m]) exp[static_cast<std::size_t>(h.node)].emplace_back(f, w * wm);
      }
    hang_ptr.assign(n + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
      for (const auto& [f, w] : exp[i]) hang_free.push_back(f), hang_w.push_back(w);
      hang_ptr[i + 1] = static_cast<int32_t>(hang_free.size());
    }
  }
  if (nf == 0) return false;
  const auto unf = static_cast<std::size_t>(nf);
  // material stiffness k u u^T per spring (positive semi-definite), assembled over free nodes
  diag.assign(unf, Mat3::Zero());
  off.clear();
  for (const Spring& s : lat.springs) {
    const Vec3 d = lat.x_m[s.b] - lat.x_m[s.a];
    const double len = d.norm();
    if (!(len > 0.0)) continue;
    const Vec3 u = d / len;
    const Mat3 k = s.k_N_per_m * u * u.transpose();
    add_block(s.a, s.a, k);
    add_block(s.b, s.b, k);
    if (s.a != s.b) {
      add_block(s.b, s.a, -k);
      add_block(s.a, s.b, -k);
    }
  }
  // the cells' volume terms (lambda_v > 0: the nearly incompressible solid's bulk stiffness; a negative term, nu < 1/4,
  // is left out, which keeps K positive definite and errs stiff): Gauss-Newton blocks lambda_v l^3 c_a c_b^T
  if (lat.volume_Pa > 0.0) {
    volume_gradients(lat, lat.x_m, &cell_c, &cell_w);
    for (std::size_t cell = 0; cell < cell_c.size(); ++cell)
      for (int a = 0; a < 8; ++a)
        for (int b = 0; b < 8; ++b)  // block (row b, column a)
          add_block(lat.cell_nodes[cell][b], lat.cell_nodes[cell][a], cell_w[cell] * cell_c[cell][b] * cell_c[cell][a].transpose());
  }
  // the cells' Neo-Hookean terms: their tangent blocks at the current configuration
  if (lat.neo_mu_Pa != 0.0) {
    neo_hookean_cells(lat, lat.x_m, &neo);
    for (std::size_t cell = 0; cell < neo.size(); ++cell)
      for (int a = 0; a < 8; ++a)
        for (int b = 0; b < 8; ++b)  // block (row b, column a)
          add_block(lat.cell_nodes[cell][b], lat.cell_nodes[cell][a], neo_hookean_block(lat, neo[cell], b, a));
  }
  std::sort(off.begin(), off.end(), [](const OffBlock& a, const OffBlock& b) { return a.col != b.col ? a.col < b.col : a.row < b.row; });
  return true;
}

void ContactCompliance::Impl::order_nodes() {
  const auto nf = static_cast<int32_t>(diag.size());
  const auto unf = diag.size();
  // fill-reducing ordering of the node graph (both triangles, pattern only)
  {
    Eigen::SparseMatrix<double> g(nf, nf);
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(off.size() + unf);
    for (int32_t f = 0; f < nf; ++f) t.emplace_back(f, f, 1.0);
    for (const OffBlock& e : off) t.emplace_back(e.row, e.col, 1.0);
    g.setFromTriplets(t.begin(), t.end());
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm;
    Eigen::AMDOrdering<int>()(g, perm);
    order.assign(perm.indices().data(), perm.indices().data() + nf);
  }
  pos.assign(unf, 0);
  for (int32_t k = 0; k < nf; ++k) pos[static_cast<std::size_t>(order[static_cast<std::size_t>(k)])] = k;
  // the strict upper triangle in elimination order (a pair's entries stay apart; the factorisation adds them)
  up_ptr.assign(unf + 1, 0);
  for (const OffBlock& e : off)
    if (pos[static_cast<std::size_t>(e.row)] < pos[static_cast<std::size_t>(e.col)]) ++up_ptr[static_cast<std::size_t>(pos[static_cast<std::size_t>(e.col)]) + 1];
  for (std::size_t k = 0; k < unf; ++k) up_ptr[k + 1] += up_ptr[k];
  up_row.assign(static_cast<std::size_t>(up_ptr[unf]), 0);
  up_val.assign(up_row.size(), Mat3::Zero());
  std::vector<int32_t>& next = flag;  // fill position per column
  next.assign(up_ptr.begin(), up_ptr.end() - 1);
  for (const OffBlock& e : off) {
    const int32_t r = pos[static_cast<std::size_t>(e.row)], c = pos[static_cast<std::size_t>(e.col)];
    if (r >= c) continue;
    const auto at = static_cast<std::size_t>(next[static_cast<std::size_t>(c)]++);
    up_row[at] = r;
    up_val[at] = e.k;
  }
}

void ContactCompliance::Impl::symbolic() {
  const auto nf = static_cast<int32_t>(diag.size());
  const auto unf = diag.size();
  // elimination tree and column counts of L (up-looking: row k of L is the tree reach of column k's rows)
  parent.assign(unf, -1);
  l_nz.assign(unf, 0);
  flag.assign(unf, -1);
  for (int32_t k = 0; k < nf; ++k) {
    flag[static_cast<std::size_t>(k)] = k;
    for (int32_t p = up_ptr[static_cast<std::size_t>(k)]; p < up_ptr[static_cast<std::size_t>(k) + 1]; ++p)
      for (int32_t i = up_row[static_cast<std::size_t>(p)]; flag[static_cast<std::size_t>(i)] != k; i = parent[static_cast<std::size_t>(i)]) {
        if (parent[static_cast<std::size_t>(i)] == -1) parent[static_cast<std::size_t>(i)] = k;
        ++l_nz[static_cast<std::size_t>(i)];
        flag[static_cast<std::size_t>(i)] = k;
      }
  }
  l_ptr.assign(unf + 1, 0);
  for (std::size_t k = 0; k < unf; ++k) l_ptr[k + 1] = l_ptr[k] + l_nz[k];
  l_row.assign(static_cast<std::size_t>(l_ptr[unf]), 0);
  l_val.assign(l_row.size(), Mat3::Zero());
  d_inv.assign(unf, Mat3::Zero());
  y.assign(unf, Mat3::Zero());
  pattern.assign(unf, 0);
  next_k = 0;
  d_max = 0.0;
  d_min = std::numeric_limits<double>::infinity();
}

bool ContactCompliance::Impl::advance(int64_t work_blocks) {
  do {
    switch (stage) {
      case Stage::kOrder: order_nodes(); stage = Stage::kSymbolic; break;
      case Stage::kSymbolic: symbolic(); stage = Stage::kNumeric; break;
      case Stage::kNumeric:
        if (!eliminate(sliced ? work_blocks : 0)) return false;
        stage = Stage::kNone;
        return true;
      case Stage::kNone: return true;
    }
  } while (!sliced);
  return false;
}

bool ContactCompliance::Impl::eliminate(int64_t work_blocks) {
  const auto nf = static_cast<int32_t>(diag.size());
  int64_t spent = 0;
  // numeric: row k of L from the triangular solve L D l_k^T = K(0:k, k), then D_k = K_kk - sum_i L_ki D_i L_ki^T
  for (int32_t& k = next_k; k < nf; ++k) {
    if (work_blocks > 0 && spent >= work_blocks) return false;
    const auto uk = static_cast<std::size_t>(k);
    int32_t top = nf;
    flag[uk] = k;
    l_nz[uk] = 0;
    for (int32_t p = up_ptr[uk]; p < up_ptr[uk + 1]; ++p) {
      int32_t i = up_row[static_cast<std::size_t>(p)];
      y[static_cast<std::size_t>(i)] += up_val[static_cast<std::size_t>(p)];
      int32_t len = 0;
      for (; flag[static_cast<std::size_t>(i)] != k; i = parent[static_cast<std::size_t>(i)]) {
        pattern[static_cast<std::size_t>(len++)] = i;
        flag[static_cast<std::size_t>(i)] = k;
      }
      while (len > 0) pattern[static_cast<std::size_t>(--top)] = pattern[static_cast<std::size_t>(--len)];
    }
    Mat3 d = diag[static_cast<std::size_t>(order[uk])];
    for (; top < nf; ++top) {
      const auto i = static_cast<std::size_t>(pattern[static_cast<std::size_t>(top)]);
      const Mat3 yi = y[i];  // D_i L_ki^T
      y[i].setZero();
      const auto p0 = static_cast<std::size_t>(l_ptr[i]), p1 = p0 + static_cast<std::size_t>(l_nz[i]);
      for (std::size_t p = p0; p < p1; ++p) y[static_cast<std::size_t>(l_row[p])].noalias() -= l_val[p] * yi;
      spent += static_cast<int64_t>(p1 - p0) + 1;
      const Mat3 lki = yi.transpose() * d_inv[i];
      d.noalias() -= lki * yi;
      l_row[p1] = k;
      l_val[p1] = lki;
      ++l_nz[i];
    }
    d = 0.5 * (d + d.transpose());
    // the block's scalar pivots: its own LDL^T, dof by dof
    const double p0 = d(0, 0);
    const double p1 = p0 != 0.0 ? d(1, 1) - d(1, 0) * d(1, 0) / p0 : 0.0;
    const double p2 = p1 != 0.0 ? d(2, 2) - d(2, 0) * d(2, 0) / p0 -
                                      (d(2, 1) - d(2, 0) * d(1, 0) / p0) * (d(2, 1) - d(2, 0) * d(1, 0) / p0) / p1
                                : 0.0;
    if (p0 == 0.0 || p1 == 0.0 || p2 == 0.0) {
      // singular: no factor (the verdict below fails on the zero pivot)
      d_min = 0.0;
      k = nf;
      return true;
    }
    d_max = std::max({d_max, p0, p1, p2});
    d_min = std::min({d_min, p0, p1, p2});
    d_inv[uk] = d.inverse();
  }
  return true;
}

bool ContactCompliance::Impl::well_conditioned() const {
  // a pivot at round-off level of the largest means a free motion (nothing fixed, a piece cut free): the system is
  // singular even when no pivot is exactly zero
  return d_max > 0.0 && d_min > kSingularPivot * d_max;
}

ContactCompliance::ContactCompliance() : impl_(std::make_unique<Impl>()) {}

void ContactCompliance::set_work_per_call(int64_t blocks) { work_per_call_ = blocks; }

void ContactCompliance::reserve(int64_t nodes, int64_t springs, bool cell_terms) {
  Impl& m = *impl_;
  const auto n = static_cast<std::size_t>(std::clamp<int64_t>(nodes, 0, kReserveMaxNodes));
  const auto k = static_cast<std::size_t>(std::clamp<int64_t>(springs, 0, 32 * kReserveMaxNodes));
  // written once, not only reserved: a page's first write is what costs (up to 25 ms for a 500-node region here)
  auto touch = [](auto* v, std::size_t size) {
    v->resize(size);
    v->clear();
  };
  const std::size_t pairs = cell_terms ? kCellPairs * n : 0;  // the cells' terms add a block per ordered corner pair
  touch(&m.off, 2 * k + pairs);
  touch(&m.up_row, k + pairs / 2);
  touch(&m.up_val, k + pairs / 2);
  touch(&m.l_row, kFillPerNode * n);
  touch(&m.l_val, kFillPerNode * n);
  for (auto* v : {&m.diag, &m.d_inv, &m.y}) touch(v, n);
  for (auto* v : {&m.free_of_node, &m.order, &m.pos, &m.up_ptr, &m.parent, &m.l_ptr, &m.l_nz, &m.flag, &m.pattern})
    touch(v, n + 1);
  if (cell_terms) {
    touch(&m.cell_c, n);
    touch(&m.cell_w, n);
    touch(&m.neo, n);
  }
}

bool ContactCompliance::factoring() const { return impl_->pending; }
ContactCompliance::~ContactCompliance() = default;

bool ContactCompliance::compute(const Lattice& lat, const PointWeights& w, bool refactor, Mat3* c_m_per_N) {
  Impl& m = *impl_;
  const bool changed = lat.revision != m.revision || lat.num_nodes() != m.nodes || lat.springs.size() != m.springs;
  if (refactor || changed || (!m.ok && !m.pending)) {
    m.revision = lat.revision;
    m.nodes = lat.num_nodes();
    m.springs = lat.springs.size();
    m.ok = false;
    m.pending = m.assemble(lat);
    m.stage = m.pending ? Impl::Stage::kOrder : Impl::Stage::kNone;
    if (!m.pending) return false;
    // a large region's factorisation is spread over calls: assembly, ordering, symbolic analysis, then columns
    // by the work budget (a small one's whole factorisation costs less than one of those stages of a large one)
    m.sliced = work_per_call_ > 0 && m.diag.size() > static_cast<std::size_t>(kSlicedFromFreeNodes);
    if (m.sliced) return false;
  }
  if (m.pending) {
    // the stiffness assembled when the factorisation began
    if (!m.advance(work_per_call_)) return false;
    m.pending = false;
    m.ok = m.well_conditioned();
  }
  if (!m.ok) return false;
  // C = W^T K^-1 W = Z^T D^-1 Z with Z = L^-1 W (W: the point force's share on each free node, one 3x3 block
  // w I per node): a forward solve only
  std::vector<Mat3>& z = m.y;  // zero between uses
  for (int i = 0; i < w.count; ++i)
    m.for_each_free(static_cast<std::size_t>(w.node[i]), [&](int32_t f, double wf) {
      z[static_cast<std::size_t>(m.pos[static_cast<std::size_t>(f)])].diagonal().array() += wf == 1.0 ? w.weight[i] : wf * w.weight[i];
    });
  Mat3 c = Mat3::Zero();
  const std::size_t nf = m.d_inv.size();
  for (std::size_t j = 0; j < nf; ++j) {
    const Mat3 zj = z[j];
    if (zj.isZero(0.0)) continue;
    z[j].setZero();
    for (auto p = static_cast<std::size_t>(m.l_ptr[j]); p < static_cast<std::size_t>(m.l_ptr[j] + m.l_nz[j]); ++p)
      z[static_cast<std::size_t>(m.l_row[p])].noalias() -= m.l_val[p] * zj;
    c.noalias() += zj.transpose() * m.d_inv[j] * zj;
  }
  if (!c.allFinite()) return false;
  // symmetric by construction up to round-off
  *c_m_per_N = 0.5 * (c + c.transpose());
  return true;
}

bool ContactCompliance::ready(const Lattice& lat) const {
  const Impl& m = *impl_;
  return m.ok && !m.pending && lat.revision == m.revision && lat.num_nodes() == m.nodes && lat.springs.size() == m.springs;
}

bool ContactCompliance::solve(const std::vector<Vec3>& f_N, std::vector<Vec3>* u_m) {
  Impl& m = *impl_;
  if (!m.ok || m.pending || f_N.size() != m.free_of_node.size()) return false;
  const std::size_t nf = m.d_inv.size();
  m.x.assign(nf, Vec3::Zero());
  for (std::size_t i = 0; i < f_N.size(); ++i)
    m.for_each_free(i, [&](int32_t f, double wf) { m.x[static_cast<std::size_t>(m.pos[static_cast<std::size_t>(f)])] += wf * f_N[i]; });
  // K = L D L^T: forward (L y = f), the pivots (D w = y), backward (L^T x = w)
  for (std::size_t j = 0; j < nf; ++j)
    for (auto p = static_cast<std::size_t>(m.l_ptr[j]); p < static_cast<std::size_t>(m.l_ptr[j] + m.l_nz[j]); ++p)
      m.x[static_cast<std::size_t>(m.l_row[p])].noalias() -= m.l_val[p] * m.x[j];
  for (std::size_t j = 0; j < nf; ++j) m.x[j] = m.d_inv[j] * m.x[j];
  for (std::size_t j = nf; j-- > 0;)
    for (auto p = static_cast<std::size_t>(m.l_ptr[j]); p < static_cast<std::size_t>(m.l_ptr[j] + m.l_nz[j]); ++p)
      m.x[j].noalias() -= m.l_val[p].transpose() * m.x[static_cast<std::size_t>(m.l_row[p])];
  u_m->assign(f_N.size(), Vec3::Zero());
  for (std::size_t i = 0; i < f_N.size(); ++i)
    m.for_each_free(i, [&](int32_t f, double wf) { (*u_m)[i] += wf * m.x[static_cast<std::size_t>(m.pos[static_cast<std::size_t>(f)])]; });
  return true;
}

bool ContactCompliance::condense(const std::vector<PointWeights>& loads, const std::vector<Vec3>& dirs, Eigen::MatrixXd* c) {
  Impl& m = *impl_;
  if (!m.ok || m.pending || loads.size() != dirs.size()) return false;
  const auto nf = static_cast<Eigen::Index>(m.d_inv.size());
  const auto k = static_cast<Eigen::Index>(loads.size());
  m.z.setZero(3 * nf, k);
  for (Eigen::Index col = 0; col < k; ++col) {
    const PointWeights& w = loads[static_cast<std::size_t>(col)];
    for (int i = 0; i < w.count; ++i) {
      if (w.node[i] < 0 || static_cast<std::size_t>(w.node[i]) >= m.free_of_node.size()) return false;
      m.for_each_free(static_cast<std::size_t>(w.node[i]), [&](int32_t f, double wf) {
        m.z.block<3, 1>(3 * m.pos[static_cast<std::size_t>(f)], col) += wf * w.weight[i] * dirs[static_cast<std::size_t>(col)];
      });
    }
  }
  // Z = L^-1 W (the loads reach only their nodes' ancestors in the elimination tree: zero blocks are skipped), then
  // C = Z^T D^-1 Z
  for (Eigen::Index j = 0; j < nf; ++j) {
    const auto zj = m.z.middleRows<3>(3 * j);
    if (zj.isZero(0.0)) continue;
    const auto uj = static_cast<std::size_t>(j);
    for (auto p = static_cast<std::size_t>(m.l_ptr[uj]); p < static_cast<std::size_t>(m.l_ptr[uj] + m.l_nz[uj]); ++p)
      m.z.middleRows<3>(3 * static_cast<Eigen::Index>(m.l_row[p])).noalias() -= m.l_val[p] * zj;
  }
  m.dz.resize(3 * nf, k);
  for (Eigen::Index j = 0; j < nf; ++j) m.dz.middleRows<3>(3 * j).noalias() = m.d_inv[static_cast<std::size_t>(j)] * m.z.middleRows<3>(3 * j);
  c->noalias() = m.z.transpose() * m.dz;
  *c = 0.5 * (*c + c->transpose()).eval();
  return c->allFinite();
}

}  // namespace palpate
