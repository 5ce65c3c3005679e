#pragma once
/// The STL reader: ASCII and binary stereolithography files, read without the third-party reader.

#include <string_view>

#include "core/result.h"
#include "core/tri_mesh.h"

namespace palpate {

/// Reads an STL file held in bytes. Binary when its size is 84 + 50 n bytes for the n its header declares
/// (whatever the 80-byte header says, "solid" too); else ASCII when it starts with "solid": solids of
/// "facet normal .. / outer loop / vertex x y z (3 or more) / endloop / endfacet", keywords in any case; else binary
/// with bytes after the last triangle ignored, a file too short for its declared triangles refused; a count of 0
/// before whole 50-byte triangles reads the triangles the file holds (a count never written back). Errors carry
/// no "mesh '<path>': " prefix and name the facet and line. Every facet has its own vertices (load_mesh welds them).
Result<TriMesh> read_stl(std::string_view bytes);

}  // namespace palpate
