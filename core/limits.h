#pragma once
/// Limits on what a scene, a file or a command line may ask for, checked before anything is allocated or
/// written, so a hostile or mistaken input is refused with the limit named instead of taking the machine.

#include <cstdint>

namespace palpate {

/// Largest scene file read, bytes (16 MiB).
inline constexpr int64_t kMaxSceneFileBytes = int64_t{16} << 20;
/// Largest replay log (haptic.csv) read, bytes (256 MiB, about 20 minutes at 1 kHz).
inline constexpr int64_t kMaxReplayFileBytes = int64_t{256} << 20;
/// Largest mesh file read, bytes (512 MiB).
inline constexpr int64_t kMaxMeshFileBytes = int64_t{512} << 20;
/// Deepest nesting of arrays and objects in a scene file (a scene needs 4), checked before parsing.
inline constexpr int kMaxJsonNesting = 64;
/// Most trajectory keyframes in a scene.
inline constexpr int kMaxKeyframes = 100000;
/// Most lattice nodes a scene's lattice may reach (estimated from the grid before it is built).
inline constexpr int64_t kMaxLatticeNodes = 65536;
/// Most lattice springs a scene's lattice may reach (estimated likewise).
inline constexpr int64_t kMaxLatticeSprings = 1048576;
/// Most triangles of a model after mesh.subdivisions (each subdivision makes 4 of every triangle).
inline constexpr int64_t kMaxTriangles = int64_t{1} << 22;
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

/// The limits above as a few lines of text, for --help.
inline constexpr const char* kLimitsHelp =
    "Limits: scene file 16 MiB (JSON nested 64 deep), mesh file 512 MiB, replay log 256 MiB; 100000 keyframes; 4194304 triangles (after mesh.subdivisions); grid.levels 8 "
    "(2097152 cells); XML mesh nesting 256 levels; lattice 65536 nodes and 1048576 springs (estimated from the scene and its grid before "
    "anything is built); frames 4096 x 4096 pixels; 100000 substeps; 1000 iterations; servo rate 100..20000 Hz.";

}  // namespace palpate
