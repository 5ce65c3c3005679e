#pragma once
/// What is checked of a mesh file before the reader (assimp) sees it, and the reader's errors made specific: a
/// regular file of bounded size, OFF/PLY counts the file can hold, PLY lists within the bytes left, XML nesting.

#include <string>

#include "core/result.h"

namespace palpate {

/// The checks load_mesh() makes before any reader sees a file: a regular file of at most kMaxMeshFileBytes, PLY
/// header counts the file's size can hold (a header with an end_header line in its first 64 KiB, whole
/// non-negative counts, and every list's entries within the bytes left; checked for any .ply file or one whose first
/// word is "ply"), and XML (Collada and others) nested at most kMaxXmlNesting deep. OFF files are checked by their
/// reader (core/off_reader.h) as it reads. Errors as load_mesh()'s.
Status check_mesh_file(const std::string& path);

}  // namespace palpate
