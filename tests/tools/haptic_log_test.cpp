// haptic.csv on a full disk: a clear error naming the file, and the rows already written kept.
#include "tools/session/haptic_log.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "support/fixtures.h"

namespace palpate {
namespace {

TEST(HapticLog, FullDiskIsAnErrorNamingTheLog) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const std::string dir = test::fresh_dir("log_full");
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/haptic.csv";
  std::filesystem::create_symlink("/dev/full", path + ".partial");
  HapticLog log;
  ASSERT_TRUE(log.open(path));
  HapticSample s;
  for (int i = 0; i < 2000; ++i) log.append(s);  // more than a stdio buffer
  const Status st = log.close();
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("log '" + path + "'"), std::string::npos) << st.error().message;
  EXPECT_NE(st.error().message.find("No space left on device"), std::string::npos) << st.error().message;
  EXPECT_FALSE(std::filesystem::exists(path));  // not renamed: the final name only ever holds a whole log
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
  EXPECT_TRUE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(path + ".partial"));
}

}  // namespace
}  // namespace palpate
