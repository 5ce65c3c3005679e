#include "sim/cut/triangle_box_grid.h"

#include <algorithm>
#include <cmath>

namespace palpate {

namespace {

// cells per triangle the grid aims at, and the most cells along an axis
constexpr double kCellsPerTriangle = 2.0;
constexpr int32_t kMaxCellsPerAxis = 1024;
// a triangle whose box reaches more cells than this (a sliver across the model, a corner that is not finite) is
// kept in one list that every query tests, not in each of its cells
constexpr int64_t kWideCells = 64;

}  // namespace

void TriangleBoxGrid::build(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles) {
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  for (const auto& t : triangles)
    for (int32_t v : t)
      if (vertices_m[static_cast<std::size_t>(v)].allFinite()) {
        lo = lo.cwiseMin(vertices_m[static_cast<std::size_t>(v)]);
        hi = hi.cwiseMax(vertices_m[static_cast<std::size_t>(v)]);
      }
  if (!(lo.array() <= hi.array()).all()) lo = hi = Vec3::Zero();
  // the cell edge that gives about kCellsPerTriangle cells a triangle over the axes longer than a cell (a flat
  // mesh is one cell thick)
  const Vec3 extent = (hi - lo).cwiseMax(Vec3::Constant(1e-12));
  const double target = std::max(1.0, kCellsPerTriangle * static_cast<double>(triangles.size()));
  double cell = std::cbrt(extent.prod() / target);
  for (int pass = 0; pass < 2; ++pass) {
    double product = 1.0;
    int axes = 0;
    for (int k = 0; k < 3; ++k)
      if (extent[k] >= cell) {
        product *= extent[k];
        ++axes;
      }
    if (axes > 0) cell = std::pow(product / target, 1.0 / axes);
  }
  cell_m_ = std::max(cell, extent.maxCoeff() / kMaxCellsPerAxis);
  origin_m_ = lo;
  for (int k = 0; k < 3; ++k)
    dims_[static_cast<std::size_t>(k)] =
        std::clamp(static_cast<int32_t>(std::ceil(extent[k] / cell_m_)), int32_t{1}, kMaxCellsPerAxis);
  // a list only for the cells a triangle reaches: a surface fills few of its box's cells
  slot_of_cell_.assign(static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2], -1);
  lists_.clear();
  wide_.clear();
  // room for the triangles cuts add, so an append in a frame never moves the whole array (at 200k triangles that
  // took 69 ms on the first splitting frame)
  const std::size_t room = triangles.size() + triangles.size() / 4 + 1024;
  ranges_.reserve(room);
  stamp_.reserve(room);
  ranges_.resize(triangles.size());
  stamp_.assign(triangles.size(), 0u);
  // each list's entries counted first, so each is allocated once
  std::vector<int32_t> counts;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    ranges_[t] = box_range(vertices_m, triangles[t]);
    if (wide(ranges_[t])) continue;
    for_cells(ranges_[t], [&](std::size_t i) {
      int32_t& slot = slot_of_cell_[i];
      if (slot < 0) {
        slot = static_cast<int32_t>(counts.size());
        counts.push_back(0);
      }
      ++counts[static_cast<std::size_t>(slot)];
    });
  }
  lists_.resize(counts.size());
  for (std::size_t i = 0; i < counts.size(); ++i) lists_[i].reserve(static_cast<std::size_t>(counts[i]));
  for (std::size_t t = 0; t < triangles.size(); ++t) add(static_cast<int32_t>(t));
}

bool TriangleBoxGrid::wide(const CellRange& r) {
  int64_t cells = 1;
  for (std::size_t k = 0; k < 3; ++k) cells *= std::max<int64_t>(0, int64_t{r[k + 3]} - r[k] + 1);
  return cells > kWideCells;
}

void TriangleBoxGrid::add(int32_t t) {
  const CellRange& r = ranges_[static_cast<std::size_t>(t)];
  if (wide(r)) {
    wide_.push_back(t);
    return;
  }
  for_cells(r, [&](std::size_t cell) {
    int32_t& slot = slot_of_cell_[cell];
    if (slot < 0) {
      slot = static_cast<int32_t>(lists_.size());
      lists_.emplace_back();
    }
    lists_[static_cast<std::size_t>(slot)].push_back(t);
  });
}

TriangleBoxGrid::CellRange TriangleBoxGrid::box_range(const std::vector<Vec3>& vertices_m,
                                                      const std::array<int32_t, 3>& tri) const {
  const Vec3& a = vertices_m[static_cast<std::size_t>(tri[0])];
  const Vec3& b = vertices_m[static_cast<std::size_t>(tri[1])];
  const Vec3& c = vertices_m[static_cast<std::size_t>(tri[2])];
  return range_of(a.cwiseMin(b).cwiseMin(c), a.cwiseMax(b).cwiseMax(c));
}

TriangleBoxGrid::CellRange TriangleBoxGrid::range_of(const Vec3& lo_m, const Vec3& hi_m) const {
  CellRange r{0, 0, 0, dims_[0] - 1, dims_[1] - 1, dims_[2] - 1};
  // a box with a corner that is not finite reaches every cell (its triangle is then always tested)
  if (!lo_m.allFinite() || !hi_m.allFinite()) return r;
  for (std::size_t k = 0; k < 3; ++k) {
    // clamped: a box beyond the grid goes to the border cells, and clamping keeps overlapping ranges overlapping
    auto index = [&](double x) {
      const double i = std::floor((x - origin_m_[static_cast<Eigen::Index>(k)]) / cell_m_);
      return static_cast<int32_t>(std::clamp(i, 0.0, static_cast<double>(dims_[k] - 1)));
    };
    r[k] = index(lo_m[static_cast<Eigen::Index>(k)]);
    r[k + 3] = index(hi_m[static_cast<Eigen::Index>(k)]);
  }
  return r;
}

template <class F>
void TriangleBoxGrid::for_cells(const CellRange& r, F f) const {
  for (int32_t z = r[2]; z <= r[5]; ++z)
    for (int32_t y = r[1]; y <= r[4]; ++y)
      for (int32_t x = r[0]; x <= r[3]; ++x)
        f((static_cast<std::size_t>(z) * dims_[1] + static_cast<std::size_t>(y)) * dims_[0] + static_cast<std::size_t>(x));
}

void TriangleBoxGrid::update(int32_t t, const std::vector<Vec3>& vertices_m,
                             const std::vector<std::array<int32_t, 3>>& triangles) {
  const auto i = static_cast<std::size_t>(t);
  auto drop = [t](std::vector<int32_t>& ids) {
    const auto it = std::find(ids.begin(), ids.end(), t);
    if (it == ids.end()) return;
    *it = ids.back();
    ids.pop_back();
  };
  if (i < ranges_.size()) {
    if (wide(ranges_[i])) {
      drop(wide_);
    } else {
      for_cells(ranges_[i], [&](std::size_t cell) {
        const int32_t slot = slot_of_cell_[cell];
        if (slot >= 0) drop(lists_[static_cast<std::size_t>(slot)]);
      });
    }
  } else {
    ranges_.resize(i + 1, CellRange{0, 0, 0, -1, -1, -1});
    stamp_.resize(i + 1, 0);
  }
  ranges_[i] = box_range(vertices_m, triangles[i]);
  add(t);
}

void TriangleBoxGrid::query(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles,
                            const Vec3& lo_m, const Vec3& hi_m, std::vector<int32_t>* out) {
  out->clear();
  last_tested_ = 0;
  if (++query_ == 0) {
    std::fill(stamp_.begin(), stamp_.end(), 0u);
    query_ = 1;
  }
  auto test = [&](const std::vector<int32_t>& ids) {
    for (int32_t t : ids) {
      if (stamp_[static_cast<std::size_t>(t)] == query_) continue;
      stamp_[static_cast<std::size_t>(t)] = query_;
      ++last_tested_;
      const auto& tri = triangles[static_cast<std::size_t>(t)];
      if (triangle_box_overlaps(vertices_m[static_cast<std::size_t>(tri[0])], vertices_m[static_cast<std::size_t>(tri[1])],
                                vertices_m[static_cast<std::size_t>(tri[2])], lo_m, hi_m))
        out->push_back(t);
    }
  };
  test(wide_);
  for_cells(range_of(lo_m, hi_m), [&](std::size_t cell) {
    const int32_t slot = slot_of_cell_[cell];
    if (slot >= 0) test(lists_[static_cast<std::size_t>(slot)]);
  });
  // the order of a test of every triangle
  std::sort(out->begin(), out->end());
}

}  // namespace palpate
