#pragma once
/// The PLY reader: the Stanford polygon format, ASCII and binary of both byte orders, read without the third-party
/// reader.

#include <string_view>

#include "core/result.h"
#include "core/tri_mesh.h"

namespace palpate {

/// Reads a PLY file held in bytes: a header of "ply", "format ascii|binary_little_endian|binary_big_endian 1.0",
/// comment and obj_info lines (and lines of no known keyword, skipped), elements with scalar and list properties of every PLY type (char..double and
/// int8..float64), any line ends, then the body. The vertex element's x, y, z (any scalar type) are the positions;
/// the face element's vertex_indices (or vertex_index, or its only list) are polygons, triangulated; a tristrips
/// element's strips (-1 restarts) are read too; every other element and property is skipped. An ASCII element is
/// one line (blank lines skipped, extra values ignored). A count or list length is checked against the bytes left
/// before anything is reserved. Errors carry no "mesh '<path>': " prefix and name the element, its index and, in
/// ASCII, the line. The vertices are not welded and degenerate triangles are kept (load_mesh does both).
Result<TriMesh> read_ply(std::string_view bytes);

}  // namespace palpate
