#pragma once
/// What is checked of a mesh file before the reader (assimp) sees it, and the reader's errors made specific: a
/// regular file of bounded size, OFF/PLY counts the file can hold, PLY lists within the bytes left, XML nesting.

#include <string>

#include "core/result.h"

namespace palpate {

/// The checks load_mesh() makes before the reader sees a file: a regular file of at most kMaxMeshFileBytes, OFF
/// and PLY header counts the file's size can hold (PLY: a header with an end_header line in its first 64 KiB, whole
/// non-negative counts, and in a binary file every list's entries within the bytes left; checked for any .ply
/// or .off file whatever its first word), every face line of a .off file listing the indices it declares within
/// its vertex list, counts on one line and vertex lines of 3 coordinates (off_face_problem), and XML (Collada
/// and others) nested at most kMaxXmlNesting deep. Errors as load_mesh()'s.
Status check_mesh_file(const std::string& path);

/// The first face of an ASCII OFF file (blank lines and '#' comments skipped) with a vertex index outside its
/// vertex list ("face 1 vertex index 9 is beyond the vertex list (size 4)") or fewer indices on its line than it
/// declares ("face 1 declares 12 vertex indices, its line lists 0"), else empty. check_mesh_file() runs it on
/// every .off file; load_mesh() again when the reader said an index was out of range (its message names no face).
std::string off_face_problem(const std::string& path);

}  // namespace palpate
