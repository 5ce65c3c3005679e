// Loaded meshes keep their geometry: positions and faces as the file states them (parsed here independently),
// outward winding (positive signed volume), in every format the loader reads.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/mesh_io.h"
#include "support/fixtures.h"
#include "support/temp_root.h"

namespace palpate {
namespace {

// Signed volume by the divergence theorem: positive for a closed mesh wound counter-clockwise from outside.
double signed_volume(const TriMesh& m) {
  double v = 0.0;
  for (const auto& t : m.triangles)
    v += m.vertices_m[t[0]].dot(m.vertices_m[t[1]].cross(m.vertices_m[t[2]])) / 6.0;
  return v;
}

// The bunny's vertices and faces read straight from its OBJ text.
TriMesh parse_obj(const std::string& path) {
  TriMesh m;
  std::ifstream f(path);
  std::string line;
  while (std::getline(f, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      double x, y, z;
      s >> x >> y >> z;
      m.vertices_m.emplace_back(x, y, z);
    } else if (tag == "f") {
      std::array<int32_t, 3> t{};
      for (int32_t& i : t) {
        std::string tok;
        s >> tok;
        i = std::stoi(tok.substr(0, tok.find('/'))) - 1;
      }
      m.triangles.push_back(t);
    }
  }
  return m;
}

TEST(MeshGeometry, BunnyLoadsAsItsFileStatesWithOutwardWinding) {
  const std::string path = test::source_path("scenes/bunny.obj");
  const TriMesh ref = parse_obj(path);
  ASSERT_EQ(ref.triangles.size(), 3674u);
  auto loaded = load_mesh(path);
  ASSERT_TRUE(loaded) << loaded.error().message;
  const TriMesh& m = loaded.value();
  ASSERT_EQ(m.vertices_m.size(), ref.vertices_m.size());  // shared vertices joined back
  ASSERT_EQ(m.triangles.size(), ref.triangles.size());
  // the importer may renumber vertices, not move them nor reorder corners: each face's corners, in order,
  // sit where the file puts them (a reversed winding or a swapped axis shows here and in the volume's sign)
  double max_dv = 0.0;
  for (std::size_t t = 0; t < m.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c)
      max_dv = std::max(max_dv, (m.vertices_m[m.triangles[t][c]] - ref.vertices_m[ref.triangles[t][c]]).cwiseAbs().maxCoeff());
  EXPECT_LT(max_dv, 1e-6);  // single-precision storage in the importer
  EXPECT_GT(signed_volume(m), 0.0);
  EXPECT_NEAR(signed_volume(m), signed_volume(ref), 1e-6 * std::abs(signed_volume(ref)));
}

// A closed box written as OFF, ASCII PLY and ASCII STL loads with positive volume equal to the box's.
TEST(MeshGeometry, BoxInEveryFormatHasOutwardWindingAndItsVolume) {
  const TriMesh box = make_box_mesh(Vec3(2.0, 3.0, 4.0), 1);
  ASSERT_NEAR(signed_volume(box), 24.0, 1e-12);
  const std::filesystem::path dir = std::filesystem::path(test::temp_root()) / "geometry";
  std::filesystem::create_directories(dir);
  std::ostringstream off, ply, stl;
  off << "OFF\n" << box.vertices_m.size() << " " << box.triangles.size() << " 0\n";
  ply << "ply\nformat ascii 1.0\nelement vertex " << box.vertices_m.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << box.triangles.size()
      << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Vec3& v : box.vertices_m) {
    off << v.x() << " " << v.y() << " " << v.z() << "\n";
    ply << v.x() << " " << v.y() << " " << v.z() << "\n";
  }
  stl << "solid box\n";
  for (const auto& t : box.triangles) {
    off << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
    ply << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
    const Vec3 n = (box.vertices_m[t[1]] - box.vertices_m[t[0]]).cross(box.vertices_m[t[2]] - box.vertices_m[t[0]]).normalized();
    stl << " facet normal " << n.x() << " " << n.y() << " " << n.z() << "\n  outer loop\n";
    for (int32_t i : t) stl << "   vertex " << box.vertices_m[i].x() << " " << box.vertices_m[i].y() << " " << box.vertices_m[i].z() << "\n";
    stl << "  endloop\n endfacet\n";
  }
  stl << "endsolid box\n";
  for (const auto& [name, text] : {std::pair<std::string, std::string>{"box.off", off.str()}, {"box.ply", ply.str()}, {"box.stl", stl.str()}}) {
    const std::string path = (dir / name).string();
    std::ofstream(path) << text;
    auto m = load_mesh(path);
    ASSERT_TRUE(m) << name << ": " << m.error().message;
    EXPECT_NEAR(signed_volume(m.value()), 24.0, 1e-5) << name;
  }
}

}  // namespace
}  // namespace palpate
