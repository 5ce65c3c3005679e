// The mesh load path on every committed seed of the mesh fuzz targets (tests/fuzz/corpus/mesh_<ext>/), in this process
// as the fuzz targets read them: a Model with finite vertices inside its normalisation cube and triangles that index
// them, or one line naming the mesh. Run again under ASan + UBSan in CI (label hostile), which is where the seeds'
// regressions are replayed; the libFuzzer targets explore new inputs (scripts/fuzz.sh SECONDS mesh_off ...).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "core/mesh_io.h"
#include "core/scene.h"
#include "support/fixtures.h"
#include "runtime/session/model.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

TEST(MeshSeeds, EveryCommittedFuzzSeedLoadsOrIsRefusedInOneLine) {
  set_default_mesh_reader_isolation(MeshReaderIsolation::in_process);
  const std::string dir = test::fresh_dir("mesh_seeds");
  fs::create_directories(dir);
  int seeds = 0, loaded = 0;
  for (const char* ext : {"off", "ply", "obj", "stl", "dae"}) {
    const fs::path corpus = fs::path(test::source_path("tests/fuzz/corpus")) / (std::string("mesh_") + ext);
    ASSERT_TRUE(fs::is_directory(corpus)) << corpus;
    // the scene the fuzz target writes for its file: a small grid (levels 3, lattice at level 2)
    const std::string mesh = dir + "/seed." + ext;
    auto scene = parse_scene("{\"mesh\": {\"file\": \"" + mesh + "\", \"size_m\": 0.05}, \"grid\": {\"levels\": 3}, "
                             "\"lattice\": {\"level\": 2}, \"trajectory\": [{\"t_s\": 0, \"pos_m\": [0, 0, 0.05]}]}",
                             "seed.json");
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    for (const auto& entry : fs::directory_iterator(corpus)) {
      std::error_code ec;
      fs::copy_file(entry.path(), mesh, fs::copy_options::overwrite_existing, ec);
      ASSERT_FALSE(ec) << entry.path() << ": " << ec.message();
      ++seeds;
      const auto model = load_model(scene.value());
      if (!model) {
        const std::string& m = model.error().message;
        EXPECT_TRUE(m.rfind("mesh '" + mesh + "': ", 0) == 0 || m.rfind("scene 'seed.json': ", 0) == 0)
            << entry.path() << ": " << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << entry.path() << ": " << m;
        continue;
      }
      ++loaded;
      const Model& mdl = model.value();
      EXPECT_FALSE(mdl.rest.triangles.empty()) << entry.path();
      EXPECT_EQ(mdl.bindings.size(), mdl.rest.vertices_m.size()) << entry.path();
      Aabb cube = mdl.normalization.cube;
      cube.min_m.array() -= 1e-9;
      cube.max_m.array() += 1e-9;
      for (const Vec3& v : mdl.rest.vertices_m) {
        ASSERT_TRUE(v.allFinite() && cube.contains(v)) << entry.path();
      }
      const auto n = static_cast<int32_t>(mdl.rest.vertices_m.size());
      for (const auto& t : mdl.rest.triangles)
        for (int32_t id : t) ASSERT_TRUE(id >= 0 && id < n) << entry.path();
    }
  }
  EXPECT_GT(seeds, 30);
  EXPECT_GT(loaded, 0);
  std::printf("[ figures ] %d mesh seeds: %d loaded, %d refused in one line\n", seeds, loaded, seeds - loaded);
}

}  // namespace
}  // namespace palpate
