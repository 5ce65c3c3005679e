#include "core/mesh_io.h"

#include "core/aabb.h"
#include "core/input_file.h"
#include "core/limits.h"
#include "core/mesh_file_checks.h"
#include "core/mesh_reader_child.h"
#include "core/off_reader.h"
#include "core/ply_reader.h"
#include "core/stl_reader.h"
#include "core/text_encoding.h"
#include "core/text_lines.h"

#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <bit>
#include <cctype>
#include <cstdint>
#include <exception>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <mutex>
#include <sstream>
#include <string>
#include <system_error>
#include <unordered_map>
#include <vector>

namespace palpate {

namespace {

// errors assimp logs while reading, per thread; the stream is owned by assimp's global logger
thread_local std::vector<std::string> t_assimp_errors;

class ErrorCapture : public Assimp::LogStream {
 public:
  void write(const char* message) override {
    std::string text = message;
    // "Error, T0: Obj: Ignoring empty face\n" -> "Obj: Ignoring empty face"
    const std::size_t colon = text.find(": ");
    if (colon != std::string::npos) text.erase(0, colon + 2);
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    t_assimp_errors.push_back(std::move(text));
  }
};

// installs the capture once per process (assimp's logger is global); a later DefaultLogger::kill elsewhere
// only removes the extra strictness below
void install_error_capture() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (Assimp::DefaultLogger::isNullLogger()) {
      Assimp::DefaultLogger::create("", Assimp::Logger::NORMAL, 0);
    }
    Assimp::DefaultLogger::get()->attachStream(new ErrorCapture, Assimp::Logger::Err);
  });
}

// the first logged error saying a reader dropped or repaired faces (or their vertex indices), else empty (material errors are harmless)
std::string face_repair_error() {
  for (const std::string& e : t_assimp_errors) {
    std::string lower = e;
    for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    // "OFF: Vertex index is out of range": the reader clamped a face's index to the last vertex
    if (lower.find("face") != std::string::npos || lower.find("vertex index") != std::string::npos) return e;
  }
  return {};
}

// Checks the faces a reader made before assimp's post-processing sees them, and sets each mesh's primitive types
// from its faces. A reader fed a damaged file can make a face of no indices (an ASCII PLY whose vertex lines
// are short) or flag polygons it did not make: assimp's triangulation then aborts the process on an internal
// assertion (numOut != pMesh->mNumFaces) instead of reporting an error. Returns the first empty face, else empty.
std::string check_faces(aiScene* scene) {
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    aiMesh* mesh = scene->mMeshes[m];
    if (mesh == nullptr) continue;
    unsigned types = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const unsigned n = mesh->mFaces[f].mNumIndices;
      if (n == 0) return "face " + std::to_string(f) + " has no vertex indices";
      if (n == 1) types |= aiPrimitiveType_POINT;
      else if (n == 2) types |= aiPrimitiveType_LINE;
      else if (n == 3) types |= aiPrimitiveType_TRIANGLE;
      else types |= aiPrimitiveType_POLYGON;
    }
    mesh->mPrimitiveTypes = types;
  }
  return {};
}

// merges the scene's meshes into one list of triangles (welded afterwards, with the files the project reads itself)
class SceneMerger {
 public:
  explicit SceneMerger(TriMesh* out) : out_(out) {}

  void add_node(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent) {
    const aiMatrix4x4 transform = parent * node.mTransformation;
    for (unsigned m = 0; m < node.mNumMeshes; ++m) {
      if (node.mMeshes[m] < scene.mNumMeshes) add_mesh(*scene.mMeshes[node.mMeshes[m]], transform);
    }
    for (unsigned c = 0; c < node.mNumChildren; ++c) {
      if (node.mChildren[c] != nullptr) add_node(scene, *node.mChildren[c], transform);
    }
  }

 private:
  void add_mesh(const aiMesh& mesh, const aiMatrix4x4& transform) {
    std::vector<int32_t> ids(mesh.mNumVertices);
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D& raw = mesh.mVertices[v];
      const aiVector3D p = transform * raw;
      // said here, before a NaN vertex is welded to another or its triangles dropped as degenerate (the file's
      // coordinate, not the transformed one: an infinite one times a zero in the transform is NaN)
      if (error_.empty() && !(std::isfinite(raw.x) && std::isfinite(raw.y) && std::isfinite(raw.z) &&
                              std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) {
        const bool nan = std::isnan(raw.x) || std::isnan(raw.y) || std::isnan(raw.z);
        error_ = std::string(nan ? "NaN coordinate" : "infinite coordinate (beyond the float range the reader keeps)") +
                 " at vertex " + std::to_string(v);
      }
      ids[v] = static_cast<int32_t>(out_->vertices_m.size());
      out_->vertices_m.emplace_back(p.x, p.y, p.z);
    }
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines carry no surface
      std::array<int32_t, 3> tri{};
      bool in_range = true;
      for (int c = 0; c < 3; ++c) {
        in_range = in_range && face.mIndices[c] < mesh.mNumVertices;
        if (in_range) tri[c] = ids[face.mIndices[c]];
      }
      if (in_range) {
        out_->triangles.push_back(tri);
      } else if (error_.empty()) {
        // a face pointing past the vertex list is a damaged file, not a face to drop
        for (int c = 0; c < 3; ++c)
          if (face.mIndices[c] >= mesh.mNumVertices) {
            error_ = "face " + std::to_string(f) + " vertex index " + std::to_string(face.mIndices[c]) +
                     " is beyond the vertex list (size " + std::to_string(mesh.mNumVertices) + ")";
            break;
          }
      }
    }
  }

  TriMesh* out_;
  std::string error_;

 public:
  /// The first face that pointed past its mesh's vertex list, else empty.
  const std::string& error() const { return error_; }
};

// drops triangles with repeated vertices or zero area, then vertices no triangle uses
void drop_degenerates(TriMesh* mesh) {
  const auto& v = mesh->vertices_m;
  std::erase_if(mesh->triangles, [&](const std::array<int32_t, 3>& t) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return true;
    return (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).isZero(0.0);
  });
  std::vector<int32_t> remap(v.size(), -1);
  std::vector<Vec3> kept;
  for (auto& t : mesh->triangles) {
    for (int32_t& id : t) {
      if (remap[id] < 0) {
        remap[id] = static_cast<int32_t>(kept.size());
        kept.push_back(v[id]);
      }
      id = remap[id];
    }
  }
  mesh->vertices_m = std::move(kept);
}

// A vertex far out from the bulk of the model (a stray triangle 1e30 away from a unit cube) makes the bounding
// box its own: the camera, the lattice and the touch all frame empty space and the body is never reached. The
// bulk is measured robustly: the median vertex's distance from the per-axis median point. Empty when none is.
std::string far_outlier(const TriMesh& mesh) {
  const std::size_t n = mesh.vertices_m.size();
  if (n < 4) return {};
  Vec3 centre;
  std::vector<double> v(n);
  for (int a = 0; a < 3; ++a) {
    for (std::size_t i = 0; i < n; ++i) v[i] = mesh.vertices_m[i][a];
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n / 2), v.end());
    centre[a] = v[n / 2];
  }
  for (std::size_t i = 0; i < n; ++i) v[i] = (mesh.vertices_m[i] - centre).norm();
  std::vector<double> sorted = v;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n / 2), sorted.end());
  const double bulk = sorted[n / 2];
  if (!(bulk > 0.0)) return {};  // half the vertices at one point: no bulk to measure against
  std::size_t worst = 0, count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!(v[i] <= kMaxOutlierRatio * bulk)) ++count;
    if (!(v[i] <= v[worst])) worst = i;
  }
  if (count == 0) return {};
  const Vec3& p = mesh.vertices_m[worst];
  char text[400];
  std::snprintf(text, sizeof text, "vertex %zu at (%.6g, %.6g, %.6g) lies %.3g units from the bulk of the model, whose "
                "median vertex lies %.3g from its centre; %zu vertices lie more than %g times that far out and would "
                "make the bounding box theirs (the view, the lattice and the touch would miss the body): remove them",
                worst, p.x(), p.y(), p.z(), v[worst], bulk, count, kMaxOutlierRatio);
  return text;
}

// welds, drops degenerates; "no triangles" when none is left
Result<TriMesh> finish_mesh(TriMesh mesh, const std::string& who) {
  // strays first: the weld's tolerance follows the model's size, which a stray would make its own
  if (const std::string far = far_outlier(mesh); !far.empty()) return make_error(who, far);
  if (!mesh.vertices_m.empty()) {
    const double span = Aabb::of(mesh.vertices_m).extent().maxCoeff();
    weld_vertices(&mesh, kWeldTolerance * span);
  }
  drop_degenerates(&mesh);
  if (mesh.triangles.empty()) return make_error(who, "no triangles");
  return mesh;
}

// Whether bytes are exactly a binary STL's length: the 84-byte header and count, then 50 bytes per triangle.
bool is_binary_stl_size(const std::string& bytes) {
  if (bytes.size() < 84) return false;
  uint64_t count = 0;
  for (int k = 0; k < 4; ++k) count |= static_cast<uint64_t>(static_cast<unsigned char>(bytes[80 + static_cast<std::size_t>(k)])) << (8 * k);
  return 84 + 50 * count == bytes.size();
}

// The formats read here rather than by assimp: by extension, else by the file's first word.
enum class OwnFormat { kNone, kOff, kPly, kStl };

OwnFormat own_format(const std::string& path, std::string_view head) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".off") return OwnFormat::kOff;
  if (ext == ".ply") return OwnFormat::kPly;
  if (ext == ".stl") return OwnFormat::kStl;
  std::vector<std::string_view> words;
  TextLines lines(head);
  std::string_view line;
  if (lines.next(&line)) split_words(line, &words);
  if (!words.empty() && is_off_keyword(words[0])) return OwnFormat::kOff;
  if (!words.empty() && words[0] == "ply") return OwnFormat::kPly;
  return OwnFormat::kNone;
}

// assimp's reading and the conversion of its scene to one TriMesh (vertices not yet welded); text (when not null)
// is the file's content decoded to UTF-8, read from memory with the file's extension as the format's hint
Result<TriMesh> read_with_assimp(const std::string& path, const std::string* text = nullptr) {
  const std::string who = "mesh '" + path + "': ";
  TriMesh mesh;
  t_assimp_errors.clear();
  try {
    Assimp::Importer importer;
    // vertices are welded afterwards with a tolerance that follows the model's size (assimp's join uses 1e-5 units)
    const unsigned flags = aiProcess_Triangulate | aiProcess_ValidateDataStructure;
    // read first, post-processed once each mesh's primitive types say what its faces are (see below)
    std::string hint = std::filesystem::path(path).extension().string();
    if (!hint.empty()) hint.erase(0, 1);
    const aiScene* scene = text != nullptr ? importer.ReadFileFromMemory(text->data(), text->size(), 0, hint.c_str())
                                           : importer.ReadFile(path, 0);
    if (scene != nullptr) {
      // the importer owns the scene and post-processes it in place
      if (const std::string empty = check_faces(const_cast<aiScene*>(scene)); !empty.empty()) return make_error(who, empty);
      scene = importer.ApplyPostProcessing(flags);
    }
    if (scene == nullptr) {
      std::string message = importer.GetErrorString();
      if (message.empty()) message = "assimp could not read the file";
      return make_error(who, message);
    }
    // a reader that skipped or fixed faces read a damaged surface: refuse it rather than guess
    const std::string repaired = face_repair_error();
    if (!repaired.empty()) return make_error(who, "malformed faces (assimp: ", repaired, ")");
    SceneMerger merger(&mesh);
    if (scene->mRootNode != nullptr) merger.add_node(*scene, *scene->mRootNode, aiMatrix4x4());
    if (!merger.error().empty()) return make_error(who, merger.error());
  } catch (const std::exception& e) {
    return make_error(who, "assimp failed: ", e.what());
  }
  return mesh;
}

// The reader and the conversion to a TriMesh (what runs in the child when isolated): OFF, PLY and STL by the
// project's readers, anything else by assimp; then every vertex finite, vertices welded within a millionth of
// the model's largest extent, degenerate triangles and unused vertices dropped.
Result<TriMesh> read_mesh(const std::string& path) {
  const std::string who = "mesh '" + path + "': ";
  std::string bytes;
  {
    std::ifstream file(path, std::ios::binary);
    if (!file) return make_error(who, "cannot open the file");
    std::string head(256, '\0');
    file.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(std::max<std::streamsize>(file.gcount(), 0)));
    // a text file with a byte order mark (UTF-8's, or UTF-16 of either order) is read as the text it stands for
    const bool marked = text_encoding(head) != TextEncoding::kPlain;
    auto head_text = marked ? decode_text(head, false) : Result<std::string>(head);
    if (!head_text) return make_error(who, head_text.error().message);
    const OwnFormat format = own_format(path, head_text.value());
    if (format == OwnFormat::kNone && !marked) {
      file.close();
      auto r = read_with_assimp(path);
      if (!r) return r;
      return finish_mesh(std::move(r).value(), who);
    }
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    if (ec || size > static_cast<uintmax_t>(max_mesh_file_bytes())) return make_error(who, "cannot read the file's size");
    bytes.resize(static_cast<std::size_t>(size));
    file.clear();
    file.seekg(0);
    file.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    bytes.resize(static_cast<std::size_t>(std::max<std::streamsize>(file.gcount(), 0)));
    // a binary STL's 80-byte header is free text that may begin with a mark's bytes: its size decides first
    if (marked && !(format == OwnFormat::kStl && is_binary_stl_size(bytes))) {
      auto text = decode_text(bytes);
      if (!text) return make_error(who, text.error().message);
      bytes = std::move(text).value();
    }
    if (format == OwnFormat::kNone) {
      file.close();
      auto r = read_with_assimp(path, &bytes);
      if (!r) return r;
      return finish_mesh(std::move(r).value(), who);
    }
    Result<TriMesh> r = format == OwnFormat::kOff ? read_off(bytes) : format == OwnFormat::kPly ? read_ply(bytes) : read_stl(bytes);
    if (!r) return make_error(who, r.error().message);
    for (std::size_t v = 0; v < r.value().vertices_m.size(); ++v) {
      const Vec3& p = r.value().vertices_m[v];
      if (!p.allFinite())
        return make_error(who, p.hasNaN() ? "NaN coordinate" : "infinite coordinate", " at vertex ", std::to_string(v));
    }
    return finish_mesh(std::move(r).value(), who);
  }
}

std::atomic<MeshReaderIsolation> g_default_isolation{MeshReaderIsolation::child_process};

}  // namespace

MeshReaderIsolation default_mesh_reader_isolation() { return g_default_isolation.load(std::memory_order_relaxed); }

void set_default_mesh_reader_isolation(MeshReaderIsolation isolation) {
  g_default_isolation.store(isolation, std::memory_order_relaxed);
}

double mesh_reader_time_limit_s(int64_t file_bytes) {
  return 10.0 + 60.0 * static_cast<double>(std::max<int64_t>(file_bytes, 0)) / 100e6;
}

Result<TriMesh> load_mesh(const std::string& path, const MeshReadOptions& options) {
  if (auto st = check_mesh_file(path); !st) return st.error();
  // before any fork: the logger is created once, here, not in a child
  install_error_capture();
  if (options.isolation == MeshReaderIsolation::in_process) return read_mesh(path);
  std::error_code ec;
  const auto bytes = static_cast<int64_t>(std::filesystem::file_size(path, ec));
  const double limit_s = options.time_limit_s > 0 ? options.time_limit_s : mesh_reader_time_limit_s(ec ? 0 : bytes);
  return read_mesh_in_child(path, &read_mesh, limit_s, options.child_delay_ms_for_test);
}

TriMesh make_box_mesh(const Vec3& size_m, int subdivisions) {
  const int n = std::max(subdivisions, 1);
  const int np = n + 1;
  TriMesh mesh;
  // surface points of the (n+1)^3 lattice, created once and shared by the faces that meet there
  std::vector<int32_t> lattice_to_vertex(static_cast<std::size_t>(np) * np * np, -1);
  auto vertex = [&](const std::array<int, 3>& g) {
    int32_t& id = lattice_to_vertex[g[0] + np * (g[1] + np * g[2])];
    if (id < 0) {
      id = static_cast<int32_t>(mesh.vertices_m.size());
      Vec3 p;
      for (int a = 0; a < 3; ++a) p[a] = size_m[a] * (static_cast<double>(g[a]) / n - 0.5);
      mesh.vertices_m.push_back(p);
    }
    return id;
  };
  for (int axis = 0; axis < 3; ++axis) {
    // (u, v, axis) is right-handed, so quads ordered u then v face +axis
    const int u = (axis + 1) % 3;
    const int w = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      for (int b = 0; b < n; ++b) {
        for (int a = 0; a < n; ++a) {
          std::array<int32_t, 4> q{};
          const int corner[4][2] = {{a, b}, {a + 1, b}, {a + 1, b + 1}, {a, b + 1}};
          for (int c = 0; c < 4; ++c) {
            std::array<int, 3> g{};
            g[axis] = side * n;
            g[u] = corner[c][0];
            g[w] = corner[c][1];
            q[c] = vertex(g);
          }
          if (side == 1) {
            mesh.triangles.push_back({q[0], q[1], q[2]});
            mesh.triangles.push_back({q[0], q[2], q[3]});
          } else {
            mesh.triangles.push_back({q[0], q[2], q[1]});
            mesh.triangles.push_back({q[0], q[3], q[2]});
          }
        }
      }
    }
  }
  return mesh;
}

}  // namespace palpate
