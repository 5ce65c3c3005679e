// The mesh reader in a child process: a crash or a hang of the third-party reader is an error naming the file,
// the child's mesh is the in-process reader's to the bit, and forking with other threads running is safe.
#include "core/mesh_io.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include "support/fixtures.h"

namespace palpate {
namespace {

namespace fs = std::filesystem;

// a file that passes the checks made before the reader and crashes assimp itself (a null pointer in its Collada
// reader): the crash stays in the child and comes back as an error naming the file and the signal
TEST(MeshIoIsolation, ReaderCrashIsAnErrorNamingTheFileAndTheSignal) {
  for (const char* name : {"dae_reader_crash_empty_url.dae"}) {
    const std::string path = test::source_path(std::string("tests/hostile/meshes/") + name);
    const auto r = load_mesh(path);
    ASSERT_FALSE(r.ok()) << path;
    EXPECT_EQ(r.error().message, "mesh '" + path + "': the mesh reader (assimp) crashed on this file (SIGSEGV); "
                                 "the file is malformed or unsupported");
  }
  // the path printed on one line, as every mesh error prints it
  const fs::path dir = test::fresh_dir("reader_crash");
  fs::create_directories(dir);
  const std::string odd = (dir / "crash\nname.dae").string();
  fs::copy_file(test::source_path("tests/hostile/meshes/dae_reader_crash_empty_url.dae"), odd);
  const auto r = load_mesh(odd);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message.rfind("mesh '" + (dir / "crash\\x0aname.dae").string() + "': the mesh reader (assimp) "
                                    "crashed on this file (SIGSEGV)", 0), 0u) << r.error().message;
}

// a reader that does not finish is killed at the time limit (the test hook makes the child sleep 10 s first)
TEST(MeshIoIsolation, HangingReaderIsStoppedAtTheTimeLimit) {
  MeshReadOptions options;
  options.time_limit_s = 0.05;
  options.child_delay_ms_for_test = 10000;
  const std::string path = test::source_path("scenes/bunny.obj");
  const auto r = load_mesh(path, options);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "mesh '" + path + "': the mesh reader (assimp) took longer than 0.05 s on this file "
                               "and was stopped; the file is malformed or too large");
  // the killed child was reaped: no child of this process is left, not even a zombie
  errno = 0;
  EXPECT_EQ(::waitpid(-1, nullptr, WNOHANG), -1);
  EXPECT_EQ(errno, ECHILD);
}

TEST(MeshIoIsolation, TimeLimitScalesWithTheFileSize) {
  EXPECT_DOUBLE_EQ(mesh_reader_time_limit_s(0), 10.0);
  EXPECT_DOUBLE_EQ(mesh_reader_time_limit_s(100'000'000), 70.0);
  EXPECT_DOUBLE_EQ(mesh_reader_time_limit_s(int64_t{512} << 20), 10.0 + 60.0 * 536870912.0 / 1e8);
}

// the child sends back exactly the mesh (and the error) the reader makes in-process
TEST(MeshIoIsolation, ChildAndInProcessGiveTheSameMeshAndTheSameErrors) {
  MeshReadOptions in_process;
  in_process.isolation = MeshReaderIsolation::in_process;
  EXPECT_EQ(default_mesh_reader_isolation(), MeshReaderIsolation::child_process);
  const std::string bunny = test::source_path("scenes/bunny.obj");
  const auto a = load_mesh(bunny);
  const auto b = load_mesh(bunny, in_process);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a.value().vertices_m.size(), b.value().vertices_m.size());
  EXPECT_GT(a.value().vertices_m.size(), 1000u);
  EXPECT_EQ(std::memcmp(a.value().vertices_m.data(), b.value().vertices_m.data(),
                        a.value().vertices_m.size() * sizeof(Vec3)), 0);
  EXPECT_EQ(a.value().triangles, b.value().triangles);
  for (const char* name : {"off_face_out_of_range.off", "obj_nan_vertex.obj", "ply_short_vertex_lines.ply"}) {
    const std::string path = test::source_path(std::string("tests/hostile/meshes/") + name);
    const auto c = load_mesh(path);
    const auto d = load_mesh(path, in_process);
    ASSERT_FALSE(c.ok() || d.ok()) << path;
    EXPECT_EQ(c.error().message, d.error().message);
  }
}

// the child is forked while other threads of this process allocate and hold locks
TEST(MeshIoIsolation, LoadsWhileOtherThreadsRun) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  // a sanitizer's own allocator is not fork-safe: a child forked while another thread holds its lock waits for it
  // for ever (seen under ASan at -O1: the child stopped at the reader's 60 s limit). glibc's malloc, which palpate
  // runs with, takes its locks across fork; this test checks that, in the plain build.
  GTEST_SKIP() << "the sanitizer's allocator is not fork-safe under threads";
#endif
  std::atomic<bool> stop{false};
  std::mutex m;
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t)
    threads.emplace_back([&] {
      std::vector<std::string> junk;
      while (!stop.load()) {
        std::lock_guard<std::mutex> lock(m);
        junk.emplace_back(1000, 'x');
        if (junk.size() > 100) junk.clear();
      }
    });
  const std::string bunny = test::source_path("scenes/bunny.obj");
  // what is checked is that a child forked here does not hang on a lock another thread held, not its speed: a minute
  // (the child shares two cores with the two threads above, and with a sanitizer's instrumentation in CI)
  MeshReadOptions options;
  options.time_limit_s = 60.0;
  // no ASSERT here: returning with the threads still joinable would abort the whole test binary
  for (int i = 0; i < 5; ++i) {
    const auto r = load_mesh(bunny, options);
    EXPECT_TRUE(r.ok()) << r.error().message;
    if (!r.ok()) break;
    EXPECT_EQ(r.value().num_triangles(), 3674u);
  }
  stop = true;
  for (auto& t : threads) t.join();
}

}  // namespace
}  // namespace palpate
