// Every valid OFF, PLY and STL file loads: one test per grammar case of each format (and text files of OBJ too with
// a byte order mark or in UTF-16), the same tetrahedron or
// square written every way, and what is refused refused with its reason.
#include "support/temp_root.h"
#include "core/mesh_io.h"
#include "core/text_encoding.h"
#include "core/aabb.h"
#include "core/tri_mesh.h"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace palpate {
namespace {

namespace fs = std::filesystem;

class MeshGrammarTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(test::temp_root()) / (std::string("grammar_") + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& bytes) const {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << bytes;
    return p.string();
  }
  // loads in this process (the grammar is what is tested, not the child)
  Result<TriMesh> load(const std::string& name, const std::string& bytes) const {
    MeshReadOptions o;
    o.isolation = MeshReaderIsolation::in_process;
    return load_mesh(write(name, bytes), o);
  }
  std::string error(const std::string& name, const std::string& bytes) const {
    auto r = load(name, bytes);
    if (r) return "loaded";
    const std::string prefix = "mesh '" + (dir_ / name).string() + "': ";
    EXPECT_EQ(r.error().message.rfind(prefix, 0), 0u) << r.error().message;
    return r.error().message.substr(std::min(prefix.size(), r.error().message.size()));
  }

  fs::path dir_;
};

// the unit tetrahedron: 4 vertices, 4 outward triangles, volume 1/6
void expect_tetrahedron(const Result<TriMesh>& r, double scale = 1.0) {
  ASSERT_TRUE(r) << r.error().message;
  const TriMesh& m = r.value();
  EXPECT_EQ(m.num_vertices(), 4u);
  ASSERT_EQ(m.num_triangles(), 4u);
  double volume = 0;
  for (const auto& t : m.triangles) volume += m.vertices_m[t[0]].dot(m.vertices_m[t[1]].cross(m.vertices_m[t[2]])) / 6.0;
  EXPECT_NEAR(volume, scale * scale * scale / 6.0, 1e-6 * scale * scale * scale);
}

const char* kTetraVertices = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
const char* kTetraFaces = "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

std::string be32(uint32_t u) {
  std::string s(4, '\0');
  for (int k = 0; k < 4; ++k) s[static_cast<std::size_t>(k)] = static_cast<char>(u >> (24 - 8 * k));
  return s;
}
std::string le(uint64_t u, int bytes) {
  std::string s(static_cast<std::size_t>(bytes), '\0');
  for (int k = 0; k < bytes; ++k) s[static_cast<std::size_t>(k)] = static_cast<char>(u >> (8 * k));
  return s;
}
std::string be(uint64_t u, int bytes) {
  std::string s = le(u, bytes);
  return std::string(s.rbegin(), s.rend());
}

// --- OFF -------------------------------------------------------------------------------------------------------

TEST_F(MeshGrammarTest, OffBlankLineAfterTheCountsAsManyExportersWrite) {
  expect_tetrahedron(load("blank.off", std::string("OFF\n4 4 0\n\n") + kTetraVertices + kTetraFaces));
}

TEST_F(MeshGrammarTest, OffCommentsAndBlankLinesWhereverALineMayBe) {
  expect_tetrahedron(load("comments.off", "OFF # keyword\n# counts next\n\n4 4 0 # v f e\n0 0 0\n\n# a comment\n1 0 0 # x\n"
                                          "0 1 0\n   \n0 0 1\n\n# faces\n3 0 2 1\n\n3 0 1 3 # second\n3 0 3 2\n\t\n3 1 2 3\n# end\n"));
}

TEST_F(MeshGrammarTest, OffCommentLinesBeforeTheKeyword) {
  std::string head;
  for (int i = 0; i < 8; ++i) head += "# exported by a scanner, line " + std::to_string(i) + "\n";
  expect_tetrahedron(load("lead.off", head + "OFF\n4 4 0\n" + kTetraVertices + kTetraFaces));
}

TEST_F(MeshGrammarTest, OffCountsOnTheKeywordLineOrWithoutAKeyword) {
  expect_tetrahedron(load("same_line.off", std::string("OFF 4 4 0\n") + kTetraVertices + kTetraFaces));
  expect_tetrahedron(load("no_keyword.off", std::string("4 4 0\n") + kTetraVertices + kTetraFaces));
  expect_tetrahedron(load("no_edges.off", std::string("OFF\n4 4\n") + kTetraVertices + kTetraFaces));
}

TEST_F(MeshGrammarTest, OffLineEndsCrlfAndCr) {
  std::string text = std::string("OFF\n4 4 0\n\n") + kTetraVertices + kTetraFaces;
  std::string crlf, cr;
  for (char c : text) {
    crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    cr += c == '\n' ? '\r' : c;
  }
  expect_tetrahedron(load("crlf.off", crlf));
  expect_tetrahedron(load("cr.off", cr));
}

TEST_F(MeshGrammarTest, OffVariantsWithNormalsColoursAndTextureCoordinates) {
  // each variant's vertex line carries its extra values after x y z; faces may carry a colour
  const std::string n = "OFF\n4 4 0\n0 0 0 0 0 -1\n1 0 0 1 0 0\n0 1 0 0 1 0\n0 0 1 0 0 1\n";
  expect_tetrahedron(load("n.off", "N" + n + kTetraFaces));
  expect_tetrahedron(load("c.off", std::string("COFF\n4 4 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n0 0 1 9 9 9 255\n") +
                                       "3 0 2 1 1 0 0\n3 0 1 3 0 1 0 1\n3 0 3 2 7\n3 1 2 3\n"));
  expect_tetrahedron(load("st.off", "STOFF\n4 4 0\n0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 1\n0 0 1 1 1\n" + std::string(kTetraFaces)));
  expect_tetrahedron(load("cn.off", "CNOFF\n4 4 0\n0 0 0 0 0 -1 1 1 1 1\n1 0 0 1 0 0 1 1 1 1\n0 1 0 0 1 0 1 1 1 1\n"
                                    "0 0 1 0 0 1 1 1 1 1\n" + std::string(kTetraFaces)));
  expect_tetrahedron(load("stcn.off", "STCNOFF 4 4 0\n0 0 0 0 0 -1 1 1 1 1 0 0\n1 0 0 1 0 0 1 1 1 1 1 0\n0 1 0 0 1 0 1 1 1 1 0 1\n"
                                      "0 0 1 0 0 1 1 1 1 1 1 1\n" + std::string(kTetraFaces)));
}

TEST_F(MeshGrammarTest, OffDimensionAsTheSpecSays) {
  expect_tetrahedron(load("n3.off", std::string("nOFF\n3\n4 4 0\n") + kTetraVertices + kTetraFaces));
  expect_tetrahedron(load("n3_line.off", std::string("nOFF 3 4 4 0\n") + kTetraVertices + kTetraFaces));
  EXPECT_EQ(error("n4.off", "nOFF 4\n4 4 0\n0 0 0 0\n"), "nOFF of dimension 4: only 3-dimensional vertices are read");
  EXPECT_EQ(error("h.off", "4OFF\n4 4 0\n0 0 0 1\n"),
            "4OFF (vertices in homogeneous coordinates x y z w) is not read: divide by w and save as OFF");
  EXPECT_EQ(error("word.off", "OFF99\n4 4 0\n"), "line 1: header keyword 'OFF99' is not [ST][C][N][4][n]OFF");
  EXPECT_EQ(error("order.off", "NCOFF\n4 4 0\n"), "line 1: header keyword 'NCOFF' is not [ST][C][N][4][n]OFF");
}

TEST_F(MeshGrammarTest, OffPolygonsAreTriangulatedConcaveOnesByEars) {
  // an L-shaped hexagon (area 3) and a square (area 1): a fan from corner 0 of the L would cover area outside it
  auto r = load("poly.off", "OFF\n10 2 0\n0 0 0\n2 0 0\n2 1 0\n1 1 0\n1 2 0\n0 2 0\n5 0 0\n6 0 0\n6 1 0\n5 1 0\n"
                            "6 0 1 2 3 4 5\n4 6 7 8 9\n");
  ASSERT_TRUE(r) << r.error().message;
  const TriMesh& m = r.value();
  EXPECT_EQ(m.num_triangles(), 6u);
  double area = 0, abs_area = 0;
  for (const auto& t : m.triangles) {
    const double z = (m.vertices_m[t[1]] - m.vertices_m[t[0]]).cross(m.vertices_m[t[2]] - m.vertices_m[t[0]]).z() / 2;
    area += z;
    abs_area += std::abs(z);
  }
  EXPECT_NEAR(area, 4.0, 1e-12);      // counter-clockwise as written
  EXPECT_NEAR(abs_area, 4.0, 1e-12);  // no triangle folded back over the notch
}

TEST_F(MeshGrammarTest, OffBinary) {
  std::string body = be32(4) + be32(4) + be32(0);
  const float v[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const auto& p : v)
    for (float c : p) body += be32(std::bit_cast<uint32_t>(c));
  const int f[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& t : f) {
    body += be32(3);
    for (int i : t) body += be32(static_cast<uint32_t>(i));
    body += be32(0);
  }
  expect_tetrahedron(load("binary.off", "OFF BINARY\n" + body));
}

TEST_F(MeshGrammarTest, OffPointsAndLinesCarryNoSurface) {
  expect_tetrahedron(load("mixed.off", std::string("OFF\n4 6 0\n") + kTetraVertices + "1 0\n2 0 1\n" + kTetraFaces));
  EXPECT_EQ(error("cloud.off", std::string("OFF\n4 0 0\n") + kTetraVertices), "no triangles");
}

TEST_F(MeshGrammarTest, OffDamageIsNamedWithItsLine) {
  EXPECT_EQ(error("index.off", std::string("OFF\n4 2 0\n") + kTetraVertices + "3 0 1 2\n3 0 1 9\n"),
            "line 8: face 1 vertex index 9 is beyond the vertex list (size 4)");
  EXPECT_EQ(error("few.off", std::string("OFF\n4 1 0\n") + kTetraVertices + "4 0 1 2\n"),
            "line 7: face 0 declares 4 vertex indices, its line lists 3");
  EXPECT_EQ(error("none.off", std::string("OFF\n4 1 0\n") + kTetraVertices + "0\n"), "line 7: face 0 declares no vertex indices");
  EXPECT_EQ(error("short.off", "OFF\n4 1 0\n0 0 0\n1 0\n" + std::string(64, '\n')), "line 4: vertex 1: fewer than 3 coordinates on its line");
  EXPECT_EQ(error("word.off", "OFF\n4 1 0\n0 0 0\n1 x 0\n" + std::string(64, '\n')), "line 4: vertex 1: 'x' is not a number");
  EXPECT_EQ(error("ends.off", std::string("OFF\n4 4 0\n") + kTetraVertices + "3 0 1 2\n"), "the file ends after 1 of 4 faces");
  EXPECT_EQ(error("split.off", "OFF\n4\n4 0\n"), "line 2: OFF header: no vertex and face counts on one line");
  EXPECT_EQ(error("huge.off", "OFF\n999999999 999999999 0\n0 0 0\n"),
            "header declares 999999999 vertices and 999999999 faces, more than the 32-byte file can hold");
  EXPECT_EQ(error("nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n"), "NaN coordinate at vertex 1");
  EXPECT_EQ(error("comments.off", "# only\n\n# comments\n"), "no OFF header: the file holds only blank and comment lines");
}

// --- PLY -------------------------------------------------------------------------------------------------------

const char* kPlyFaceHeader = "element face 4\nproperty list uchar int vertex_indices\nend_header\n";

TEST_F(MeshGrammarTest, PlyAsciiWithCommentsExtraPropertiesAndElements) {
  expect_tetrahedron(load("extra.ply", std::string("ply\nformat ascii 1.0\ncomment made by hand\nobj_info scanner 3\n"
                                                   "element vertex 4\nproperty uchar red\nproperty float x\nproperty float nx\n"
                                                   "property float y\nproperty float z\nproperty float confidence\n"
                                                   "element face 4\nproperty uchar flags\nproperty list uchar uint vertex_index\n"
                                                   "property float quality\nelement edge 1\nproperty int vertex1\n"
                                                   "property int vertex2\nend_header\n"
                                                   "255 0 9 0 0 0.5\n0 1 9 0 0 1\n\n0 0 9 1 0 1\n0 0 9 0 1 1\n"
                                                   "7 3 0 2 1 0.5\n7 3 0 1 3 0.5\n7 3 0 3 2 0.5\n7 3 1 2 3 0.5\n0 1\n")));
}

TEST_F(MeshGrammarTest, PlyBinaryBothByteOrdersEveryIndexType) {
  const float v[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const int f[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  struct Case {
    const char* count;
    int count_bytes;
    const char* index;
    int index_bytes;
  };
  for (const bool big : {false, true})
    for (const Case c : {Case{"uchar", 1, "int", 4}, Case{"uint8", 1, "uint32", 4}, Case{"ushort", 2, "ushort", 2},
                         Case{"int", 4, "uchar", 1}, Case{"uint", 4, "int16", 2}}) {
      auto put = [&](uint64_t u, int bytes) { return big ? be(u, bytes) : le(u, bytes); };
      std::string body;
      for (const auto& p : v) {
        for (float x : p) body += put(std::bit_cast<uint32_t>(x), 4);
        body += put(std::bit_cast<uint64_t>(0.25), 8);  // a double property after x y z
      }
      for (const auto& t : f) {
        body += put(3, c.count_bytes);
        for (int i : t) body += put(static_cast<uint64_t>(i), c.index_bytes);
      }
      const std::string header = std::string("ply\r\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
                                 " 1.0\r\nelement vertex 4\r\nproperty float32 x\r\nproperty float y\r\nproperty float z\r\n"
                                 "property double s\r\nelement face 4\r\nproperty list " + c.count + " " + c.index +
                                 " vertex_indices\r\nend_header\r\n";
      SCOPED_TRACE(header);
      expect_tetrahedron(load("binary.ply", header + body));
    }
}

TEST_F(MeshGrammarTest, PlyDoubleCoordinatesAndFacesBeforeVertices) {
  std::string body;
  const int f[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& t : f) {
    body += le(3, 1);
    for (int i : t) body += le(static_cast<uint64_t>(i), 4);
  }
  const double v[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const auto& p : v)
    for (double x : p) body += le(std::bit_cast<uint64_t>(x), 8);
  expect_tetrahedron(load("double.ply", "ply\nformat binary_little_endian 1.0\nelement face 4\nproperty list uchar int vertex_indices\n"
                                        "element vertex 4\nproperty float64 x\nproperty float64 y\nproperty float64 z\nend_header\n" + body));
}

TEST_F(MeshGrammarTest, PlyTriangleStrips) {
  // one strip 0 1 2 3 over a square: triangles (0 1 2), (2 1 3)
  auto r = load("strips.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                              "element tristrips 1\nproperty list int int vertex_indices\nend_header\n"
                              "0 0 0\n1 0 0\n0 1 0\n1 1 0\n5 0 1 2 -1 3\n");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r.value().num_triangles(), 1u);  // the -1 restarts the strip, so 3 alone makes none
  auto s = load("strip.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                             "element tristrips 1\nproperty list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n4 0 1 2 3\n");
  ASSERT_TRUE(s) << s.error().message;
  ASSERT_EQ(s.value().num_triangles(), 2u);
  for (const auto& t : s.value().triangles) {
    const TriMesh& m = s.value();
    EXPECT_GT((m.vertices_m[t[1]] - m.vertices_m[t[0]]).cross(m.vertices_m[t[2]] - m.vertices_m[t[0]]).z(), 0.0);
  }
}

TEST_F(MeshGrammarTest, PlyDamageIsNamed) {
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n";
  EXPECT_EQ(error("short.ply", head + kPlyFaceHeader + "0 0 0\n1 0\n" + std::string(64, '\n')),
            "line 11: element vertex 1: its line holds 2 values, fewer than its properties need");
  EXPECT_EQ(error("index.ply", head + kPlyFaceHeader + kTetraVertices + "3 0 2 1\n3 0 1 7\n"),
            "line 15: face 1 vertex index 7 is beyond the vertex list (size 4)");
  EXPECT_EQ(error("list.ply", head + kPlyFaceHeader + kTetraVertices + "3 0 2 1\n9 0 1\n"),
            "element face 1: a list of 9 entries, more than the 4 bytes left in the file");  // checked before reading
  EXPECT_EQ(error("word.ply", head + kPlyFaceHeader + "0 0 0\n1 zero 0\n" + std::string(64, '\n')), "line 11: element vertex 1: 'zero' is not a number");
  EXPECT_EQ(error("ends.ply", head + kPlyFaceHeader + kTetraVertices + "3 0 2 1\n"), "the file ends before element face 1");
  EXPECT_EQ(error("noxyz.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n"),
            "PLY header: element vertex lacks one of the properties x, y, z");
  EXPECT_EQ(error("type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n0\n"),
            "line 4: PLY header: unknown property type 'float128'");
  EXPECT_EQ(error("cloud.ply", head + "end_header\n" + kTetraVertices), "no triangles");
  const std::string bin = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                          "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  EXPECT_EQ(error("truncated.ply", bin + std::string(36, '\0') + "\x03" + le(0, 4) + le(1, 4)),
            "element face 0: a list of 3 entries, more than the 8 bytes left in the file");
  EXPECT_EQ(error("list.ply", head + kPlyFaceHeader + kTetraVertices + "3 0 2 1\n9 0 1\n" + std::string(64, '\n')),
            "line 15: element face 1: a list of '9' entries, its line holds 2 more values");
  // a negative index or count is said to be negative, not "not a whole number" or "more than the bytes left"
  EXPECT_EQ(error("negative.ply", head + kPlyFaceHeader + kTetraVertices + "3 0 2 1\n3 0 -5 2\n" + std::string(64, '\n')),
            "line 15: element face 1: vertex index -5 is negative (indices count from 0)");
  EXPECT_EQ(error("half.ply", head + kPlyFaceHeader + kTetraVertices + "3 0 2 1\n3 0 1.5 2\n" + std::string(64, '\n')),
            "line 15: element face 1: vertex index 1.5 is not a whole number");
  EXPECT_EQ(error("count.ply", head + kPlyFaceHeader + kTetraVertices + "3 0 2 1\n-3 0 1 2\n" + std::string(64, '\n')),
            "element face 1: a list of -3 entries: a count cannot be negative");
}

// --- STL -------------------------------------------------------------------------------------------------------

std::string stl_ascii_tetra(const std::string& solid, bool upper) {
  const double v[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const int f[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  std::string s = (upper ? "SOLID " : "solid ") + solid + "\n";
  for (const auto& t : f) {
    s += upper ? "FACET NORMAL 0 0 0\nOUTER LOOP\n" : "  facet normal 0 0 0\n    outer loop\n";
    for (int i : t)
      s += std::string(upper ? "VERTEX " : "      vertex ") + std::to_string(v[i][0]) + " " + std::to_string(v[i][1]) + " " +
           std::to_string(v[i][2]) + "\n";
    s += upper ? "ENDLOOP\nENDFACET\n" : "    endloop\n  endfacet\n";
  }
  return s + (upper ? "ENDSOLID " : "endsolid ") + solid + "\n";
}

std::string stl_binary_tetra(const std::string& header, const std::string& trailer = "") {
  std::string h = header.substr(0, 80);
  h.resize(80, ' ');
  std::string s = h + le(4, 4);
  const float v[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const int f[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& t : f) {
    s += std::string(12, '\0');
    for (int i : t)
      for (float x : v[i]) s += le(std::bit_cast<uint32_t>(x), 4);
    s += le(0, 2);
  }
  return s + trailer;
}

TEST_F(MeshGrammarTest, StlAsciiAnyCaseNamesWithBlanksSeveralSolids) {
  expect_tetrahedron(load("ascii.stl", stl_ascii_tetra("part one", false)));
  expect_tetrahedron(load("upper.stl", stl_ascii_tetra("PART", true)));
  // two solids: the same tetrahedron twice welds into one vertex set, 8 triangles
  auto r = load("two.stl", stl_ascii_tetra("a", false) + stl_ascii_tetra("b", false));
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r.value().num_vertices(), 4u);
  EXPECT_EQ(r.value().num_triangles(), 8u);
}

TEST_F(MeshGrammarTest, StlBinaryEvenWhenItsHeaderSaysSolid) {
  expect_tetrahedron(load("binary.stl", stl_binary_tetra("made by a CAD program")));
  expect_tetrahedron(load("solid_header.stl", stl_binary_tetra("solid part exported as binary")));
  expect_tetrahedron(load("trailer.stl", stl_binary_tetra("binary", std::string(7, '\0'))));
  // a count never written back (0) before whole triangles: the triangles the file holds
  std::string unpatched = stl_binary_tetra("streamed");
  unpatched.replace(80, 4, le(0, 4));
  expect_tetrahedron(load("count_zero.stl", unpatched));
  // ... but not when the bytes after the header are not whole triangles
  EXPECT_EQ(error("count_zero_odd.stl", unpatched + "x"), "no triangles");
}

TEST_F(MeshGrammarTest, StlDamageIsNamed) {
  EXPECT_EQ(error("short.stl", stl_binary_tetra("binary").substr(0, 150)),
            "binary STL: the header declares 4 triangles (284 bytes), the file has 150 bytes");
  std::string ascii = stl_ascii_tetra("a", false);
  EXPECT_EQ(error("noend.stl", ascii.substr(0, ascii.rfind("endsolid"))), "the file ends before 'endsolid' (after facet 4)");
  EXPECT_EQ(error("cut.stl", ascii.substr(0, 50)), "the file ends inside facet 0");
  EXPECT_EQ(error("word.stl", "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertx 1 0 0\n"),
            "line 5: facet 0: expected 'vertex' or 'endloop', found 'vertx'");
  EXPECT_EQ(error("tiny.stl", "hello"),
            "not an STL file: it does not start with 'solid' and is shorter than a binary STL's 84-byte header");
}

// --- encodings -------------------------------------------------------------------------------------------------

// text with a byte order mark: UTF-8's, or UTF-16 of either byte order (ASCII text, one unit per character)
std::string utf8_marked(const std::string& text) { return "\xEF\xBB\xBF" + text; }
std::string utf16(const std::string& text, bool little) {
  std::string s = little ? "\xFF\xFE" : "\xFE\xFF";
  for (char c : text) s += little ? std::string{c, '\0'} : std::string{'\0', c};
  return s;
}

TEST_F(MeshGrammarTest, TextFilesWithAByteOrderMarkOrInUtf16ReadAsTheirText) {
  const std::string obj = "# a tetrahedron\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  const std::string ply = std::string("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                      "property float z\nelement face 4\nproperty list uchar int vertex_indices\n"
                                      "end_header\n") + kTetraVertices + kTetraFaces;
  const std::string off = std::string("OFF\n4 4 0\n") + kTetraVertices + kTetraFaces;
  const std::pair<const char*, std::string> files[] = {
      {"obj", obj}, {"ply", ply}, {"off", off}, {"stl", stl_ascii_tetra("part", false)}};
  for (const auto& [ext, text] : files) {
    SCOPED_TRACE(ext);
    expect_tetrahedron(load(std::string("utf8_mark.") + ext, utf8_marked(text)));
    expect_tetrahedron(load(std::string("utf16_le.") + ext, utf16(text, true)));
    expect_tetrahedron(load(std::string("utf16_be.") + ext, utf16(text, false)));
  }
  // found by its first word without an extension's help
  expect_tetrahedron(load("no_extension", utf16(off, true)));
}

TEST_F(MeshGrammarTest, ABinaryStlWhoseHeaderBeginsWithAMarksBytesStaysBinary) {
  expect_tetrahedron(load("mark.stl", stl_binary_tetra("\xEF\xBB\xBF exported")));
  expect_tetrahedron(load("ff_fe.stl", stl_binary_tetra("\xFF\xFE exported")));
}

TEST_F(MeshGrammarTest, BrokenUtf16IsNamed) {
  const std::string off = std::string("OFF\n4 4 0\n") + kTetraVertices + kTetraFaces;
  EXPECT_EQ(error("odd.off", utf16(off, true) + "x"),
            "UTF-16 text of an odd number of bytes (" + std::to_string(2 * off.size() + 3) + "): its last byte is half a character");
  // a low surrogate (0xDC00) where a character should be
  std::string lone = utf16(off, true);
  lone.insert(10, std::string("\x00\xDC", 2));
  EXPECT_EQ(error("lone.off", lone), "UTF-16 text: a low surrogate at byte 10 with no high surrogate before it");
}

TEST(DecodeText, Utf16BecomesUtf8ThroughEveryPlane) {
  // "e acute" (2 UTF-8 bytes), "euro" (3) and a character past the 16-bit plane (a surrogate pair, 4 bytes)
  const std::string le16("\xFF\xFE" "a\0" "\xE9\0" "\xAC\x20" "\x3D\xD8\x00\xDE", 12);
  auto r = decode_text(le16);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r.value(), "a\xC3\xA9\xE2\x82\xAC\xF0\x9F\x98\x80");
  std::string be16("\xFE\xFF", 2);
  for (std::size_t i = 2; i < le16.size(); i += 2) be16 += std::string{le16[i + 1], le16[i]};
  EXPECT_EQ(decode_text(be16).value(), r.value());
  EXPECT_EQ(decode_text("\xEF\xBB\xBFOFF").value(), "OFF");
  EXPECT_EQ(decode_text("OFF").value(), "OFF");
  // a prefix that ends inside a pair decodes up to it
  EXPECT_EQ(decode_text(le16.substr(0, 10), false).value(), "a\xC3\xA9\xE2\x82\xAC");
}

// --- scale -----------------------------------------------------------------------------------------------------

TEST_F(MeshGrammarTest, AModelOfAnyScaleLoadsAndWeldsAlike) {
  // a 1 um tetrahedron in metres, and a 1000 km one: the weld follows the model's size
  for (const double scale : {1e-6, 1e-3, 1.0, 1e6}) {
    std::string text = "solid s\n";
    const double v[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const int f[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    char buf[128];
    for (const auto& t : f) {
      text += "facet normal 0 0 0\nouter loop\n";
      for (int i : t) {
        std::snprintf(buf, sizeof buf, "vertex %.9g %.9g %.9g\n", scale * v[i][0], scale * v[i][1], scale * v[i][2]);
        text += buf;
      }
      text += "endloop\nendfacet\n";
    }
    SCOPED_TRACE(scale);
    expect_tetrahedron(load("scaled.stl", text + "endsolid s\n"), scale);
  }
}

TEST(WeldVertices, MergesWithinTheToleranceOnly) {
  TriMesh m;
  m.vertices_m = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1e-7, 0, -0.0), Vec3(1 + 3e-6, 0, 0), Vec3(-0.0, 1, 0)};
  m.triangles = {{0, 1, 2}, {3, 4, 5}};
  TriMesh exact = m;
  EXPECT_EQ(weld_vertices(&exact, 0.0), 1u);  // only -0 and +0 alike
  EXPECT_EQ(exact.triangles[1], (std::array<int32_t, 3>{3, 4, 2}));
  EXPECT_EQ(weld_vertices(&m, 1e-6), 2u);  // 1e-7 merges, 3e-6 stays
  EXPECT_EQ(m.num_vertices(), 4u);
  EXPECT_EQ(m.triangles[1], (std::array<int32_t, 3>{0, 3, 2}));
}

// The weld looks up a vertex's cell (1024 tolerances wide) and the neighbours it is within the tolerance of: pairs
// straddling a cell's face, edge and corner merge into the first; a pair just beyond the tolerance across a corner
// stays; a vertex within the tolerance of two kept ones merges into the first of them. Checked against the
// all-pairs definition on a cloud placed around cell corners.
TEST(WeldVertices, PairsAcrossTheLookupCellsFacesEdgesAndCornersMerge) {
  const double tol = 1e-6, cell = 1024 * tol;
  TriMesh m;
  const Vec3 corner(3 * cell, -2 * cell, 5 * cell);
  m.vertices_m = {corner + Vec3(-4e-7, 0, 0),          corner + Vec3(4e-7, 0, 0),             // across a face
                  corner + Vec3(-4e-7, -4e-7, 0),      corner + Vec3(4e-7, 4e-7, 0),          // across an edge
                  corner + Vec3(-4e-7, -4e-7, -4e-7), corner + Vec3(4e-7, 4e-7, 4e-7),       // across the corner
                  corner + Vec3(-6e-7, 6e-7, 0),       corner + Vec3(6e-7, -6e-7, 2e-6)};     // beyond, across z
  for (int32_t i = 0; i + 2 < static_cast<int32_t>(m.vertices_m.size()); ++i) m.triangles.push_back({i, i + 1, i + 2});
  TriMesh welded = m;
  weld_vertices(&welded, tol);
  // the all-pairs definition: each vertex goes to the first earlier kept one within tol (per coordinate)
  std::vector<int32_t> to(m.vertices_m.size());
  std::vector<Vec3> kept;
  for (std::size_t i = 0; i < m.vertices_m.size(); ++i) {
    to[i] = static_cast<int32_t>(kept.size());
    for (std::size_t k = 0; k < kept.size(); ++k)
      if ((kept[k] - m.vertices_m[i]).cwiseAbs().maxCoeff() <= tol) {
        to[i] = static_cast<int32_t>(k);
        break;
      }
    if (to[i] == static_cast<int32_t>(kept.size())) kept.push_back(m.vertices_m[i]);
  }
  EXPECT_EQ(welded.num_vertices(), kept.size());
  EXPECT_EQ(kept.size(), 2u);  // every vertex but the last is within tol of the first
  for (std::size_t t = 0; t < m.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(welded.triangles[t][c], to[static_cast<std::size_t>(m.triangles[t][c])]) << "triangle " << t;
}

}  // namespace
}  // namespace palpate
