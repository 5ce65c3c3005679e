// haptic.csv on a full disk: a clear error naming the file, and the rows already written kept.
#include "runtime/session/haptic_log.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "support/file_size_limit.h"
#include "support/fixtures.h"
#include "support/read_file.h"

namespace palpate {
namespace {

TEST(HapticLog, FailedWriteIsAnErrorNamingTheLog) {
  // a file size limit makes the writes fail (EFBIG) as a full disk does (ENOSPC)
  const std::string dir = test::fresh_dir("log_full");
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/haptic.csv";
  Status st = Ok{};
  HapticLog log;
  {
    test::FileSizeLimit limit(8192);
    ASSERT_TRUE(log.open(path));
    HapticSample s;
    for (int i = 0; i < 2000; ++i) log.append(s);  // more than a stdio buffer
    st = log.close();
  }
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("log '" + path + "'"), std::string::npos) << st.error().message;
  EXPECT_NE(st.error().message.find("File too large"), std::string::npos) << st.error().message;
  EXPECT_FALSE(std::filesystem::exists(path));  // not renamed: the final name only ever holds a whole log
  // what is kept is the .partial, and its rows are what the log reports, not the rows handed to the stream
  EXPECT_EQ(log.kept_path(), path + ".partial");
  const std::string kept = test::read_file(path + ".partial");
  ASSERT_LE(kept.size(), 8192u);
  EXPECT_EQ(log.kept_rows(), std::count(kept.begin(), kept.end(), '\n') - 1);
  EXPECT_GT(log.kept_rows(), 0);
  EXPECT_LT(log.kept_rows(), log.rows()) << "rows the stream took that never reached the disk are not counted";
}

TEST(HapticLog, APlantedLinkAtThePartialNameIsNotFollowed) {
  const std::string dir = test::fresh_dir("log_link");
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/haptic.csv";
  {
    std::ofstream(dir + "/victim") << "keep";
  }
  std::filesystem::create_symlink(dir + "/victim", path + ".partial");
  HapticLog log;
  ASSERT_TRUE(log.open(path));
  log.append(HapticSample{});
  ASSERT_TRUE(log.close());
  EXPECT_EQ(test::read_file(dir + "/victim"), "keep");
}

TEST(HapticLog, WritesOneRowPerSampleAndRenamesWhenClosed) {
  const std::string dir = test::fresh_dir("log_ok");
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/haptic.csv";
  HapticLog log;
  ASSERT_TRUE(log.open(path));
  HapticSample s;
  for (int i = 0; i < 10; ++i) {
    s.tick = i;
    log.append(s);
  }
  EXPECT_TRUE(std::filesystem::exists(path + ".partial"));
  ASSERT_TRUE(log.close());
  EXPECT_EQ(log.rows(), 10);
  EXPECT_EQ(log.kept_rows(), 10);
  EXPECT_EQ(log.kept_path(), path);
  EXPECT_TRUE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(path + ".partial"));
}

}  // namespace
}  // namespace palpate
