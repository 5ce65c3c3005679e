// The hostile-input corpus (tests/hostile/) through the palpate command: every input ends within a time limit
// with exit 0, or with one `palpate:` line on stderr (warnings aside) and exit 1 or 2, never a signal; the
// expected exit and message come from tests/hostile/expected.tsv; a refused input leaves no output folder.
// Inputs too large to commit (deep nesting, floods, huge lines) are generated here. Run under AddressSanitizer
// and UndefinedBehaviorSanitizer by .ci/run, where a sanitizer report is a failure.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "support/temp_root.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

const std::string kCorpus = "tests/hostile";
// seconds one input may take: 120, or $PALPATE_HOSTILE_TIME_LIMIT_S (the AddressSanitizer stage of .ci/run
// gives 300: the slowest inputs, such as a 64 MiB replay line, take far longer under the sanitizers)
int time_limit_s() {
  const char* env = std::getenv("PALPATE_HOSTILE_TIME_LIMIT_S");
  const int s = env ? std::atoi(env) : 0;
  return s > 0 ? s : 120;
}
const int kTimeLimitS = time_limit_s();

struct Expectation {
  int code = 0;
  std::string text;  // empty: a run that succeeds
};

// Reads expected.tsv: "<input>\t<exit code>\t<message part or ->".
std::map<std::string, Expectation> read_expectations() {
  std::map<std::string, Expectation> out;
  std::ifstream in(std::string(PALPATE_SOURCE_DIR) + "/" + kCorpus + "/expected.tsv");
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream cells(line);
    std::string input, code, text;
    std::getline(cells, input, '\t');
    std::getline(cells, code, '\t');
    std::getline(cells, text);
    out[input] = {std::atoi(code.c_str()), text == "-" ? std::string() : text};
  }
  return out;
}

struct Outcome {
  int status = -1;  // raw wait status
  std::string err;  // stderr
};

// Runs a shell command with stdout discarded and stderr captured, under a time limit.
Outcome run(const std::string& cmd) {
  Outcome o;
  const std::string full = "timeout -k 5 " + std::to_string(kTimeLimitS) + " " + cmd + " 2>&1 >/dev/null";
  FILE* p = popen(full.c_str(), "r");
  if (!p) return o;
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), buf.size(), p)) o.err += buf.data();
  o.status = pclose(p);
  return o;
}

std::string palpate_bin() {
  const char* bin = std::getenv("PALPATE_BIN_DIR");
  return std::string(bin ? bin : "build/bin") + "/palpate";
}

std::string quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// Shows bytes outside printable ASCII as \xNN (how the manifest spells them and how palpate prints them).
std::string escaped(const std::string& s) {
  std::string out;
  for (unsigned char c : s) {
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      char b[8];
      std::snprintf(b, sizeof b, "\\x%02x", c);
      out += b;
    }
  }
  return out;
}

// The inputs generated here, by their manifest names (large, or with names a repository should not hold).
std::map<std::string, std::string> generate(const fs::path& dir) {
  fs::create_directories(dir);
  std::map<std::string, std::string> files;  // manifest name -> path
  auto put = [&](const std::string& manifest_name, const std::string& file_name, const std::string& bytes) {
    const fs::path p = dir / file_name;
    std::ofstream(p, std::ios::binary) << bytes;
    files[manifest_name] = p.string();
  };
  // Collada: 20000 nested nodes (assimp's reader recurses once per level)
  {
    std::string s = "<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" "
                    "version=\"1.4.1\">\n<library_visual_scenes><visual_scene id=\"s\">\n";
    for (int i = 0; i < 20000; ++i) s += "<node>";
    for (int i = 0; i < 20000; ++i) s += "</node>";
    s += "\n</visual_scene></library_visual_scenes>\n<scene><instance_visual_scene url=\"#s\"/></scene>\n</COLLADA>\n";
    put("generated/deep_nesting.dae", "deep_nesting.dae", s);
  }
  // one keyframe past the limit
  {
    std::string s = R"({"mesh": {"box_m": [0.06, 0.06, 0.06]}, "trajectory": [)";
    for (int i = 0; i <= 100000; ++i) {
      if (i > 0) s += ',';
      s += R"({"t_s":)";
      s += std::to_string(i);
      s += R"(,"pos_m":[0,0,0.05]})";
    }
    put("generated/keyframe_flood.json", "keyframe_flood.json", s + "]}");
  }
  // a million nested arrays (a recursive parser or destructor runs out of stack)
  put("generated/deep_arrays.json", "deep_arrays.json", std::string(1000000, '[') + std::string(1000000, ']'));
  // a 64 MiB line of digits in a replay log
  {
    std::string s = "tick,t_s,tool_x_m,tool_y_m,tool_z_m,proxy_x_m,proxy_y_m,proxy_z_m,force_x_N,force_y_N,force_z_N,"
                    "contact,buttons,rejected\n";
    s += std::string(64 << 20, '7') + "\n";
    put("generated/huge_line.csv", "huge_line.csv", s);
  }
  // a mesh whose name is not UTF-8, so its error line must not carry the raw byte
  put("generated/bad_name_\\xff.obj", "bad_name_\xff.obj", "v 0 0 0\n");
  return files;
}

// The command for one input, by its folder.
std::string command_for(const std::string& manifest_name, const std::string& path, const std::string& out) {
  const std::string bin = palpate_bin();
  if (manifest_name.rfind("scenes/", 0) == 0 || manifest_name.ends_with(".json"))
    return bin + " record " + quoted(path) + " --duration 0.1 -q --no-video --out " + quoted(out);
  if (manifest_name.rfind("replay/", 0) == 0 || manifest_name.ends_with(".csv"))
    return bin + " record " + kCorpus + "/scenes/control_box.json --duration 0.1 -q --no-render --out " + quoted(out) +
           " --device " + quoted("replay:" + path);
  return bin + " info " + quoted(path);
}

TEST(HostileCorpus, EveryInputEndsWithItsExpectedExitAndOneLine) {
  const std::map<std::string, Expectation> expected = read_expectations();
  ASSERT_GT(expected.size(), 50u) << "tests/hostile/expected.tsv not read";

  // the committed corpus, run from the source root with paths as a user gives them
  std::map<std::string, std::string> inputs;
  for (const char* folder : {"meshes", "scenes", "replay"})
    for (const auto& e : fs::directory_iterator(fs::path(PALPATE_SOURCE_DIR) / kCorpus / folder)) {
      const std::string name = std::string(folder) + "/" + e.path().filename().string();
      EXPECT_TRUE(expected.count(name)) << name << " has no line in tests/hostile/expected.tsv";
      inputs[name] = kCorpus + "/" + name;
    }
  for (const auto& [name, path] : generate(fs::path(test::temp_root()) / "hostile_generated")) inputs[name] = path;
  for (const auto& [name, e] : expected) EXPECT_TRUE(inputs.count(name)) << name << " is listed but not in the corpus";

  // each input's wall time, the slowest printed at the end (a figure, not a pass/fail: the limit above is the test)
  std::vector<std::pair<double, std::string>> seconds;
  struct Slowest {
    std::vector<std::pair<double, std::string>>* s;
    ~Slowest() {
      std::sort(s->rbegin(), s->rend());
      for (std::size_t i = 0; i < std::min<std::size_t>(3, s->size()); ++i)
        std::printf("[ figures ] slowest input %zu: %s, %.2f s\n", i + 1, (*s)[i].second.c_str(), (*s)[i].first);
    }
  } slowest{&seconds};
  int index = 0;
  for (const auto& [name, path] : inputs) {
    if (!expected.count(name)) continue;
    const Expectation& want = expected.at(name);
    const std::string out = (fs::path(test::temp_root()) / ("corpus_out_" + std::to_string(index++))).string();
    const auto t0 = std::chrono::steady_clock::now();
    const Outcome o = run(command_for(name, path, out));
    seconds.emplace_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), name);
    SCOPED_TRACE(name + ": " + o.err);
    ASSERT_TRUE(WIFEXITED(o.status)) << "ended by a signal";
    const int code = WEXITSTATUS(o.status);
    ASSERT_NE(code, 124) << "took longer than " << kTimeLimitS << " s";
    ASSERT_NE(code, 137) << "killed after the time limit";
    EXPECT_EQ(code, want.code);
    // stderr: warnings, then at most one error line (a sanitizer report is many lines and fails here)
    std::vector<std::string> errors;
    std::istringstream lines(o.err);
    for (std::string line; std::getline(lines, line);)
      if (line.rfind("palpate: warning: ", 0) != 0) errors.push_back(line);
    if (want.code == 0) {
      EXPECT_TRUE(errors.empty()) << "a successful run printed more than warnings";
      continue;
    }
    ASSERT_EQ(errors.size(), 1u) << "one error line expected";
    EXPECT_EQ(errors[0].rfind("palpate: ", 0), 0u);
    EXPECT_NE(errors[0].find(want.text), std::string::npos) << "expected: " << want.text;
    // the message is printable: no raw control or non-ASCII bytes from the input echoed
    EXPECT_EQ(escaped(errors[0]), errors[0]) << "raw bytes in the message";
    // a refused input leaves nothing; a diverged run keeps its outputs by design (and says so)
    if (errors[0].find("the lattice diverged") == std::string::npos) {
      EXPECT_FALSE(fs::exists(out)) << out << " left behind";
    }
  }
}

}  // namespace
}  // namespace palpate
