// `palpate bench feel --hands`: seeded random hands on models the project did not make — a coarse ball felt through
// its 80 facets and the bunny — keep the god-object's invariant on every tick, go NaN nowhere and send no step the
// device's motion does not explain; the same seed makes the same hands.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_run.h"
#include "support/fixtures.h"
#include "support/json_file.h"
#include "support/read_file.h"
#include "support/temp_root.h"

namespace palpate {
namespace {

using test::CliRun;
using test::palpate;

std::string tmp(const std::string& name) { return test::temp_path("hand_fuzz_", name); }

// an icosahedron split once onto a 50 mm sphere: 80 flat facets 31 mm across, 20 degrees between neighbours
std::string coarse_ball_off() {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<std::array<double, 3>> v{{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                       {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> f{{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                    {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                    {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  std::map<std::pair<int, int>, int> mid;
  auto m = [&](int a, int b) {
    const auto key = std::minmax(a, b);
    auto it = mid.find(key);
    if (it != mid.end()) return it->second;
    v.push_back({(v[a][0] + v[b][0]) / 2, (v[a][1] + v[b][1]) / 2, (v[a][2] + v[b][2]) / 2});
    return mid[key] = static_cast<int>(v.size()) - 1;
  };
  std::vector<std::array<int, 3>> split;
  for (const auto& [a, b, c] : f) {
    const int ab = m(a, b), bc = m(b, c), ca = m(c, a);
    split.insert(split.end(), {{a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca}});
  }
  std::string s = "OFF\n" + std::to_string(v.size()) + " " + std::to_string(split.size()) + " 0\n";
  char line[128];
  for (const auto& p : v) {
    const double n = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    std::snprintf(line, sizeof line, "%.9f %.9f %.9f\n", 50 * p[0] / n, 50 * p[1] / n, 50 * p[2] / n);
    s += line;
  }
  for (const auto& [a, b, c] : split) s += "3 " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "\n";
  return s;
}

TEST(HandFuzz, RandomHandsOnModelsTheProjectDidNotMakeKeepTheSurface) {
  const std::string ball = tmp("coarse_ball.off"), json = tmp("hands.json"), keep = tmp("kept");
  test::write_text(ball, coarse_ball_off());
  const std::string models = ball + " " + test::source_path("scenes/bunny.obj");
  const CliRun r = palpate("bench feel --hands 5 --seed 10 " + models + " --json " + json + " --keep " + keep);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("coarse_ball.off"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(test::read_file(json));
  ASSERT_EQ(j["hands"].size(), 10u);
  std::set<std::string> kinds;
  int touched = 0;
  for (const auto& h : j["hands"]) {
    const std::string what = h["model"].get<std::string>() + " hand " + std::to_string(h["seed"].get<int>());
    ASSERT_FALSE(h.contains("error")) << what << ": " << h.dump();
    kinds.insert(h["kind"].get<std::string>());
    touched += h["contact_ticks"].get<int64_t>() > 100;
    EXPECT_EQ(h["tool_inside_ticks"].get<int64_t>(), 0) << what;
    EXPECT_EQ(h["proxy_inside_ticks"].get<int64_t>(), 0) << what;
    EXPECT_EQ(h["nan_events"].get<int64_t>(), 0) << what;
    EXPECT_EQ(h["wild_steps"].get<int64_t>(), 0) << what << ": largest " << h["max_wild_excess_N"];
  }
  EXPECT_GE(kinds.size(), 2u);
  EXPECT_GE(touched, 8);
}

TEST(HandFuzz, TheSameSeedMakesTheSameHandsAndAMissingModelIsNamed) {
  const std::string a = tmp("a.json"), b = tmp("b.json");
  const std::string bunny = test::source_path("scenes/bunny.obj");
  ASSERT_EQ(palpate("bench feel --hands 2 --seed 3 " + bunny + " --json " + a).code, 0);
  ASSERT_EQ(palpate("bench feel --hands 2 --seed 3 " + bunny + " --json " + b).code, 0);
  EXPECT_EQ(test::read_file(a), test::read_file(b));
  const CliRun missing = palpate("bench feel --hands 2 " + tmp("no_such_model.obj"));
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.out.find("no_such_model.obj"), std::string::npos) << missing.out;
  // the scripted runs' options are refused with hands, and the hands' options without them
  const CliRun plot = palpate("bench feel --hands 2 " + bunny + " --plot " + tmp("p.png"));
  EXPECT_EQ(plot.code, 2);
  EXPECT_NE(plot.out.find("--plot does not apply with --hands"), std::string::npos) << plot.out;
  const CliRun seed = palpate("bench feel scenes/cube_press.json --seed 4");
  EXPECT_EQ(seed.code, 2);
  EXPECT_NE(seed.out.find("--seed needs --hands N"), std::string::npos) << seed.out;
}

}  // namespace
}  // namespace palpate
