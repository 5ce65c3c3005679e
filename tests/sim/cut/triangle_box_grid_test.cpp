// The triangles by grid cell gives what testing every triangle's box gives — after build, after corners move far
// across the grid (a cut's pieces falling apart), and after triangles are appended — and tests only the triangles near
// the box.
#include "sim/cut/triangle_box_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace palpate {
namespace {

struct Mesh {
  std::vector<Vec3> v;
  std::vector<std::array<int32_t, 3>> t;
};

// a 40 x 40 sheet of quads over [0, 1]^2, two triangles each, its heights jittered
Mesh sheet() {
  Mesh m;
  const int n = 40;
  std::mt19937 g(7);
  std::uniform_real_distribution<double> jitter(-0.01, 0.01);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.v.push_back(Vec3(static_cast<double>(i) / n, static_cast<double>(j) / n, jitter(g)));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      m.t.push_back({a, b, c});
      m.t.push_back({a, c, d});
    }
  return m;
}

std::vector<int32_t> brute(const Mesh& m, const Vec3& lo, const Vec3& hi) {
  std::vector<int32_t> out;
  for (int32_t i = 0; i < static_cast<int32_t>(m.t.size()); ++i) {
    const auto& t = m.t[static_cast<std::size_t>(i)];
    if (triangle_box_overlaps(m.v[t[0]], m.v[t[1]], m.v[t[2]], lo, hi)) out.push_back(i);
  }
  return out;
}

// random boxes over and beyond the sheet, each compared with testing every triangle
void expect_queries_match(TriangleBoxGrid& grid, const Mesh& m, uint32_t seed, std::size_t* tested_most) {
  std::mt19937 g(seed);
  std::uniform_real_distribution<double> at(-0.2, 1.4), size(0.0, 0.1);
  std::vector<int32_t> got;
  for (int q = 0; q < 300; ++q) {
    const Vec3 lo(at(g), at(g), -0.05), hi = lo + Vec3(size(g), size(g), 0.1 + size(g));
    grid.query(m.v, m.t, lo, hi, &got);
    ASSERT_EQ(got, brute(m, lo, hi)) << "query " << q;
    *tested_most = std::max(*tested_most, grid.last_tested());
  }
}

TEST(TriangleBoxGrid, QueriesGiveWhatTestingEveryTriangleGivesAfterMovesAndAppends) {
  Mesh m = sheet();
  TriangleBoxGrid grid;
  grid.build(m.v, m.t);
  ASSERT_EQ(grid.size(), m.t.size());
  std::size_t tested = 0;
  expect_queries_match(grid, m, 1, &tested);
  // a box query tests the triangles near it, not the sheet's 3200
  EXPECT_LT(tested, m.t.size() / 10);

  // a corner of every 7th vertex's triangles moved 0.3 across the sheet (and one 0.3 beyond it): the triangles at
  // those vertices are re-filed where their boxes are now
  std::vector<bool> moved(m.v.size(), false);
  for (std::size_t k = 0; k < m.v.size(); k += 7) {
    m.v[k] += Vec3(0.3, k % 2 ? 0.25 : -0.25, 0.02);
    moved[k] = true;
  }
  for (int32_t i = 0; i < static_cast<int32_t>(m.t.size()); ++i) {
    const auto& t = m.t[static_cast<std::size_t>(i)];
    if (moved[static_cast<std::size_t>(t[0])] || moved[static_cast<std::size_t>(t[1])] ||
        moved[static_cast<std::size_t>(t[2])])
      grid.update(i, m.v, m.t);
  }
  expect_queries_match(grid, m, 2, &tested);

  // a slot given another triangle, and triangles appended (a cut's new faces)
  m.t[5] = {0, 40, 1680};
  grid.update(5, m.v, m.t);
  for (int k = 0; k < 20; ++k) {
    m.v.push_back(Vec3(1.1 + 0.01 * k, 0.5, 0.0));
    m.t.push_back({static_cast<int32_t>(m.v.size()) - 1, 100 + k, 900 + k});
    grid.update(static_cast<int32_t>(m.t.size()) - 1, m.v, m.t);
  }
  ASSERT_EQ(grid.size(), m.t.size());
  expect_queries_match(grid, m, 3, &tested);

  // a corner that is not finite, then back: its triangles are filed as reaching everywhere, and back in their cells
  auto update_at = [&](int32_t v) {
    for (int32_t i = 0; i < static_cast<int32_t>(m.t.size()); ++i)
      for (int32_t c : m.t[static_cast<std::size_t>(i)])
        if (c == v) grid.update(i, m.v, m.t);
  };
  const Vec3 kept = m.v[45];
  m.v[45] = Vec3(NAN, 0.5, 0.0);
  update_at(45);
  expect_queries_match(grid, m, 4, &tested);
  m.v[45] = kept;
  update_at(45);
  expect_queries_match(grid, m, 5, &tested);
}

}  // namespace
}  // namespace palpate
