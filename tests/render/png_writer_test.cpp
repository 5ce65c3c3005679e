#include "render/png_writer.h"

#include <gtest/gtest.h>

#include <sys/inotify.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <random>
#include <system_error>

#include "render/png_io.h"
#include "render_test_util.h"

namespace palpate {
namespace {

constexpr int kW = 48;
constexpr int kH = 32;

std::string frame_path(const test::ScratchDir& dir, int index) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", index);
  return dir.file(name);
}

void fill_frame(uint8_t* rgba, int index) {
  for (int i = 0; i < kW * kH * 4; ++i) rgba[i] = static_cast<uint8_t>(index * 31 + i / 4 + (i % 4) * 64);
}

// A thread the system refuses (here: no address space left for its stack) ends the construction with
// std::system_error, the threads already started stopped and joined; it never destroys a running thread
// (std::terminate, the process aborted). In a child process, whose address space is capped 24 MB above what it uses.
TEST(PngWriter, AThreadTheSystemRefusesIsAnErrorNotAnAbort) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's shadow memory does not fit under an address-space limit";
#else
  test::ScratchDir scratch("png_writer_threads");
  const std::string dir = scratch.str();
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    long pages = 0;
    if (FILE* f = std::fopen("/proc/self/statm", "r")) {
      if (std::fscanf(f, "%ld", &pages) != 1) pages = 0;
      std::fclose(f);
    }
    const rlim_t cap = static_cast<rlim_t>(pages) * static_cast<rlim_t>(::sysconf(_SC_PAGESIZE)) + (24u << 20);
    const rlimit lim{cap, cap};
    if (pages == 0 || ::setrlimit(RLIMIT_AS, &lim) != 0) std::_Exit(3);
    PngWriterConfig config;
    config.threads = 64;  // 64 stacks of 8 MB: far past the cap
    try {
      PngWriter writer(dir, 1, 1, 1, config);
      std::_Exit(2);  // every thread started: the cap did not bite
    } catch (const std::system_error&) {
      std::_Exit(0);
    } catch (...) {
      std::_Exit(4);
    }
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << "the child died of signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0)
                                 << " (6: std::terminate, a running thread destroyed)";
  EXPECT_EQ(WEXITSTATUS(status), 0) << "2: every thread started; 3: no cap set; 4: another exception";
#endif
}

TEST(PngWriter, WritesNumberedFramesInOrder) {
  test::ScratchDir dir("png_writer");
  constexpr int kFrames = 12;
  std::vector<double> png_ms;
  {
    PngWriter writer(dir.str(), kW, kH, 3);
    for (int i = 1; i <= kFrames; ++i) {
      uint8_t* buffer = writer.acquire(/*block=*/true);
      ASSERT_NE(buffer, nullptr);
      fill_frame(buffer, i);
      writer.submit(i, buffer);
    }
    writer.finish();
    writer.finish();  // idempotent
    EXPECT_EQ(writer.frames_written(), kFrames);
    EXPECT_EQ(writer.write_errors(), 0) << writer.first_error();
    EXPECT_EQ(writer.first_error(), "");
    png_ms = writer.png_ms();
  }
  ASSERT_EQ(png_ms.size(), static_cast<std::size_t>(kFrames));
  for (double ms : png_ms) EXPECT_GT(ms, 0.0);

  std::vector<uint8_t> expected(kW * kH * 4);
  auto previous_time = std::filesystem::file_time_type::min();
  for (int i = 1; i <= kFrames; ++i) {
    auto image = read_png(frame_path(dir, i));
    ASSERT_TRUE(image.ok()) << image.error().message;
    fill_frame(expected.data(), i);
    EXPECT_EQ(image.value().rgba, expected) << "frame " << i;
    // one thread writes in submission order, so modification times never go backwards
    const auto t = std::filesystem::last_write_time(frame_path(dir, i));
    EXPECT_GE(t, previous_time) << "frame " << i;
    previous_time = t;
  }
  EXPECT_FALSE(std::filesystem::exists(frame_path(dir, 0)));
  EXPECT_FALSE(std::filesystem::exists(frame_path(dir, kFrames + 1)));
}

// Frames alternate between noise (slow to compress) and flat (fast), so with two threads a flat frame is ready
// long before the noisy frame before it: the writer must still rename them in order. inotify reports every
// rename into the folder in the order the kernel made them.
TEST(PngWriter, ParallelEncodersRenameFramesInSubmissionOrder) {
  constexpr int kW2 = 640, kH2 = 480, kFrames = 16;
  test::ScratchDir dir("png_writer_par");
  const int fd = inotify_init1(IN_NONBLOCK);
  ASSERT_GE(fd, 0);
  ASSERT_GE(inotify_add_watch(fd, dir.str().c_str(), IN_MOVED_TO), 0);
  std::vector<std::vector<uint8_t>> expected;
  std::mt19937 rng(5);
  {
    PngWriterConfig config;
    config.threads = 2;
    PngWriter writer(dir.str(), kW2, kH2, 4, config);
    for (int i = 0; i < kFrames; ++i) {
      std::vector<uint8_t> img(static_cast<std::size_t>(kW2) * kH2 * 4, 255);
      if (i % 2 == 0)
        for (std::size_t k = 0; k < img.size(); ++k) img[k] = (k % 4 == 3) ? 255 : static_cast<uint8_t>(rng());
      uint8_t* buffer = writer.acquire(true);
      ASSERT_NE(buffer, nullptr);
      std::copy(img.begin(), img.end(), buffer);
      writer.submit(i, buffer);
      expected.push_back(std::move(img));
    }
    writer.finish();
    EXPECT_EQ(writer.frames_written(), kFrames);
    EXPECT_EQ(writer.write_errors(), 0) << writer.first_error();
    EXPECT_EQ(writer.png_ms().size(), static_cast<std::size_t>(kFrames));
  }
  std::vector<std::string> renamed;
  alignas(inotify_event) char events[16384];
  for (;;) {
    const ssize_t n = read(fd, events, sizeof events);
    if (n <= 0) break;
    for (ssize_t at = 0; at < n;) {
      const auto* e = reinterpret_cast<const inotify_event*>(events + at);
      if (e->len > 0) renamed.emplace_back(e->name);
      at += static_cast<ssize_t>(sizeof(inotify_event) + e->len);
    }
  }
  close(fd);
  std::vector<std::string> in_order;
  for (int i = 0; i < kFrames; ++i) in_order.push_back(std::filesystem::path(frame_path(dir, i)).filename().string());
  EXPECT_EQ(renamed, in_order);
  for (int i = 0; i < kFrames; ++i) {
    auto image = read_png(frame_path(dir, i));
    ASSERT_TRUE(image.ok()) << image.error().message;
    EXPECT_EQ(image.value().rgba, expected[static_cast<std::size_t>(i)]) << "frame " << i;
  }
}

TEST(PngWriter, AcquireWithoutBlockingReturnsNullWhenPoolIsExhausted) {
  test::ScratchDir dir("png_writer");
  PngWriter writer(dir.str(), kW, kH, 2);
  uint8_t* a = writer.acquire(false);
  uint8_t* b = writer.acquire(false);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_NE(a, b);
  EXPECT_EQ(writer.acquire(false), nullptr);
  fill_frame(a, 7);
  writer.submit(7, a);
  uint8_t* c = writer.acquire(true);  // comes back once frame 7 is written
  EXPECT_EQ(c, a);
  writer.submit(8, b);
  writer.finish();
  EXPECT_EQ(writer.frames_written(), 2);
  EXPECT_EQ(writer.acquire(true), nullptr);  // finished: nothing to wait for
  EXPECT_TRUE(std::filesystem::exists(frame_path(dir, 7)));
  EXPECT_TRUE(std::filesystem::exists(frame_path(dir, 8)));
}

TEST(PngWriter, WriteFailuresAreCountedWithTheFirstPath) {
  test::ScratchDir dir("png_writer");
  const std::string missing = dir.file("missing");
  PngWriter writer(missing, kW, kH, 2);
  for (int i = 1; i <= 3; ++i) {
    uint8_t* buffer = writer.acquire(true);
    ASSERT_NE(buffer, nullptr);
    writer.submit(i, buffer);
  }
  writer.finish();
  EXPECT_EQ(writer.frames_written(), 0);
  EXPECT_EQ(writer.write_errors(), 3);
  EXPECT_NE(writer.first_error().find(missing + "/frame_00001.png"), std::string::npos) << writer.first_error();
  EXPECT_TRUE(writer.png_ms().empty());
}

// a frame that cannot be written (here a folder in its place; on a full disk ENOSPC) ends the sequence: no later
// frame is renamed, so the folder keeps the gapless prefix before it and no temporary
TEST(PngWriter, AFailedFrameEndsTheSequenceWithoutAGap) {
  test::ScratchDir dir("png_writer_gap");
  std::filesystem::create_directory(frame_path(dir, 3));
  PngWriterConfig config;
  config.threads = 2;
  PngWriter writer(dir.str(), kW, kH, 4, config);
  for (int i = 0; i < 8; ++i) {
    uint8_t* buffer = writer.acquire(true);
    ASSERT_NE(buffer, nullptr);
    fill_frame(buffer, i);
    writer.submit(i, buffer);
  }
  writer.finish();
  EXPECT_EQ(writer.frames_written(), 3);
  EXPECT_EQ(writer.write_errors(), 5);
  EXPECT_NE(writer.first_error().find(frame_path(dir, 3) + "': is not a regular file"), std::string::npos)
      << writer.first_error();
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(read_png(frame_path(dir, i)).ok()) << i;
  EXPECT_TRUE(std::filesystem::is_directory(frame_path(dir, 3)));
  for (int i = 4; i < 8; ++i) EXPECT_FALSE(std::filesystem::exists(frame_path(dir, i))) << i;
  for (const auto& e : std::filesystem::directory_iterator(dir.str()))
    EXPECT_NE(e.path().extension(), ".tmp") << e.path();
}

TEST(PngWriter, SubmitAfterFinishAndForeignBuffersAreErrors) {
  test::ScratchDir dir("png_writer");
  PngWriter writer(dir.str(), kW, kH, 2);
  std::vector<uint8_t> foreign(kW * kH * 4);
  writer.submit(1, foreign.data());
  uint8_t* buffer = writer.acquire(false);
  ASSERT_NE(buffer, nullptr);
  writer.finish();
  writer.submit(2, buffer);
  EXPECT_EQ(writer.write_errors(), 2);
  EXPECT_EQ(writer.frames_written(), 0);
  EXPECT_NE(writer.first_error().find("frame_00001.png"), std::string::npos) << writer.first_error();
  EXPECT_TRUE(std::filesystem::is_empty(dir.str()));
}

}  // namespace
}  // namespace palpate
