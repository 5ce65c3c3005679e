#include "core/grid_hierarchy.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

namespace palpate {

namespace {

// leaf boxes are grown by this fraction of a cell so the triangle test stays conservative under rounding
constexpr double kOverlapSlack = 1e-9;

std::string fmt_vec(const Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), "(%.6g, %.6g, %.6g)", v.x(), v.y(), v.z());
  return buf;
}

// separating-axis test of a triangle against the closed cube of half side h_m centred at c_m
bool triangle_overlaps_box(const Vec3& c_m, double h_m, const Vec3& a_m, const Vec3& b_m, const Vec3& d_m) {
  const Vec3 v[3] = {a_m - c_m, b_m - c_m, d_m - c_m};
  // a zero axis projects everything to 0 and never separates
  auto separated = [&](const Vec3& axis) {
    const double p0 = axis.dot(v[0]);
    const double p1 = axis.dot(v[1]);
    const double p2 = axis.dot(v[2]);
    const double r = h_m * axis.cwiseAbs().sum();
    return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
  };
  for (int a = 0; a < 3; ++a) {
    if (separated(Vec3::Unit(a))) return false;
  }
  const Vec3 e[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
  if (separated(e[0].cross(e[1]))) return false;
  for (int a = 0; a < 3; ++a) {
    for (const Vec3& edge : e) {
      if (separated(Vec3::Unit(a).cross(edge))) return false;
    }
  }
  return true;
}

// counting sort of (cell, id) pairs into CSR arrays; ids keep their order within a cell
void fill_csr(const std::vector<std::pair<int32_t, int32_t>>& pairs, int64_t num_cells,
              std::vector<int32_t>* offsets, std::vector<int32_t>* ids) {
  offsets->assign(static_cast<std::size_t>(num_cells) + 1, 0);
  for (const auto& [cell, id] : pairs) ++(*offsets)[cell + 1];
  for (int64_t c = 0; c < num_cells; ++c) (*offsets)[c + 1] += (*offsets)[c];
  ids->resize(pairs.size());
  std::vector<int32_t> cursor(offsets->begin(), offsets->end() - 1);
  for (const auto& [cell, id] : pairs) (*ids)[cursor[cell]++] = id;
}

}  // namespace

GridHierarchy::GridHierarchy() {
  build_leaf_lists(TriMesh{});
  build_flags();
  build_solid_fractions(TriMesh{});
}

Result<GridHierarchy> GridHierarchy::build(const TriMesh& mesh, const Aabb& cube, int levels) {
  if (levels < 1 || levels > kMaxLevels) {
    return make_error("grid levels ", std::to_string(levels), " out of range [1, ", std::to_string(kMaxLevels),
                      "]");
  }
  const Vec3 extent = cube.extent();
  const double side_m = extent.x();
  const double tol_m = 1e-9 * std::abs(side_m);
  if (!extent.allFinite() || !(side_m > 0.0) || std::abs(extent.y() - side_m) > tol_m ||
      std::abs(extent.z() - side_m) > tol_m) {
    return make_error("grid cube extent ", fmt_vec(extent), " is not a cube of positive finite side");
  }
  const std::size_t nv = mesh.vertices_m.size();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int32_t v : mesh.triangles[t]) {
      if (v < 0 || static_cast<std::size_t>(v) >= nv) {
        return make_error("grid: triangle ", std::to_string(t), " vertex index ", std::to_string(v),
                          " is beyond the vertex list (size ", std::to_string(nv), ")");
      }
    }
  }
  for (std::size_t v = 0; v < nv; ++v) {
    if (!cube.contains(mesh.vertices_m[v])) {
      return make_error("grid: vertex ", std::to_string(v), " at ", fmt_vec(mesh.vertices_m[v]),
                        " lies outside the cube ", fmt_vec(cube.min_m), " - ", fmt_vec(cube.max_m));
    }
  }

  // the default constructor's empty lists are rebuilt for the real mesh
  GridHierarchy grid;
  grid.levels_ = levels;
  grid.cube_ = cube;
  grid.side_m_ = side_m;
  grid.num_vertices_ = nv;
  grid.num_triangles_ = mesh.triangles.size();
  grid.build_leaf_lists(mesh);
  grid.build_flags();
  grid.build_solid_fractions(mesh);
  return grid;
}

void GridHierarchy::build_leaf_lists(const TriMesh& mesh) {
  const int leaf = levels_;
  const double cell_m = cell_size_m(leaf);
  const double slack_m = kOverlapSlack * cell_m;
  std::vector<std::pair<int32_t, int32_t>> pairs;

  // vertices: one leaf each
  pairs.reserve(mesh.vertices_m.size());
  for (std::size_t v = 0; v < mesh.vertices_m.size(); ++v) {
    pairs.emplace_back(linear_index(cell_of(mesh.vertices_m[v], leaf), leaf), static_cast<int32_t>(v));
  }
  fill_csr(pairs, num_cells(leaf), &leaf_vertex_offsets_, &leaf_vertex_ids_);

  // triangles: the leaves of their vertices, plus every leaf in their bounding box that the SAT test accepts
  pairs.clear();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3& a = mesh.vertices_m[tri[0]];
    const Vec3& b = mesh.vertices_m[tri[1]];
    const Vec3& d = mesh.vertices_m[tri[2]];
    const int32_t own[3] = {linear_index(cell_of(a, leaf), leaf), linear_index(cell_of(b, leaf), leaf),
                            linear_index(cell_of(d, leaf), leaf)};
    const CellCoord lo = cell_of(a.cwiseMin(b).cwiseMin(d) - Vec3::Constant(slack_m), leaf);
    const CellCoord hi = cell_of(a.cwiseMax(b).cwiseMax(d) + Vec3::Constant(slack_m), leaf);
    for (int k = lo.k; k <= hi.k; ++k) {
      for (int j = lo.j; j <= hi.j; ++j) {
        for (int i = lo.i; i <= hi.i; ++i) {
          const CellCoord c{i, j, k};
          const int32_t cell = linear_index(c, leaf);
          const bool holds_vertex = cell == own[0] || cell == own[1] || cell == own[2];
          const Vec3 center_m = cell_min_m(c, leaf) + Vec3::Constant(0.5 * cell_m);
          if (holds_vertex || triangle_overlaps_box(center_m, 0.5 * cell_m + slack_m, a, b, d)) {
            pairs.emplace_back(cell, static_cast<int32_t>(t));
          }
        }
      }
    }
  }
  fill_csr(pairs, num_cells(leaf), &leaf_triangle_offsets_, &leaf_triangle_ids_);
}

void GridHierarchy::build_flags() {
  surface_.assign(levels_, {});
  solid_.assign(levels_, {});
  surface_count_.assign(levels_, 0);
  solid_count_.assign(levels_, 0);

  // surface: leaves from their lists, coarser levels as the OR of their children
  const int leaf = levels_;
  std::vector<uint8_t>& leaf_surface = surface_[leaf - 1];
  leaf_surface.assign(num_cells(leaf), 0);
  for (int64_t c = 0; c < num_cells(leaf); ++c) {
    leaf_surface[c] = leaf_vertex_offsets_[c + 1] > leaf_vertex_offsets_[c] ||
                      leaf_triangle_offsets_[c + 1] > leaf_triangle_offsets_[c];
  }
  for (int level = leaf - 1; level >= 1; --level) {
    surface_[level - 1].assign(num_cells(level), 0);
    for (int64_t c = 0; c < num_cells(level + 1); ++c) {
      surface_[level - 1][parent(static_cast<int32_t>(c), level + 1)] |= surface_[level][c];
    }
  }

  // solid: everything a 6-connected flood of empty cells from the border does not reach
  std::vector<int32_t> queue;
  for (int level = 1; level <= levels_; ++level) {
    const int n = cells_per_axis(level);
    const std::vector<uint8_t>& surface = surface_[level - 1];
    std::vector<uint8_t> outside(num_cells(level), 0);
    queue.clear();
    auto visit = [&](int i, int j, int k) {
      const int32_t c = linear_index({i, j, k}, level);
      if (!surface[c] && !outside[c]) {
        outside[c] = 1;
        queue.push_back(c);
      }
    };
    for (int k = 0; k < n; ++k) {
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          if (i == 0 || j == 0 || k == 0 || i == n - 1 || j == n - 1 || k == n - 1) visit(i, j, k);
        }
      }
    }
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const CellCoord c = coord_of(queue[head], level);
      if (c.i > 0) visit(c.i - 1, c.j, c.k);
      if (c.i < n - 1) visit(c.i + 1, c.j, c.k);
      if (c.j > 0) visit(c.i, c.j - 1, c.k);
      if (c.j < n - 1) visit(c.i, c.j + 1, c.k);
      if (c.k > 0) visit(c.i, c.j, c.k - 1);
      if (c.k < n - 1) visit(c.i, c.j, c.k + 1);
    }
    std::vector<uint8_t>& solid = solid_[level - 1];
    solid.resize(outside.size());
    for (std::size_t c = 0; c < outside.size(); ++c) {
      solid[c] = !outside[c];
      solid_count_[level - 1] += solid[c];
      surface_count_[level - 1] += surface[c];
    }
  }
}

int64_t GridHierarchy::num_cells(int level) const {
  const int64_t n = cells_per_axis(level);
  return n * n * n;
}

double GridHierarchy::cell_size_m(int level) const { return side_m_ / cells_per_axis(level); }

CellCoord GridHierarchy::cell_of(const Vec3& p_m, int level) const {
  const int n = cells_per_axis(level);
  const double inv_cell = 1.0 / cell_size_m(level);
  int idx[3];
  for (int a = 0; a < 3; ++a) {
    const double t = (p_m[a] - cube_.min_m[a]) * inv_cell;
    // NaN fails t >= 0 and lands in cell 0
    idx[a] = t >= 0.0 ? (t < n ? static_cast<int>(t) : n - 1) : 0;
  }
  return {idx[0], idx[1], idx[2]};
}

int32_t GridHierarchy::linear_index(const CellCoord& c, int level) const {
  const int n = cells_per_axis(level);
  assert(c.i >= 0 && c.i < n && c.j >= 0 && c.j < n && c.k >= 0 && c.k < n);
  return c.i + n * (c.j + n * c.k);
}

CellCoord GridHierarchy::coord_of(int32_t index, int level) const {
  const int n = cells_per_axis(level);
  assert(index >= 0 && index < num_cells(level));
  return {index % n, (index / n) % n, index / (n * n)};
}

Vec3 GridHierarchy::cell_min_m(const CellCoord& c, int level) const {
  return cube_.min_m + cell_size_m(level) * Vec3(c.i, c.j, c.k);
}

int32_t GridHierarchy::parent(int32_t index, int level) const {
  assert(level >= 2 && level <= levels_);
  const CellCoord c = coord_of(index, level);
  return linear_index({c.i / 2, c.j / 2, c.k / 2}, level - 1);
}

std::array<int32_t, 8> GridHierarchy::children(int32_t index, int level) const {
  assert(level >= 1 && level < levels_);
  const CellCoord c = coord_of(index, level);
  std::array<int32_t, 8> out{};
  for (int b = 0; b < 8; ++b) {
    out[b] = linear_index({2 * c.i + (b & 1), 2 * c.j + ((b >> 1) & 1), 2 * c.k + ((b >> 2) & 1)}, level + 1);
  }
  return out;
}

std::span<const int32_t> GridHierarchy::leaf_vertices(int32_t leaf) const {
  assert(leaf >= 0 && leaf < num_cells(levels_));
  const int32_t begin = leaf_vertex_offsets_[leaf];
  return {leaf_vertex_ids_.data() + begin, static_cast<std::size_t>(leaf_vertex_offsets_[leaf + 1] - begin)};
}

std::span<const int32_t> GridHierarchy::leaf_triangles(int32_t leaf) const {
  assert(leaf >= 0 && leaf < num_cells(levels_));
  const int32_t begin = leaf_triangle_offsets_[leaf];
  return {leaf_triangle_ids_.data() + begin, static_cast<std::size_t>(leaf_triangle_offsets_[leaf + 1] - begin)};
}

bool GridHierarchy::surface_cell(int32_t index, int level) const {
  assert(level >= 1 && level <= levels_ && index >= 0 && index < num_cells(level));
  return surface_[level - 1][index] != 0;
}

bool GridHierarchy::solid_cell(int32_t index, int level) const {
  assert(level >= 1 && level <= levels_ && index >= 0 && index < num_cells(level));
  return solid_[level - 1][index] != 0;
}

int64_t GridHierarchy::surface_cells(int level) const { return surface_count_[level - 1]; }

int64_t GridHierarchy::solid_cells(int level) const { return solid_count_[level - 1]; }

void GridHierarchy::triangles_near(const Vec3& lo_m, const Vec3& hi_m, std::vector<int32_t>* out,
                                   std::vector<int32_t>* scratch) const {
  out->clear();
  // NaN fails <= as well
  if (!(lo_m.array() <= hi_m.array()).all()) return;
  if ((hi_m.array() < cube_.min_m.array()).any() || (lo_m.array() > cube_.max_m.array()).any()) return;
  const CellCoord lo = cell_of(lo_m, levels_);
  const CellCoord hi = cell_of(hi_m, levels_);
  for (int k = lo.k; k <= hi.k; ++k) {
    for (int j = lo.j; j <= hi.j; ++j) {
      for (int i = lo.i; i <= hi.i; ++i) {
        const std::span<const int32_t> ids = leaf_triangles(linear_index({i, j, k}, levels_));
        out->insert(out->end(), ids.begin(), ids.end());
      }
    }
  }
  // least significant digit first, 11 bits a pass (ids are below num_triangles_): linear in the ids gathered
  std::vector<int32_t> local;
  std::vector<int32_t>& tmp = scratch != nullptr ? *scratch : local;
  tmp.resize(out->size());
  constexpr int kBits = 11;
  constexpr uint32_t kMask = (1u << kBits) - 1;
  std::array<int32_t, (1u << kBits) + 1> count{};
  for (int shift = 0; shift < 31 && (static_cast<uint64_t>(num_triangles_) >> shift) > 0; shift += kBits) {
    count.fill(0);
    for (int32_t id : *out) ++count[((static_cast<uint32_t>(id) >> shift) & kMask) + 1];
    for (std::size_t d = 1; d < count.size(); ++d) count[d] += count[d - 1];
    for (int32_t id : *out) tmp[static_cast<std::size_t>(count[(static_cast<uint32_t>(id) >> shift) & kMask]++)] = id;
    out->swap(tmp);
  }
  out->erase(std::unique(out->begin(), out->end()), out->end());
}

}  // namespace palpate
