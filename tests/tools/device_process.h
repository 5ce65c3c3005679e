#include "support/temp_root.h"
#pragma once
#include "support/temp_root.h"
// Test helpers: real second processes (palpate, palpate-device) started with fork/exec, their output in a file,
#include "support/temp_root.h"
// signals, bounded waits; scenes and CSV files read back.
#include "support/temp_root.h"

#include "support/temp_root.h"
#include <signal.h>
#include "support/temp_root.h"
#include <sys/resource.h>
#include "support/temp_root.h"
#include <sys/wait.h>
#include "support/temp_root.h"
#include <unistd.h>
#include "support/temp_root.h"

#include "support/temp_root.h"
#include <chrono>
#include "support/temp_root.h"
#include <cstdlib>
#include "support/temp_root.h"
#include <filesystem>
#include "support/temp_root.h"
#include <fstream>
#include "support/temp_root.h"
#include <sstream>
#include "support/temp_root.h"
#include <string>
#include "support/temp_root.h"
#include <thread>
#include "support/temp_root.h"
#include <vector>
#include "support/temp_root.h"

#include "support/temp_root.h"
#include <nlohmann/json.hpp>
#include "support/temp_root.h"

#include "support/temp_root.h"
namespace palpate::test {
#include "support/temp_root.h"

#include "support/temp_root.h"
/// Folder of the built executables.
#include "support/temp_root.h"
inline std::string bin_dir() {
#include "support/temp_root.h"
  const char* b = std::getenv("PALPATE_BIN_DIR");
#include "support/temp_root.h"
  return b ? b : "build/bin";
#include "support/temp_root.h"
}
#include "support/temp_root.h"

#include "support/temp_root.h"
/// Whole file as text ("" when absent).
#include "support/temp_root.h"
inline std::string slurp(const std::string& path) {
#include "support/temp_root.h"
  std::ifstream f(path, std::ios::binary);
#include "support/temp_root.h"
  std::ostringstream s;
#include "support/temp_root.h"
  s << f.rdbuf();
#include "support/temp_root.h"
  return s.str();
#include "support/temp_root.h"
}
#include "support/temp_root.h"

#include "support/temp_root.h"
/// A child process; killed (SIGKILL) and reaped on destruction if still running.
#include "support/temp_root.h"
class Child {
#include "support/temp_root.h"
 public:
#include "support/temp_root.h"
  /// Starts argv[0] (a path) with stdout+stderr to out_path; no core files.
#include "support/temp_root.h"
  Child(const std::vector<std::string>& argv, std::string out_path) : out_(std::move(out_path)) {
#include "support/temp_root.h"
    pid_ = fork();
#include "support/temp_root.h"
    if (pid_ == 0) {
#include "support/temp_root.h"
      rlimit no_core{0, 0};
#include "support/temp_root.h"
      setrlimit(RLIMIT_CORE, &no_core);
#include "support/temp_root.h"
      std::FILE* f = std::fopen(out_.c_str(), "w");
#include "support/temp_root.h"
      if (f) {
#include "support/temp_root.h"
        dup2(fileno(f), 1);
#include "support/temp_root.h"
        dup2(fileno(f), 2);
#include "support/temp_root.h"
      }
#include "support/temp_root.h"
      std::vector<char*> args;
#include "support/temp_root.h"
      for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
#include "support/temp_root.h"
      args.push_back(nullptr);
#include "support/temp_root.h"
      execv(args[0], args.data());
#include "support/temp_root.h"
      _exit(127);
#include "support/temp_root.h"
    }
#include "support/temp_root.h"
  }
#include "support/temp_root.h"
  ~Child() {
#include "support/temp_root.h"
    if (pid_ > 0 && !done_) {
#include "support/temp_root.h"
      kill(pid_, SIGKILL);
#include "support/temp_root.h"
      waitpid(pid_, nullptr, 0);
#include "support/temp_root.h"
    }
#include "support/temp_root.h"
  }
#include "support/temp_root.h"
  Child(const Child&) = delete;
#include "support/temp_root.h"
  Child& operator=(const Child&) = delete;
#include "support/temp_root.h"

#include "support/temp_root.h"
  /// Sends a signal.
#include "support/temp_root.h"
  void signal(int sig) const { kill(pid_, sig); }
#include "support/temp_root.h"
  /// Waits up to timeout_s; returns the exit code, -signal when killed, or -1000 on timeout (then kills it).
#include "support/temp_root.h"
  int wait(double timeout_s) {
#include "support/temp_root.h"
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
#include "support/temp_root.h"
    while (std::chrono::steady_clock::now() < end) {
#include "support/temp_root.h"
      int st = 0;
#include "support/temp_root.h"
      if (waitpid(pid_, &st, WNOHANG) == pid_) {
#include "support/temp_root.h"
        done_ = true;
#include "support/temp_root.h"
        return WIFEXITED(st) ? WEXITSTATUS(st) : -WTERMSIG(st);
#include "support/temp_root.h"
      }
#include "support/temp_root.h"
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
#include "support/temp_root.h"
    }
#include "support/temp_root.h"
    kill(pid_, SIGKILL);
#include "support/temp_root.h"
    waitpid(pid_, nullptr, 0);
#include "support/temp_root.h"
    done_ = true;
#include "support/temp_root.h"
    return -1000;
#include "support/temp_root.h"
  }
#include "support/temp_root.h"
  /// Waits up to timeout_s for `needle` in the output; true when seen.
#include "support/temp_root.h"
  bool wait_for_output(const std::string& needle, double timeout_s) const {
#include "support/temp_root.h"
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
#include "support/temp_root.h"
    while (std::chrono::steady_clock::now() < end) {
#include "support/temp_root.h"
      if (output().find(needle) != std::string::npos) return true;
#include "support/temp_root.h"
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
#include "support/temp_root.h"
    }
#include "support/temp_root.h"
    return false;
#include "support/temp_root.h"
  }
#include "support/temp_root.h"
  /// Output so far.
#include "support/temp_root.h"
  std::string output() const { return slurp(out_); }
#include "support/temp_root.h"
  /// Process id.
#include "support/temp_root.h"
  pid_t pid() const { return pid_; }
#include "support/temp_root.h"

#include "support/temp_root.h"
 private:
#include "support/temp_root.h"
  pid_t pid_ = -1;
#include "support/temp_root.h"
  std::string out_;
#include "support/temp_root.h"
  bool done_ = false;
#include "support/temp_root.h"
};
#include "support/temp_root.h"

#include "support/temp_root.h"
/// Sleeps for s seconds.
#include "support/temp_root.h"
inline void sleep_s(double s) { std::this_thread::sleep_for(std::chrono::duration<double>(s)); }
#include "support/temp_root.h"

#include "support/temp_root.h"
/// A CSV file as header names and numeric rows (non-numeric cells become NaN).
#include "support/temp_root.h"
struct Csv {
#include "support/temp_root.h"
  std::vector<std::string> head;
#include "support/temp_root.h"
  std::vector<std::vector<double>> rows;
#include "support/temp_root.h"
  /// Column index by name (-1 when absent).
#include "support/temp_root.h"
  int col(const std::string& name) const {
#include "support/temp_root.h"
    for (std::size_t i = 0; i < head.size(); ++i)
#include "support/temp_root.h"
      if (head[i] == name) return static_cast<int>(i);
#include "support/temp_root.h"
    return -1;
#include "support/temp_root.h"
  }
#include "support/temp_root.h"
};
#include "support/temp_root.h"

#include "support/temp_root.h"
/// Reads a CSV file written by palpate or palpate-device.
#include "support/temp_root.h"
inline Csv read_csv(const std::string& path) {
#include "support/temp_root.h"
  Csv c;
#include "support/temp_root.h"
  std::istringstream in(slurp(path));
#include "support/temp_root.h"
  std::string line, cell;
#include "support/temp_root.h"
  bool first = true;
#include "support/temp_root.h"
  while (std::getline(in, line)) {
#include "support/temp_root.h"
    std::istringstream ls(line);
#include "support/temp_root.h"
    std::vector<double> row;
#include "support/temp_root.h"
    while (std::getline(ls, cell, ',')) {
#include "support/temp_root.h"
      if (first) c.head.push_back(cell);
#include "support/temp_root.h"
      else row.push_back(std::strtod(cell.c_str(), nullptr));
#include "support/temp_root.h"
    }
#include "support/temp_root.h"
    if (!first) c.rows.push_back(row);
#include "support/temp_root.h"
    first = false;
#include "support/temp_root.h"
  }
#include "support/temp_root.h"
  return c;
#include "support/temp_root.h"
}
#include "support/temp_root.h"

#include "support/temp_root.h"
/// cube_press (pressed and held) with realtime run mode, the given duration and device keys, in a temporary file.
#include "support/temp_root.h"
inline std::string device_scene(const std::string& name, double duration_s, const nlohmann::json& device_keys) {
#include "support/temp_root.h"
  nlohmann::json j = nlohmann::json::parse(slurp(std::string(PALPATE_SOURCE_DIR) + "/scenes/cube_press.json"));
#include "support/temp_root.h"
  j["name"] = name;
#include "support/temp_root.h"
  j["duration_s"] = duration_s;
#include "support/temp_root.h"
  j["run_mode"] = "realtime";
#include "support/temp_root.h"
  for (const auto& [k, v] : device_keys.items()) j["device"][k] = v;
#include "support/temp_root.h"
  // press by 0.3 s and hold: faults injected at loosely timed moments still find the tool in contact
#include "support/temp_root.h"
  j["trajectory"] = nlohmann::json::array({{{"t_s", 0.0}, {"pos_m", {0.004, 0.004, 0.045}}},
#include "support/temp_root.h"
                                           {{"t_s", 0.3}, {"pos_m", {0.004, 0.004, 0.012}}},
#include "support/temp_root.h"
                                           {{"t_s", 60.0}, {"pos_m", {0.004, 0.004, 0.012}}}});
#include "support/temp_root.h"
  const std::string path = (std::filesystem::path(test::temp_root()) / ("palpate_" + name + ".json")).string();
#include "support/temp_root.h"
  std::ofstream(path) << j.dump(2);
#include "support/temp_root.h"
  return path;
#include "support/temp_root.h"
}
#include "support/temp_root.h"

#include "support/temp_root.h"
/// A link name unique to this test process.
#include "support/temp_root.h"
inline std::string link_name(const std::string& base) { return base + "-" + std::to_string(getpid()); }
#include "support/temp_root.h"

#include "support/temp_root.h"
}  // namespace palpate::test
