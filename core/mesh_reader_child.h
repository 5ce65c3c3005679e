#pragma once
/// The mesh reader in a child process: a third-party reader fed an untrusted file may crash or hang; run in a
/// forked child, its crash or hang becomes an error naming the file, and its result comes back through a memfd.

#include <string>

#include "core/result.h"
#include "core/tri_mesh.h"

namespace palpate {

/// Reads a mesh file into a TriMesh (what runs in the child).
using MeshReader = Result<TriMesh> (*)(const std::string& path);

/// Runs read(path) in a forked child that writes the vertex and triangle arrays (or the error message) to a memfd
/// in one go and _exits; waits at most limit_s (then kills it). A child that dies by a signal, exits non-zero, runs
/// out of time or leaves no complete record gives an error naming the file. child_delay_ms_for_test > 0 makes the
/// child sleep first (tests of the time limit).
Result<TriMesh> read_mesh_in_child(const std::string& path, MeshReader read, double limit_s, int child_delay_ms_for_test);

}  // namespace palpate
