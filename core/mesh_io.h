#pragma once
/// Mesh input: loading triangle meshes from files (assimp) and building simple procedural meshes.

#include <string>

#include "core/mesh_file_checks.h"  // check_mesh_file
#include "core/result.h"
#include "core/tri_mesh.h"
#include "core/types.h"

namespace palpate {


/// Loads OBJ, PLY, STL, OFF (anything assimp reads) into one TriMesh: all meshes merged with their node
/// transforms applied, triangulated, vertices at identical positions welded, degenerate triangles and unused
/// vertices dropped. Errors start with "mesh '<path>': " and end with "file not found", "not a regular file",
/// "file is empty", "<n> bytes, more than the limit of <kMaxMeshFileBytes>", "header declares ..., more than the
/// <n>-byte file can hold" (OFF/PLY counts, read from the first 64 KiB, any line ends), "element face 0: a list
/// of <n> entries, more than the <m> bytes left in the file", "XML elements nested deeper than the limit of 256
/// levels (line <n>)", "NaN coordinate at vertex <i>", "degenerate: the model spans only <x> units, ...", assimp's own message,
/// "malformed faces (assimp: <message>)" when the reader skipped or repaired faces or their vertex indices,
/// "face 3 vertex index 9 is beyond the vertex list (size 4)", "face 0 has no vertex indices", or "no triangles". Thread: any; the first call
/// attaches an error stream to assimp's
/// global DefaultLogger (creating one if none exists).
Result<TriMesh> load_mesh(const std::string& path);

/// A closed box centred at the origin with side lengths size_m, each face split into n x n quads of two
/// triangles; vertices shared, triangles counter-clockwise seen from outside. subdivisions < 1 counts as 1.
TriMesh make_box_mesh(const Vec3& size_m, int subdivisions);

}  // namespace palpate
