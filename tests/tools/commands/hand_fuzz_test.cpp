// `palpate bench feel --hands`: seeded random hands on models the project did not make — a coarse ball felt through
// its 80 facets and the bunny — keep the god-object's invariant on every tick, go NaN nowhere and send no step the
// device's motion does not explain; the same seed makes the same hands.
#include <gtest/gtest.h>

#include <fstream>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <sstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/types.h"
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

// the force's angle from the radius at the device over the contact ticks of haptic.csv, sorted (a ball centred at the
// origin)
std::vector<double> angles_from_radius(const std::string& csv) {
  std::stringstream in(test::read_file(csv));
  std::vector<double> out;
  std::string line;
  std::getline(in, line);  // the header
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::string cell;
    for (std::stringstream row(line); std::getline(row, cell, ',');) v.push_back(std::atof(cell.c_str()));
    if (v.size() < 12 || v[11] != 1.0) continue;  // tick,t,tool xyz,proxy xyz,force xyz,contact
    const Vec3 tool(v[2], v[3], v[4]), force(v[8], v[9], v[10]);
    if (force.norm() < 0.05) continue;
    out.push_back(std::acos(std::clamp(force.normalized().dot(tool.normalized()), -1.0, 1.0)) * 180.0 / 3.14159265358979323846);
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(HandFuzz, AShadedCoarseBallIsFeltAsItsSphere) {
  // the 80-facet ball (25 mm, stiff), a point stroked round it 1 mm under its facets' centres: with force shading
  // the force follows the ball's radius at the device; without it, each facet's normal (up to ~10 degrees off)
  const std::string ball = tmp("shaded_ball.off");
  test::write_text(ball, coarse_ball_off());
  nlohmann::json s = {
      {"name", "shaded_ball"},
      {"mesh", {{"file", ball}, {"size_m", 0.05}}},
      {"grid", {{"levels", 5}}},
      {"lattice", {{"level", 3}, {"radius_cells", 2}, {"fix_floor", true}, {"integrator", "implicit_euler"}}},
      {"material", {{"young_modulus_Pa", 1e7}, {"poisson_ratio", 0.25}, {"density_kg_per_m3", 1000}}},
      {"device", {{"driver", "scripted"}, {"max_force_N", 3.3}, {"coupling_N_per_m", 300}}},
      {"interaction", {{"mode", "touch"}}},
      {"run_mode", "lockstep"}};
  nlohmann::json keys = nlohmann::json::array();
  keys.push_back({{"t_s", 0.0}, {"pos_m", {0.0, 0.0, 0.035}}});
  for (int k = 0; k <= 20; ++k) {
    // down onto the top, then round the ball in the x-z plane to 60 degrees, 21.5 mm from the centre
    const double th = 1.05 * k / 20.0, rad = 0.0215;
    keys.push_back({{"t_s", 0.4 + 0.1 * k}, {"pos_m", {rad * std::sin(th), 0.003, rad * std::cos(th)}}});
  }
  s["trajectory"] = keys;
  s["duration_s"] = 2.5;
  std::vector<double> p95;
  for (double deg : {0.0, 60.0}) {
    s["device"]["force_shading_deg"] = deg;
    const std::string dir = tmp("shaded_ball_" + std::to_string(static_cast<int>(deg)));
    test::write_text(dir + ".json", s.dump());
    const CliRun r = palpate("record " + dir + ".json --no-render -q -o " + dir);
    ASSERT_EQ(r.code, 0) << r.out;
    const std::vector<double> a = angles_from_radius(dir + "/haptic.csv");
    ASSERT_GT(a.size(), 1000u) << deg;
    p95.push_back(a[static_cast<std::size_t>(0.95 * static_cast<double>(a.size() - 1))]);
  }
  std::printf("force's angle from the ball's radius, p95: facets %.2f deg, shaded %.2f deg\n", p95[0], p95[1]);
  EXPECT_GT(p95[0], 5.0);
  EXPECT_LT(p95[1], 0.5 * p95[0]) << "facets " << p95[0] << " deg, shaded " << p95[1] << " deg";
  // and the random hands on it shaded (bench feel --force-shading) keep the surface and send no wild step
  const std::string json = tmp("shaded_hands.json");
  const CliRun h = palpate("bench feel --hands 4 --seed 20 --force-shading 60 " + ball + " --json " + json);
  ASSERT_EQ(h.code, 0) << h.out;
  for (const auto& hand : nlohmann::json::parse(test::read_file(json))["hands"]) {
    EXPECT_EQ(hand["proxy_inside_ticks"].get<int64_t>(), 0) << hand.dump();
    EXPECT_EQ(hand["wild_steps"].get<int64_t>(), 0) << hand.dump();
  }
}

// a lumpy closed blob (radius about 50) as a latitude-longitude grid of n_lat x n_lon, its radius noisy (seeded)
std::string noisy_blob_off(int n_lat, int n_lon, double noise, uint32_t seed) {
  std::mt19937 g(seed);
  std::normal_distribution<double> jitter(0.0, noise);
  std::vector<std::array<double, 3>> v{{0.0, 0.0, 40.0}};
  for (int i = 1; i < n_lat; ++i)
    for (int j = 0; j < n_lon; ++j) {
      const double th = 3.14159265358979323846 * i / n_lat, ph = 2 * 3.14159265358979323846 * j / n_lon;
      const double r = 50.0 * (1 + 0.12 * std::sin(3 * th) * std::cos(2 * ph) + 0.06 * std::sin(5 * ph)) + jitter(g);
      v.push_back({r * std::sin(th) * std::cos(ph), 0.8 * r * std::sin(th) * std::sin(ph), 0.8 * r * std::cos(th)});
    }
  v.push_back({0.0, 0.0, -40.0});
  const int bottom = static_cast<int>(v.size()) - 1;
  auto ring = [&](int i, int j) { return 1 + (i - 1) * n_lon + (j % n_lon); };
  std::vector<std::array<int, 3>> t;
  for (int j = 0; j < n_lon; ++j) {
    t.push_back({0, ring(1, j), ring(1, j + 1)});
    for (int i = 1; i < n_lat - 1; ++i) {
      t.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      t.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
    t.push_back({ring(n_lat - 1, j), bottom, ring(n_lat - 1, j + 1)});
  }
  std::string s = "OFF\n" + std::to_string(v.size()) + " " + std::to_string(t.size()) + " 0\n";
  char line[128];
  for (const auto& p : v) {
    std::snprintf(line, sizeof line, "%.9f %.9f %.9f\n", p[0], p[1], p[2]);
    s += line;
  }
  for (const auto& [a, b, c] : t) s += "3 " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "\n";
  return s;
}

TEST(HandFuzz, AShadedPressOnANoisyScanIsNotShadedWhereTheToolSitsInItsPits) {
  // a press into a noisy scan (2 x 10^4 facets, 0.4 units of noise): where the tool sits in a pit, touching two places
  // or held by faces that turn toward each other, each place's smooth normal is a different one, and shading toward
  // them flips the force; the contact is then felt as the facets hold it (shaded there, this hand had 294 ticks
  // beyond the device's motion in 4363, 6.7 %, and 84 lateral flips)
  const std::string blob = tmp("noisy_blob.off"), json = tmp("blob_hand.json");
  test::write_text(blob, noisy_blob_off(100, 100, 0.4, 1));
  const CliRun r = palpate("bench feel --hands 1 --seed 18 --force-shading 60 " + blob + " --json " + json);
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json hand = nlohmann::json::parse(test::read_file(json))["hands"][0];
  ASSERT_EQ(hand["kind"].get<std::string>(), "press") << hand.dump();
  const double contact = static_cast<double>(hand["contact_ticks"].get<int64_t>());
  const double steady = static_cast<double>(hand["steady_ticks"].get<int64_t>());
  ASSERT_GT(contact, 1000.0) << hand.dump();
  std::printf("shaded press on the noisy scan: %lld of %.0f contact ticks beyond the device's motion, %lld flips\n",
              static_cast<long long>(hand["excess_ticks"].get<int64_t>()), contact,
              static_cast<long long>(hand["lateral_flips"].get<int64_t>()));
  EXPECT_LT(static_cast<double>(hand["excess_ticks"].get<int64_t>()), 0.03 * contact) << hand.dump();
  EXPECT_LT(static_cast<double>(hand["lateral_flips"].get<int64_t>()), 0.01 * steady) << hand.dump();
  EXPECT_EQ(hand["tool_inside_ticks"].get<int64_t>(), 0) << hand.dump();
  EXPECT_EQ(hand["wild_steps"].get<int64_t>(), 0) << hand.dump();
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
  // one model that cannot be used among others (a flat one, before the bunny) is named and skipped; the bunny's hands
  // still run, and the exit status says a model was skipped
  const std::string flat = tmp("flat.obj");
  {
    std::ofstream f(flat);
    f << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
  }
  const CliRun mixed = palpate("bench feel --hands 1 --seed 3 " + flat + " " + bunny);
  EXPECT_EQ(mixed.code, 1) << mixed.out;
  EXPECT_NE(mixed.out.find("skipped: "), std::string::npos) << mixed.out;
  EXPECT_NE(mixed.out.find("flat on axis z"), std::string::npos) << mixed.out;
  EXPECT_NE(mixed.out.find("bunny.obj "), std::string::npos) << "the bunny's row is missing: " << mixed.out;
  EXPECT_NE(mixed.out.find("skipped 1 model(s) that could not be used: " + flat), std::string::npos) << mixed.out;
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
