#pragma once
// Test helpers: real second processes (palpate, palpate-device) started with fork/exec, their output in a file,
// signals, bounded waits; scenes and CSV files read back.

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/read_file.h"
#include "support/temp_root.h"

namespace palpate::test {

/// Folder of the built executables.
inline std::string bin_dir() {
  const char* b = std::getenv("PALPATE_BIN_DIR");
  return b ? b : "build/bin";
}

/// A child process; killed (SIGKILL) and reaped on destruction if still running.
class Child {
 public:
  /// Starts argv[0] (a path) with stdout+stderr to out_path; no core files.
  Child(const std::vector<std::string>& argv, std::string out_path) : out_(std::move(out_path)) {
    pid_ = fork();
    if (pid_ == 0) {
      rlimit no_core{0, 0};
      setrlimit(RLIMIT_CORE, &no_core);
      std::FILE* f = std::fopen(out_.c_str(), "w");
      if (f) {
        dup2(fileno(f), 1);
        dup2(fileno(f), 2);
      }
      std::vector<char*> args;
      for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      execv(args[0], args.data());
      _exit(127);
    }
  }
  ~Child() {
    if (pid_ > 0 && !done_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  /// Sends a signal.
  void signal(int sig) const { kill(pid_, sig); }
  /// Waits up to timeout_s; returns the exit code, -signal when killed, or -1000 on timeout (then kills it).
  int wait(double timeout_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < end) {
      int st = 0;
      if (waitpid(pid_, &st, WNOHANG) == pid_) {
        done_ = true;
        return WIFEXITED(st) ? WEXITSTATUS(st) : -WTERMSIG(st);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
    done_ = true;
    return -1000;
  }
  /// Waits up to timeout_s for `needle` in the output; true when seen.
  bool wait_for_output(const std::string& needle, double timeout_s) const {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < end) {
      if (output().find(needle) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }
  /// Output so far.
  std::string output() const { return read_file(out_); }
  /// Process id.
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
  std::string out_;
  bool done_ = false;
};

/// Sleeps for s seconds.
inline void sleep_s(double s) { std::this_thread::sleep_for(std::chrono::duration<double>(s)); }

/// A CSV file as header names and numeric rows (non-numeric cells become NaN).
struct Csv {
  std::vector<std::string> head;
  std::vector<std::vector<double>> rows;
  /// Column index by name (-1 when absent).
  int col(const std::string& name) const {
    for (std::size_t i = 0; i < head.size(); ++i)
      if (head[i] == name) return static_cast<int>(i);
    return -1;
  }
};

/// Reads a CSV file written by palpate or palpate-device.
inline Csv read_csv(const std::string& path) {
  Csv c;
  std::istringstream in(read_file(path));
  std::string line, cell;
  bool first = true;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::vector<double> row;
    while (std::getline(ls, cell, ',')) {
      if (first) c.head.push_back(cell);
      else row.push_back(std::strtod(cell.c_str(), nullptr));
    }
    if (!first) c.rows.push_back(row);
    first = false;
  }
  return c;
}

/// cube_press (pressed and held) with realtime run mode, the given duration and device keys, in a temporary file.
inline std::string device_scene(const std::string& name, double duration_s, const nlohmann::json& device_keys) {
  nlohmann::json j = nlohmann::json::parse(read_file(std::string(PALPATE_SOURCE_DIR) + "/scenes/cube_press.json"));
  j["name"] = name;
  j["duration_s"] = duration_s;
  j["run_mode"] = "realtime";
  for (const auto& [k, v] : device_keys.items()) j["device"][k] = v;
  // press by 0.3 s and hold: faults injected at loosely timed moments still find the tool in contact
  j["trajectory"] = nlohmann::json::array({{{"t_s", 0.0}, {"pos_m", {0.004, 0.004, 0.045}}},
                                           {{"t_s", 0.3}, {"pos_m", {0.004, 0.004, 0.012}}},
                                           {{"t_s", 60.0}, {"pos_m", {0.004, 0.004, 0.012}}}});
  const std::string path = (std::filesystem::path(test::temp_root()) / ("palpate_" + name + ".json")).string();
  std::ofstream(path) << j.dump(2);
  return path;
}

/// A link name unique to this test process.
inline std::string link_name(const std::string& base) { return base + "-" + std::to_string(getpid()); }

}  // namespace palpate::test
