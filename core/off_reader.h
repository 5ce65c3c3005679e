#pragma once
/// The OFF reader: Geomview's Object File Format, text and binary, read without the third-party reader.

#include <string_view>

#include "core/result.h"
#include "core/tri_mesh.h"

namespace palpate {

/// Whether word is an OFF header keyword: [ST][C][N][4][n]OFF, in that order.
bool is_off_keyword(std::string_view word);

/// Reads an OFF file held in bytes: the keyword [ST][C][N][4][n]OFF (optional), '#' comments and blank lines
/// anywhere (before the keyword too), the counts on the keyword's line or the next, for nOFF the dimension (3 only)
/// first, vertex lines of at least 3 coordinates (normals, colours, texture coordinates after them are ignored),
/// face lines "n i0 .. i(n-1) [colour]" (points and lines are dropped, polygons triangulated), and "OFF BINARY"
/// (big-endian 32-bit counts, floats and indices). Counts are checked against the file's size before anything is
/// reserved. 4OFF (homogeneous coordinates) and nOFF of another dimension are refused by name. Errors carry no
/// "mesh '<path>': " prefix (the caller adds it) and name the line: "line 7: face 1 vertex index 9 is beyond the
/// vertex list (size 4)". The vertices are not welded and degenerate triangles are kept (load_mesh does both).
Result<TriMesh> read_off(std::string_view bytes);

}  // namespace palpate
