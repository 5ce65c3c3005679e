// libFuzzer targets: file bytes -> the whole mesh load path a scene's mesh takes (load_model: the checks made
// before the reader, assimp reading the file by its extension, the project's own validation, welding and
// degenerate removal, the triangle limit, normalisation, the grid hierarchy on a 3-level grid, the lattice
// limits and the vertex bindings), with the limits a user gets: a Model or a one-line error naming the mesh,
// never a crash, a hang, a leak or undefined behaviour; a loaded model holds finite vertices inside its
// normalisation cube and triangles that index them. Built once per format hint (PALPATE_FUZZ_MESH_EXT: off,
// ply, obj, stl, dae), each from its own seeds in tests/fuzz/corpus/mesh_<ext>/. The reader runs in this process
// (LLVMFuzzerInitialize), not in the child palpate forks for it.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/mesh_io.h"
#include "core/scene.h"
#include "runtime/session/model.h"

#ifndef PALPATE_FUZZ_MESH_EXT
#error "PALPATE_FUZZ_MESH_EXT (the file extension the reader is chosen by) must be defined"
#endif

namespace {

// one file per process, rewritten for every input (in $TMPDIR, removed at exit)
struct FuzzFile {
  std::string path;
  FuzzFile() {
    const char* tmp = std::getenv("TMPDIR");
    path = std::string(tmp && *tmp ? tmp : "/tmp") + "/palpate_mesh_fuzz_" + std::to_string(::getpid()) + "." +
           PALPATE_FUZZ_MESH_EXT;
  }
  ~FuzzFile() { std::remove(path.c_str()); }
};

// the scene a user would write for the file: its mesh on a small grid (levels 3, lattice at level 2)
palpate::Scene scene_for(const std::string& mesh_path) {
  const std::string json = "{\"mesh\": {\"file\": \"" + mesh_path +
                           "\", \"size_m\": 0.05}, \"grid\": {\"levels\": 3}, \"lattice\": {\"level\": 2}, "
                           "\"trajectory\": [{\"t_s\": 0, \"pos_m\": [0, 0, 0.05]}]}";
  auto scene = palpate::parse_scene(json, "fuzz.json");
  if (!scene) {
    std::fprintf(stderr, "fuzz scene refused: %s\n", scene.error().message.c_str());
    std::abort();
  }
  return std::move(scene).value();
}

}  // namespace

// the reader runs in this process here (palpate forks a child for it): its crashes are the findings, and a child
// per input would hide its coverage and cost a fork each
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  palpate::set_default_mesh_reader_isolation(palpate::MeshReaderIsolation::in_process);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  static FuzzFile file;
  static const palpate::Scene scene = scene_for(file.path);
  FILE* f = std::fopen(file.path.c_str(), "wb");
  if (!f) std::abort();
  if (size > 0) std::fwrite(data, 1, size, f);
  std::fclose(f);
  auto model = palpate::load_model(scene);
  if (!model) {
    // one line naming the mesh (or the scene, for a lattice limit)
    const std::string& m = model.error().message;
    const bool named = m.rfind("mesh '" + file.path + "': ", 0) == 0 || m.rfind("scene 'fuzz.json': ", 0) == 0;
    if (!named || m.find('\n') != std::string::npos) {
      std::fprintf(stderr, "badly formed error: %s\n", m.c_str());
      std::abort();
    }
    return 0;
  }
  const palpate::Model& mdl = model.value();
  if (mdl.rest.triangles.empty() || mdl.bindings.size() != mdl.rest.vertices_m.size()) std::abort();
  palpate::Aabb cube = mdl.normalization.cube;
  cube.min_m.array() -= 1e-9;
  cube.max_m.array() += 1e-9;
  for (const palpate::Vec3& v : mdl.rest.vertices_m)
    if (!v.allFinite() || !cube.contains(v)) std::abort();
  const auto n = static_cast<int32_t>(mdl.rest.vertices_m.size());
  for (const auto& t : mdl.rest.triangles)
    for (int32_t id : t)
      if (id < 0 || id >= n) std::abort();
  return 0;
}
