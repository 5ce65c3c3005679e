// A recording in which the tool never touches the model says so, and how close the tool came.
#include "runtime/session/contact_report.h"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "support/cli_run.h"
#include "support/fixtures.h"
#include "support/json_file.h"
#include "support/record_options.h"
#include "runtime/record/recorder.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

using test::CliRun;
using test::palpate;
using test::read_json;
using test::write_text;

TEST(ContactReport, RecordingThatNeverTouchesSaysHowCloseTheToolCame) {
  // a 100 mm box (top at z = 50 mm); the tool holds 12 mm above its top
  const std::string dir = test::fresh_dir("scene_nocontact");
  fs::create_directories(dir);
  write_text(dir + "/s.json", R"({"mesh": {"box_m": [0.1, 0.1, 0.1]}, "lattice": {"level": 4},
    "trajectory": [{"t_s": 0, "pos_m": [0.01, 0.0, 0.062]}], "duration_s": 1.0})");
  const CliRun r = palpate("record " + dir + "/s.json --no-render -q -o " + dir + "/out");
  EXPECT_EQ(r.code, 0) << r.out;
  const std::string note = "no contact in 1.0 s: the trajectory stays 12 mm from the surface at its closest";
  EXPECT_NE(r.out.find("palpate: warning: " + note), std::string::npos) << r.out;
  const auto j = read_json(dir + "/out/summary.json");
  EXPECT_EQ(j["no_contact"], note);
  EXPECT_EQ(j["max_force_N"].get<double>(), 0.0);
}

TEST(ContactReport, PullThatNeverGrabsSaysWhereTheButtonWasPressed) {
  Scene s = parse_scene(R"({"mesh": {"box_m": [0.1, 0.1, 0.1]}, "lattice": {"level": 4},
    "interaction": {"mode": "pull", "grab_radius_m": 0.008},
    "trajectory": [{"t_s": 0, "pos_m": [0.0, 0.0, 0.07]}, {"t_s": 0.2, "pos_m": [0.0, 0.0, 0.07], "button": true}],
    "duration_s": 0.5})", "pull.json").value();
  RecordOptions opt = test::quiet_options("scene_nograb", false);
  auto r = record_scene(s, opt);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r.value().no_contact, "no contact in 0.5 s: the button is pressed 20 mm from the surface at its closest "
                                  "(grab_radius_m is 8.0 mm)");
}

}  // namespace
}  // namespace palpate
