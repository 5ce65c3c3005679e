#pragma once
/// Limits on what a scene, a file or a command line may ask for, checked before anything is allocated or
/// written, so a hostile or mistaken input is refused with the limit named instead of taking the machine.

#include <cstdint>
#include <string>

namespace palpate {

/// Largest scene file read, bytes (16 MiB).
inline constexpr int64_t kMaxSceneFileBytes = int64_t{16} << 20;
/// Largest replay log (haptic.csv) read, bytes (256 MiB, about 20 minutes at 1 kHz).
inline constexpr int64_t kMaxReplayFileBytes = int64_t{256} << 20;
/// Deepest nesting of arrays and objects in a scene file (a scene needs 4), checked before parsing.
inline constexpr int kMaxJsonNesting = 64;
/// Most trajectory keyframes in a scene.
inline constexpr int kMaxKeyframes = 100000;
/// Most lattice nodes a scene's lattice may reach (estimated from the grid before it is built).
inline constexpr int64_t kMaxLatticeNodes = 65536;
/// Most lattice springs a scene's lattice may reach (estimated likewise).
inline constexpr int64_t kMaxLatticeSprings = 1048576;
/// What a run may plan on holding in memory, bytes: the machine's physical memory, or its control group's limit
/// where one is set lower (a container's); PALPATE_MEMORY_BYTES, a whole number of bytes (a K, M or G suffix for
/// KiB, MiB, GiB), says it instead. Read once.
int64_t memory_bytes();
/// What a recording holds at its peak per triangle of its model, bytes: the rest and deformed surfaces, normals,
/// bindings, adjacency, the renderer's buffers and clustered copy. Measured with frames (bunny_pull, lockstep,
/// 640 x 480): the bunny subdivided to 15.0M triangles, read from a binary PLY, peaked at 2.51 GB, 167 bytes a
/// triangle (docs/limits.md); this leaves room over that.
inline constexpr int64_t kPeakBytesPerTriangle = 320;
/// Most triangles of a model after mesh.subdivisions (each subdivision makes 4 of every triangle): those
/// memory_bytes() holds at kPeakBytesPerTriangle, and at most 2^29 (the corners of the triangles, three each, are
/// numbered in 32 bits). Checked from a mesh file's header before it is read (PLY, OFF, binary STL), and before subdividing.
int64_t max_triangles();
/// Largest mesh file read, bytes: a sixteenth of memory_bytes() (the file is held while it is read, beside the mesh
/// it makes; assimp's readers hold several times the file), at least 64 MiB.
int64_t max_mesh_file_bytes();
/// "N triangles this machine's memory holds (G GiB at B bytes a triangle)": the limit and where it comes from, for
/// messages.
std::string triangle_limit_text();
/// Deepest grid level (128^3 = 2,097,152 cells at the finest level).
inline constexpr int kMaxGridLevels = 8;
/// Deepest element nesting of an XML mesh file (Collada .dae and other XML formats), checked by a scan before
/// the reader sees it: assimp's readers recurse once per level, and 20000 levels overflow the stack.
inline constexpr int kMaxXmlNesting = 256;
/// A mesh file's vertex farther from the bulk of the model than this many times the median vertex's distance
/// from its centre is refused as a stray (it would make the bounding box its own).
inline constexpr double kMaxOutlierRatio = 1000.0;
/// Most pixels of a rendered frame (width x height; 4096 x 4096).
inline constexpr int64_t kMaxImagePixels = int64_t{4096} * 4096;
/// Most substeps per frame (fixed or automatic cap).
inline constexpr int kMaxSubsteps = 100000;
/// Most Newton or local/global iterations per step.
inline constexpr int kMaxIterations = 1000;
/// Servo rates a scene (servo.rate_hz) or --servo-rate may ask for, Hz.
inline constexpr double kMinServoRate_hz = 100.0;
inline constexpr double kMaxServoRate_hz = 20000.0;

/// The limits above as a few lines of text, for --help (the memory's limits as this machine has them).
std::string limits_help();

}  // namespace palpate
