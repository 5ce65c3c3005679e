// The docs cannot hide a command: every fence in README.md and docs/*.md says what it holds (sh or bash for commands,
// which scripts/readme_figures.sh --commands runs as pasted; text or another language for output and diagrams), and
// every command of an sh fence that runs the palpate program names it as built (build/bin/palpate), not a bare
// `palpate` a fresh clone has nowhere on its PATH.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "support/fixtures.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

std::vector<std::string> pages() {
  std::vector<std::string> out = {test::source_path("README.md")};
  for (const auto& e : fs::directory_iterator(test::source_path("docs")))
    if (e.path().extension() == ".md") out.push_back(e.path().string());
  return out;
}

TEST(DocFences, EveryFenceSaysWhatItHoldsAndEveryCommandRunsAsPasted) {
  const std::regex fence(R"(^\s*```(\S*)\s*$)");
  const std::regex bare(R"((^|[;&|(]\s*)palpate\s)");
  int fences = 0, commands = 0;
  for (const std::string& page : pages()) {
    std::ifstream in(page);
    std::string line;
    bool inside = false, shell = false;
    for (int n = 1; std::getline(in, line); ++n) {
      std::smatch m;
      if (std::regex_match(line, m, fence)) {
        if (!inside) {
          ++fences;
          EXPECT_FALSE(m[1].str().empty()) << page << ":" << n << ": an untagged fence (sh for commands, text for output)";
          shell = m[1] == "sh" || m[1] == "bash";
        }
        inside = !inside;
        continue;
      }
      if (!inside || !shell || line.empty() || line.find_first_not_of(' ') == std::string::npos) continue;
      if (line.find_first_not_of(' ') == line.find('#')) continue;  // a comment line
      ++commands;
      EXPECT_FALSE(std::regex_search(line, bare)) << page << ":" << n << ": runs a bare `palpate` (build/bin/palpate): " << line;
    }
    EXPECT_FALSE(inside) << page << ": a fence left open";
  }
  EXPECT_GT(fences, 50);
  EXPECT_GT(commands, 100);
}

}  // namespace
}  // namespace palpate
