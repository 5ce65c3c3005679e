// libFuzzer target: file bytes -> check_mesh_file(), the project's checks made before assimp reads a mesh (OFF/PLY header
// counts and face lines, binary PLY lists, XML nesting): Ok or a one-line error, never a crash, a hang or undefined
// behaviour. Only the project's own code runs, so CI explores it (the mesh_* targets go on into assimp).
// The first byte picks the file's extension (off, ply, obj, stl, dae), the rest is the file.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/mesh_io.h"

namespace {

// one file per process, rewritten for every input (in $TMPDIR, removed at exit)
struct FuzzFile {
  std::string base;
  FuzzFile() {
    const char* tmp = std::getenv("TMPDIR");
    base = std::string(tmp && *tmp ? tmp : "/tmp") + "/palpate_mesh_fuzz_" + std::to_string(::getpid());
  }
  ~FuzzFile() {
    for (const char* ext : {".off", ".ply", ".obj", ".stl", ".dae"}) std::remove((base + ext).c_str());
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  static FuzzFile file;
  if (size == 0) return 0;
  static const char* const kExt[] = {".off", ".ply", ".obj", ".stl", ".dae"};
  const std::string path = file.base + kExt[data[0] % 5];
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size > 1) std::fwrite(data + 1, 1, size - 1, f);
  std::fclose(f);
  auto st = palpate::check_mesh_file(path);
  if (!st) {
    const std::string& m = st.error().message;
    if (m.rfind("mesh '" + path + "': ", 0) != 0 || m.find('\n') != std::string::npos) std::abort();
  }
  std::remove(path.c_str());
  return 0;
}
