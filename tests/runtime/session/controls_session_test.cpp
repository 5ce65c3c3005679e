// A person's change of the controls through a whole session (core/controls.h, Session): the model starts again from
// rest under the scene the controls make — a stiffer material pushes back harder at the same depth, a mode switch
// takes that mode's servo and stage, a reset puts the surface back at rest — and a run with changes replays from its
// haptic.csv tick for tick.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/scene.h"
#include "core/scene_controls.h"
#include "haptics/devices/replay_device.h"
#include "runtime/session/device_factory.h"
#include "runtime/session/haptic_log.h"
#include "runtime/session/model.h"
#include "runtime/session/session.h"
#include "support/fixtures.h"
#include "support/haptic_fixtures.h"

namespace palpate {
namespace {

// a 5 cm box of springs (every mode can be switched to) on a fixed floor, its top at z = 0.025 m
Scene box_scene(double duration_s) {
  char text[1024];
  std::snprintf(text, sizeof text, R"({
    "mesh": {"box_m": [0.05, 0.05, 0.05], "box_subdivisions": 16, "size_m": 0.05},
    "grid": {"levels": 4},
    "lattice": {"level": 4, "radius_cells": 2, "fix_floor": true, "integrator": "implicit_euler",
                "gravity_m_per_s2": [0, 0, 0]},
    "material": {"young_modulus_Pa": 3e4, "poisson_ratio": 0.25, "density_kg_per_m3": 1000, "stiffness_damping_s": 2e-3},
    "device": {"max_force_N": 3.3, "coupling_N_per_m": 300, "tool_radius_m": 0.003, "workspace_half_m": 0.2},
    "interaction": {"mode": "touch", "grab_radius_m": 0.004},
    "trajectory": [{"t_s": 0.0, "pos_m": [0, 0, 0.04]}],
    "duration_s": %g
  })", duration_s);
  return parse_scene(text, "controls_box.json").value();
}

constexpr double kTop = 0.025;

// One scripted person: where the tool is, the button and the controls at scene time t.
struct Person {
  struct Step {
    double t_s;
    double z_m;
    uint32_t buttons;
    Controls controls;
  };
  std::vector<Step> steps;  // each holds from its time on
  void apply(double t, test::FixedDevice* dev) const {
    for (const Step& s : steps)
      if (s.t_s <= t + 1e-9) {
        dev->pos_m = Vec3(0.0, 0.0, s.z_m);
        dev->buttons = s.buttons;
        dev->controls = s.controls;
      }
  }
};

Controls changed(const Scene& scene, int64_t seq, InteractionMode mode, double stiffness, int64_t resets = 0) {
  Controls c = scene_controls(scene);
  c.seq = seq;
  c.mode = mode;
  c.stiffness_scale = stiffness;
  c.resets = resets;
  return c;
}

// the mean force along z over [t0, t1) of the ticks kept
double mean_fz(const std::vector<HapticSample>& samples, double t0, double t1) {
  double sum = 0.0;
  int n = 0;
  for (const HapticSample& s : samples)
    if (s.t_s >= t0 && s.t_s < t1) {
      sum += s.force_N.z();
      ++n;
    }
  return n ? sum / n : 0.0;
}

struct PersonRun {
  std::vector<HapticSample> samples;
  std::string hash;
  std::vector<ControlChange> changes;
};

// the person's run in lockstep, its haptic.csv written to `csv` when given
PersonRun run_person(const Scene& scene, const Model& model, const Person& person, const std::string& csv = "") {
  test::FixedDevice dev;
  PersonRun r;
  HapticLog log;
  log.keep_samples(&r.samples);
  if (!csv.empty()) {
    EXPECT_TRUE(log.open(csv).ok());
  }
  SessionOutputs out;
  out.log = &log;
  Session session(scene, model, &dev, out);
  person.apply(0.0, &dev);
  session.run_lockstep(scene.duration_s, [](int64_t, double) {},
                       [&](int64_t i, double) { person.apply(session.rates().tick_time_s(i + 1), &dev); });
  if (!csv.empty()) {
    EXPECT_TRUE(log.close().ok());
  }
  r.hash = session.stage().state_hash();
  r.changes = session.control_changes();
  return r;
}

TEST(ControlsSession, AStifferMaterialPushesBackHarderAtTheSameDepthAfterTheModelStartsAgain) {
  const Scene scene = box_scene(2.4);
  const Model model = load_model(scene).value();
  const Controls own = scene_controls(scene);
  Person p;
  p.steps = {{0.0, kTop + 0.005, 0, own},
             {0.1, kTop - 0.004, 0, own},
             // four times as stiff: the tool goes out and in again (a reset model under a tool left inside is not
             // touched until the tool comes back out: the god-object's invariant)
             {1.2, kTop + 0.005, 0, changed(scene, 1, InteractionMode::kTouch, 4.0)},
             {1.3, kTop - 0.004, 0, changed(scene, 1, InteractionMode::kTouch, 4.0)}};
  test::FixedDevice dev;
  std::vector<HapticSample> samples;
  HapticLog log;
  log.keep_samples(&samples);
  SessionOutputs out;
  out.log = &log;
  Session session(scene, model, &dev, out);
  p.apply(0.0, &dev);
  int64_t felt_old = 0;
  session.run_lockstep(
      scene.duration_s, [](int64_t, double) {},
      [&](int64_t i, double) {
        const HapticSample& s = session.servo().last_sample();
        // under the new controls nothing is felt of a patch the old stage made
        if (s.controls.seq == 1 && !session.control_changes().empty() &&
            s.model_frame <= session.control_changes().front().frame && s.contact != ContactState::kFree)
          ++felt_old;
        p.apply(session.rates().tick_time_s(i + 1), &dev);
      });
  ASSERT_EQ(session.control_changes().size(), 1u);
  const ControlChange& c = session.control_changes().front();
  EXPECT_EQ(c.controls.seq, 1);
  EXPECT_EQ(c.controls.stiffness_scale, 4.0);
  // the frame that took tick 1200's sample (the first under seq 1): frame 73 (frame 72 runs just before tick 1200)
  EXPECT_EQ(c.frame, 73);
  EXPECT_DOUBLE_EQ(session.current_scene().lattice.material.young_modulus_Pa, 1.2e5);
  EXPECT_EQ(felt_old, 0);
  const double soft_N = mean_fz(samples, 0.9, 1.2), stiff_N = mean_fz(samples, 2.1, 2.4);
  std::printf("[ figures ] 4 mm into the box: %.3f N at E 30 kPa, %.3f N at E 120 kPa\n", soft_N, stiff_N);
  EXPECT_GT(soft_N, 0.2);
  EXPECT_GT(stiff_N, 1.3 * soft_N);
  // the figures ran on across the restart: every frame of the run is counted once
  EXPECT_EQ(session.stage().stats().frames, session.rates().frames(scene.duration_s));
}

TEST(ControlsSession, AResetPutsTheSurfaceBackAtRestAndAModeSwitchTakesThatModesServoAndStage) {
  const Scene scene = box_scene(2.0);
  const Model model = load_model(scene).value();
  const Controls own = scene_controls(scene);
  test::FixedDevice dev;
  Session session(scene, model, &dev);
  const std::string rest_hash = session.stage().state_hash();
  Person p;
  p.steps = {{0.0, kTop + 0.005, 0, own}, {0.1, kTop - 0.004, 0, own},
             // a reset with the tool lifted clear
             {0.6, kTop + 0.01, 0, changed(scene, 1, InteractionMode::kTouch, 1.0, 1)},
             // pull: the button on the surface grabs it, 5 mm above it the grab pulls the hand down
             {0.9, kTop + 0.01, 0, changed(scene, 2, InteractionMode::kPull, 1.0, 1)},
             {1.0, kTop, 1, changed(scene, 2, InteractionMode::kPull, 1.0, 1)},
             {1.2, kTop + 0.005, 1, changed(scene, 2, InteractionMode::kPull, 1.0, 1)},
             // cut
             {1.6, kTop + 0.01, 0, changed(scene, 3, InteractionMode::kCut, 1.0, 1)}};
  p.apply(0.0, &dev);
  bool dented = false, rest_after_reset = false, grabbed = false, pulled = false;
  session.run_lockstep(
      scene.duration_s,
      [&](int64_t, double t) {
        if (t > 0.5 && t < 0.6) dented = dented || session.stage().state_hash() != rest_hash;
        // the frame after the reset's: the surface is the rest's again, and so is the whole state
        if (session.control_changes().size() == 1 && !rest_after_reset)
          rest_after_reset = session.stage().vertices_m() == model.rest.vertices_m &&
                             session.stage().state_hash() == rest_hash;
      },
      [&](int64_t i, double t) {
        const HapticSample& s = session.servo().last_sample();
        if (t > 1.1 && t < 1.2) grabbed = grabbed || s.contact == ContactState::kGrab;
        if (t > 1.45 && t < 1.6) pulled = pulled || (s.contact == ContactState::kGrab && s.force_N.z() < -0.3);
        p.apply(session.rates().tick_time_s(i + 1), &dev);
      });
  EXPECT_TRUE(dented);
  EXPECT_TRUE(rest_after_reset);
  EXPECT_TRUE(grabbed);
  EXPECT_TRUE(pulled);
  ASSERT_EQ(session.control_changes().size(), 3u);
  EXPECT_EQ(session.control_changes()[0].controls.resets, 1);
  EXPECT_EQ(session.current_scene().mode, InteractionMode::kCut);
  EXPECT_NE(session.stage().cut_model(), nullptr) << "the cut mode's stage holds the cut mesh";
  EXPECT_EQ(session.servo().controls().mode, InteractionMode::kCut);
}

TEST(ControlsSession, ARunWithChangesReplaysFromItsLogTickForTick) {
  const Scene scene = box_scene(2.0);
  const Model model = load_model(scene).value();
  const Controls own = scene_controls(scene);
  Person p;
  p.steps = {{0.0, kTop + 0.005, 0, own}, {0.1, kTop - 0.003, 0, own},
             {0.5, kTop + 0.005, 0, changed(scene, 1, InteractionMode::kTouch, 2.5)},
             {0.6, kTop - 0.003, 0, changed(scene, 1, InteractionMode::kTouch, 2.5)},
             {1.0, kTop + 0.005, 0, changed(scene, 2, InteractionMode::kPull, 2.5)},
             {1.1, kTop, 1, changed(scene, 2, InteractionMode::kPull, 2.5)},
             {1.3, kTop + 0.004, 1, changed(scene, 2, InteractionMode::kPull, 2.5)},
             {1.6, kTop + 0.01, 0, changed(scene, 3, InteractionMode::kPull, 2.5, 1)}};
  const std::string dir = test::fresh_dir("controls_replay");
  std::filesystem::create_directories(dir);
  const std::string csv = dir + "/haptic.csv";
  const PersonRun live = run_person(scene, model, p, csv);
  ASSERT_EQ(live.changes.size(), 3u);

  auto rows = load_haptic_csv(csv);
  ASSERT_TRUE(rows.ok()) << rows.error().message;
  auto schedule = replay_schedule(rows.value(), {}, csv);
  ASSERT_TRUE(schedule.ok()) << schedule.error().message;
  ASSERT_TRUE(schedule.value().has_value());
  ReplayDevice replay(DeviceSpecs{}, std::move(rows).value(), std::move(schedule).value());
  std::vector<HapticSample> again;
  HapticLog log;
  log.keep_samples(&again);
  SessionOutputs out;
  out.log = &log;
  Session session(scene, model, &replay, out);
  session.run_lockstep(scene.duration_s, [](int64_t, double) {});
  ASSERT_EQ(again.size(), live.samples.size());
  double worst_N = 0.0;
  for (std::size_t i = 0; i < again.size(); ++i) {
    ASSERT_EQ(again[i].tick, live.samples[i].tick);
    ASSERT_EQ(again[i].controls.seq, live.samples[i].controls.seq) << "tick " << again[i].tick;
    worst_N = std::max(worst_N, (again[i].force_N - live.samples[i].force_N).norm());
  }
  EXPECT_EQ(worst_N, 0.0);
  ASSERT_EQ(session.control_changes().size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(session.control_changes()[k].frame, live.changes[k].frame);
  EXPECT_EQ(session.stage().state_hash(), live.hash);
}

// a haptic.csv line's cells
std::vector<std::string> cells_of(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
  return cells;
}

// What a run with changes is checked against, each refusal naming its culprit: a replay whose logged change the
// scene would refuse (another scene's narrower bounds) names the log's line; a control column that is not a value
// names its line and column; a stiffness range whose stiffest end the scene's integrator cannot keep stable is
// refused when the browser run opens, naming the key.
TEST(ControlsSession, ALoggedChangeTheSceneRefusesAMalformedColumnAndAnUnstableRangeAreNamed) {
  const Scene scene = box_scene(0.4);
  const Model model = load_model(scene).value();
  const Controls own = scene_controls(scene);
  Person p;
  p.steps = {{0.0, kTop + 0.005, 0, own}, {0.2, kTop + 0.005, 0, changed(scene, 1, InteractionMode::kTouch, 2.5)}};
  const std::string dir = test::fresh_dir("controls_refused");
  std::filesystem::create_directories(dir);
  const std::string csv = dir + "/haptic.csv";
  ASSERT_EQ(run_person(scene, model, p, csv).changes.size(), 1u);
  // the line of the first row under the change (the header is line 1)
  std::ifstream in(csv);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  ASSERT_GT(lines.size(), 2u);
  const std::vector<std::string> header = cells_of(lines[0]);
  const auto col = static_cast<std::size_t>(std::find(header.begin(), header.end(), "controls") - header.begin());
  ASSERT_LT(col, header.size());
  std::size_t first = 0;
  for (std::size_t i = 1; i < lines.size() && first == 0; ++i) {
    const std::vector<std::string> cells = cells_of(lines[i]);
    if (cells.size() > col && cells[col] == "1") first = i + 1;
  }
  ASSERT_GT(first, 0u);

  // the same log against a scene whose stiffness bounds end at 2
  Scene narrow = scene;
  narrow.device.browser_stiffness_hi = 2.0;
  auto refused = make_device(narrow, "replay:" + csv);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().message,
            "replay '" + csv + "': line " + std::to_string(first) + ": the controls changed there: stiffness 2.5 is "
            "outside the scene's range [0.25, 2] (device.browser_stiffness_range)");
  EXPECT_TRUE(make_device(scene, "replay:" + csv).ok()) << "its own scene takes it";

  // a mode that is not one, on the line after the change
  const std::size_t k = first;  // 0-based index of the line after `first`
  std::vector<std::string> cells = cells_of(lines[k]);
  const auto mode_col = static_cast<std::size_t>(std::find(header.begin(), header.end(), "mode") - header.begin());
  ASSERT_LT(mode_col, cells.size());
  cells[mode_col] = "x";
  std::string row;
  for (std::size_t c = 0; c < cells.size(); ++c) row += (c ? "," : "") + cells[c];
  lines[k] = row;
  const std::string bad = dir + "/bad_mode.csv";
  {
    std::ofstream out(bad);
    for (const std::string& l : lines) out << l << "\n";
  }
  auto malformed = make_device(scene, "replay:" + bad);
  ASSERT_FALSE(malformed.ok());
  EXPECT_EQ(malformed.error().message,
            "replay '" + bad + "': line " + std::to_string(k + 1) + ": column 'mode': 'x' is not a valid value");

  // an explicit scheme kept stable at the scene's own stiffness, not at a thousand times it
  Scene soft = parse_scene(R"({
    "mesh": {"box_m": [0.05, 0.05, 0.05], "box_subdivisions": 16, "size_m": 0.05},
    "grid": {"levels": 4},
    "lattice": {"level": 4, "radius_cells": 2, "fix_floor": true, "integrator": "symplectic_euler"},
    "material": {"young_modulus_Pa": 300, "poisson_ratio": 0.25, "density_kg_per_m3": 1000, "stiffness_damping_s": 2e-3},
    "device": {"browser_stiffness_range": [0.25, 1000]},
    "trajectory": [{"t_s": 0.0, "pos_m": [0, 0, 0.04]}]
  })", "soft_explicit.json").value();
  const auto soft_model = load_model(soft);
  ASSERT_TRUE(soft_model.ok()) << soft_model.error().message;
  const Status unstable = check_control_range(soft, soft_model.value());
  ASSERT_FALSE(unstable.ok());
  EXPECT_NE(unstable.error().message.find("device.browser_stiffness_range: its high end 1000 is not stable"),
            std::string::npos) << unstable.error().message;
  soft.device.browser_stiffness_hi = 1.5;
  EXPECT_TRUE(check_control_range(soft, soft_model.value()).ok());
}

}  // namespace
}  // namespace palpate
