#pragma once
/// What is checked of a mesh file before the reader (assimp) sees it, and the reader's errors made specific: a
/// regular file of bounded size, OFF/PLY counts the file can hold, PLY lists within the bytes left, XML nesting.

#include <string>

#include "core/result.h"

namespace palpate {

/// The checks load_mesh() makes before the reader sees a file: a regular file of at most kMaxMeshFileBytes, OFF
/// and PLY header counts the file's size can hold (PLY: a header with an end_header line in its first 64 KiB, whole
/// non-negative counts, and in a binary file every list's entries within the bytes left), and XML (Collada
/// and others) nested at most kMaxXmlNesting deep. Errors as load_mesh()'s.
Status check_mesh_file(const std::string& path);

/// The first face of an ASCII OFF file with a vertex index outside its vertex list ("face 1 vertex index 9 is
/// beyond the vertex list (size 4)"), else empty. Read only once the reader said an index was out of range (its
/// message names no face).
std::string off_face_out_of_range(const std::string& path);

}  // namespace palpate
