// Outputs: never over a device or through a link, every write checked, nothing half-written under the final name.
#include "core/atomic_file.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include "support/file_size_limit.h"
#include "support/fixtures.h"
#include "support/read_file.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;
using test::read_file;

TEST(AtomicFile, WritesAndRenames) {
  const std::string dir = test::fresh_dir("atomic_ok");
  fs::create_directories(dir);
  const std::string path = dir + "/a.json";
  ASSERT_TRUE(write_file_atomic(path, "{}\n", "summary"));
  EXPECT_EQ(read_file(path), "{}\n");
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  ASSERT_TRUE(write_file_atomic(path, "[]\n", "summary"));  // an earlier regular file is replaced
  EXPECT_EQ(read_file(path), "[]\n");
}

TEST(AtomicFile, RefusesADeviceAndLeavesItADevice) {
  const Status st = write_file_atomic("/dev/null", "x", "bench json");
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("bench json '/dev/null': is not a regular file"), std::string::npos)
      << st.error().message;
  struct stat s {};
  ASSERT_EQ(::stat("/dev/null", &s), 0);
  EXPECT_TRUE(S_ISCHR(s.st_mode));
}

TEST(AtomicFile, RefusesAFolderAndASymlinkAtTheFinalName) {
  const std::string dir = test::fresh_dir("atomic_targets");
  fs::create_directories(dir + "/folder");
  const Status folder = write_file_atomic(dir + "/folder", "x", "png");
  ASSERT_FALSE(folder.ok());
  EXPECT_NE(folder.error().message.find("is not a regular file"), std::string::npos) << folder.error().message;
  {
    std::ofstream(dir + "/victim") << "keep";
  }
  fs::create_symlink(dir + "/victim", dir + "/link.json");
  const Status link = write_file_atomic(dir + "/link.json", "x", "summary");
  ASSERT_FALSE(link.ok());
  EXPECT_NE(link.error().message.find("is a symbolic link"), std::string::npos) << link.error().message;
  EXPECT_EQ(read_file(dir + "/victim"), "keep");
  EXPECT_FALSE(fs::exists(dir + "/link.json.tmp"));
}

TEST(AtomicFile, APlantedLinkAtTheTemporaryNameIsNotFollowed) {
  const std::string dir = test::fresh_dir("atomic_planted");
  fs::create_directories(dir);
  {
    std::ofstream(dir + "/victim") << "keep";
  }
  fs::create_symlink(dir + "/victim", dir + "/haptic.csv.partial");
  auto f = AtomicFile::open(dir + "/haptic.csv", "log", ".partial");
  ASSERT_TRUE(f) << f.error().message;
  f.value().write("tick\n");
  ASSERT_TRUE(f.value().commit());
  EXPECT_EQ(read_file(dir + "/victim"), "keep");
  EXPECT_EQ(read_file(dir + "/haptic.csv"), "tick\n");
}

TEST(AtomicFile, AFailedWriteNamesTheFileAndLeavesNothing) {
  const std::string dir = test::fresh_dir("atomic_full");
  fs::create_directories(dir);
  const std::string path = dir + "/big.json";
  Status st = Ok{};
  {
    test::FileSizeLimit limit(4096);
    st = write_file_atomic(path, std::string(100000, 'x'), "bench json");
  }
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("bench json '" + path + "': File too large"), std::string::npos)
      << st.error().message;
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path + ".tmp"));
}

// a log kept after a failed write (here EFBIG past a file size limit; on a full disk ENOSPC) ends after its last
// whole line, never inside the line the failure tore
TEST(AtomicFile, AKeptPartialEndsAfterItsLastWholeLine) {
  const std::string dir = test::fresh_dir("atomic_partial");
  fs::create_directories(dir);
  const std::string path = dir + "/haptic.csv";
  std::string lines;
  for (int i = 0; i < 100; ++i) {
    std::string line = std::to_string(i) + ",";
    line += std::string(99 - line.size(), 'x') + "\n";  // 100 bytes a line
    lines += line;
  }
  Status st = Ok{};
  {
    test::FileSizeLimit limit(4096);
    auto f = AtomicFile::open(path, "log", ".partial");
    ASSERT_TRUE(f) << f.error().message;
    for (int i = 0; i < 100; ++i) f.value().write(std::string_view(lines).substr(static_cast<std::size_t>(i) * 100, 100));
    st = f.value().commit(/*keep_partial=*/true);
  }
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().message, "log '" + path + "': File too large (partial data kept in " + path +
                                    ".partial, up to its last whole line)");
  EXPECT_FALSE(fs::exists(path));
  EXPECT_EQ(read_file(path + ".partial"), lines.substr(0, 4000));  // 40 whole lines of the 4096 bytes written

  // no newline at all: nothing of the torn line is kept
  {
    test::FileSizeLimit limit(4096);
    auto f = AtomicFile::open(path, "log", ".partial");
    ASSERT_TRUE(f) << f.error().message;
    f.value().write(std::string(10000, 'y'));
    st = f.value().commit(/*keep_partial=*/true);
  }
  ASSERT_FALSE(st.ok());
  EXPECT_TRUE(fs::exists(path + ".partial"));
  EXPECT_EQ(fs::file_size(path + ".partial"), 0u);
}

}  // namespace
}  // namespace palpate
