#include "support/temp_root.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <vector>

namespace palpate::test {
namespace {

// Owns the folder; removes it at exit in the process that made it (a forked child that exits does not).
class TempRoot {
 public:
  TempRoot() : owner_pid_(::getpid()) {
    const char* env = std::getenv("TMPDIR");
    const std::string base = (env != nullptr && env[0] != '\0') ? env : "/tmp";
    std::string pattern = base + "/palpate_test_XXXXXX";
    std::vector<char> buf(pattern.begin(), pattern.end());
    buf.push_back('\0');
    if (::mkdtemp(buf.data()) == nullptr) {
      std::perror("palpate tests: mkdtemp");
      std::abort();
    }
    path_ = buf.data();
  }
  ~TempRoot() {
    if (::getpid() != owner_pid_) return;
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempRoot(const TempRoot&) = delete;
  TempRoot& operator=(const TempRoot&) = delete;
  const std::string& path() const { return path_; }

 private:
  pid_t owner_pid_;
  std::string path_;
};

}  // namespace

const std::string& temp_root() {
  static TempRoot root;
  return root.path();
}

std::string temp_path(const std::string& prefix, const std::string& name) {
  return (std::filesystem::path(temp_root()) / (prefix + name)).string();
}

}  // namespace palpate::test
