#pragma once
// The palpate command run as a user runs it: a shell command's exit code and its stdout + stderr.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace palpate::test {

/// What a command printed (stdout and stderr together) and its exit code (-1 when it did not exit normally).
struct CliRun {
  int code = -1;
  std::string out;
};

/// Runs `cmd` through the shell and waits for it.
inline CliRun shell(const std::string& cmd) {
  CliRun r;
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), buf.size(), p)) r.out += buf.data();
  const int st = pclose(p);
  r.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

/// The palpate program in the build's bin folder ($PALPATE_BIN_DIR, set by ctest; else build/bin).
inline std::string palpate_path() {
  const char* bin = std::getenv("PALPATE_BIN_DIR");
  return std::string(bin ? bin : "build/bin") + "/palpate";
}

/// Runs `palpate ARGS` (palpate_path()).
inline CliRun palpate(const std::string& args) { return shell(palpate_path() + " " + args); }

}  // namespace palpate::test
