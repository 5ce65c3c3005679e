#pragma once
// A triangle mesh as the text of an OBJ file, for tests that hand `palpate scene` a model file.

#include <string>

#include "core/tri_mesh.h"
#include "core/types.h"

namespace palpate::test {

/// The mesh's vertices (moved by offset) and triangles as OBJ "v" and "f" lines.
inline std::string obj_text(const TriMesh& m, const Vec3& offset = Vec3::Zero()) {
  std::string text;
  for (const Vec3& v : m.vertices_m) {
    const Vec3 p = v + offset;
    text += "v " + std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + "\n";
  }
  for (const auto& t : m.triangles)
    text += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + "\n";
  return text;
}

}  // namespace palpate::test
