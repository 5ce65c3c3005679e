#pragma once
/// Mesh input: loading triangle meshes from files (assimp) and building simple procedural meshes.

#include <cstdint>
#include <string>

#include "core/mesh_file_checks.h"  // check_mesh_file
#include "core/result.h"
#include "core/tri_mesh.h"
#include "core/types.h"

namespace palpate {


/// Where the third-party reader (assimp) runs. It parses untrusted bytes and some malformed files crash it, so
/// by default it runs in a forked child process that can only report a mesh or an error back.
enum class MeshReaderIsolation {
  child_process,  ///< fork, read and convert in the child, send the arrays back through a memfd; a crash or a
                  ///< hang of the reader becomes an error naming the file
  in_process,     ///< read in this process: only for the fuzz targets (coverage, speed), where a crash is the finding
};

/// The process-wide default isolation: child_process unless set_default_mesh_reader_isolation changed it.
MeshReaderIsolation default_mesh_reader_isolation();

/// Vertices closer than this fraction of the model's largest extent are welded into one (per coordinate), so a model
/// welds alike at any scale: a 1 um part in metres as a 100 mm one in millimetres.
inline constexpr double kWeldTolerance = 1e-6;

/// How load_mesh reads the file.
struct MeshReadOptions {
  MeshReaderIsolation isolation = default_mesh_reader_isolation();
  /// Wall-clock limit on the child, seconds; <= 0: 10 s + 60 s per 100 MB of file (mesh_reader_time_limit_s).
  double time_limit_s = 0.0;
  /// Test hook: the child sleeps this long before reading (to check that a hanging reader is stopped).
  int child_delay_ms_for_test = 0;
};

/// Sets the isolation MeshReadOptions starts with, for the whole process; only the fuzz targets use it (they load
/// meshes through load_model, which takes default options). Thread: call before any load.
void set_default_mesh_reader_isolation(MeshReaderIsolation isolation);

/// The wall-clock limit on an isolated reader for a file of file_bytes: 10 s + 60 s per 100 MB
/// (reading runs at tens of MB/s here: a 50 MB STL in 1.7 s; a small file that takes 10 s is a hang).
double mesh_reader_time_limit_s(int64_t file_bytes);

/// Loads OBJ, PLY, STL, OFF (anything assimp reads) into one TriMesh: all meshes merged with their node
/// transforms applied, triangulated, vertices at identical positions welded, degenerate triangles and unused
/// vertices dropped. Errors start with "mesh '<path>': " and end with "file not found", "not a regular file",
/// "file is empty", "<n> bytes, more than the limit of <kMaxMeshFileBytes>", "header declares ..., more than the
/// <n>-byte file can hold" (OFF/PLY counts, read from the first 64 KiB, any line ends), "element face 0: a list
/// of <n> entries, more than the <m> bytes left in the file", "XML elements nested deeper than the limit of 256
/// levels (line <n>)", "NaN coordinate at vertex <i>", "degenerate: the model spans only <x> units, ...", assimp's own message,
/// "malformed faces (assimp: <message>)" when the reader skipped or repaired faces or their vertex indices,
/// "face 3 vertex index 9 is beyond the vertex list (size 4)", "face 0 has no vertex indices", or "no triangles";
/// with the reader isolated (the default) also "the mesh reader (assimp) crashed on this file (SIGSEGV); the file
/// is malformed or unsupported", "the mesh reader (assimp) took longer than <n> s on this file and was stopped;
/// ..." or "could not run the mesh reader in a child process (<reason>)". Thread: any (the child is forked from
/// the calling thread and runs only the reader before _exit); the first call attaches an error stream to
/// assimp's global DefaultLogger (creating one if none exists).
Result<TriMesh> load_mesh(const std::string& path, const MeshReadOptions& options = {});

/// A closed box centred at the origin with side lengths size_m, each face split into n x n quads of two
/// triangles; vertices shared, triangles counter-clockwise seen from outside. subdivisions < 1 counts as 1.
TriMesh make_box_mesh(const Vec3& size_m, int subdivisions);

}  // namespace palpate
