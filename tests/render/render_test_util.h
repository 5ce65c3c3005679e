#pragma once
/// Helpers shared by the render tests: a scratch directory, a box mesh, pixel access and comparison.

#include <unistd.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "core/tri_mesh.h"
#include "support/temp_root.h"

namespace palpate::test {

/// A fresh directory under the process's temp_root(), removed with its contents on destruction.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& tag) {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::path(temp_root()) / (tag + "_" + std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  /// The directory path.
  std::string str() const { return path_.string(); }
  /// A file path inside the directory.
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

/// An axis-aligned box with 12 outward counter-clockwise triangles.
inline TriMesh make_box_mesh(const Vec3& lo, const Vec3& hi) {
  TriMesh mesh;
  for (int i = 0; i < 8; ++i) {
    mesh.vertices_m.emplace_back((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  }
  mesh.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                    {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return mesh;
}

/// RGBA of pixel (x, y) in a top-down image of the given width.
inline std::array<int, 4> pixel(const std::vector<uint8_t>& rgba, int width, int x, int y) {
  const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 4;
  return {rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]};
}

/// Pixels whose RGB differ between two RGBA images of the same size.
inline int count_different(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  int n = 0;
  for (std::size_t i = 0; i < a.size(); i += 4) n += a[i] != b[i] || a[i + 1] != b[i + 1] || a[i + 2] != b[i + 2];
  return n;
}

}  // namespace palpate::test
