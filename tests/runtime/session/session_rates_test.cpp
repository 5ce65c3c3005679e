// One set of rates for the whole session (Scene::rates): the lockstep clock's order, the device's own stiffness
// limit, and recordings at 500 Hz to 4 kHz that follow the same hand, filter the tool's velocity with the same
// cut-off and write their video at the frame rate, as at 1 kHz.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/scene.h"
#include "support/fixtures.h"
#include "support/haptic_fixtures.h"
#include "support/record_options.h"
#include "tools/bench/bench_loop.h"
#include "runtime/session/device_factory.h"
#include "runtime/session/lockstep.h"
#include "runtime/record/recorder.h"
#include "runtime/session/session.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

// One call of the lockstep driver: a frame ('f') or a tick ('t'), its index and time.
struct Call {
  char kind;
  int64_t index;
  int64_t t_us;
  bool operator==(const Call& o) const { return kind == o.kind && index == o.index && t_us == o.t_us; }
};

std::vector<Call> calls_of(const Rates& rates, double duration_s) {
  std::vector<Call> calls;
  run_lockstep(
      rates, duration_s, [&](int64_t f, double t) { calls.push_back({'f', f, std::lround(t * 1e6)}); },
      [&](int64_t i, double t) { calls.push_back({'t', i, std::lround(t * 1e6)}); });
  return calls;
}

std::size_t position(const std::vector<Call>& calls, char kind, int64_t index) {
  for (std::size_t k = 0; k < calls.size(); ++k)
    if (calls[k].kind == kind && calls[k].index == index) return k;
  return calls.size();
}

TEST(Lockstep, FramesRunAtTheirBoundaryBeforeTheTickAtThatTime) {
  // 50 ticks and 3 frames (0, 16.7, 33.3 ms): frame 1 comes after tick 16 and before tick 17
  const auto calls = calls_of(Rates{1000.0, 60.0}, 0.05);
  ASSERT_EQ(calls.size(), 53u);
  EXPECT_EQ(calls[0], (Call{'f', 0, 0}));
  EXPECT_EQ(calls[1], (Call{'t', 0, 0}));
  const std::size_t f1 = position(calls, 'f', 1);
  ASSERT_LT(f1 + 1, calls.size());
  EXPECT_EQ(calls[f1], (Call{'f', 1, 16667}));
  EXPECT_EQ(calls[f1 - 1], (Call{'t', 16, 16000}));
  EXPECT_EQ(calls[f1 + 1], (Call{'t', 17, 17000}));
  // at 2 kHz the same frames fall between other ticks
  const auto fast = calls_of(Rates{2000.0, 60.0}, 0.05);
  ASSERT_EQ(fast.size(), 103u);
  EXPECT_EQ(fast[position(fast, 'f', 1) - 1], (Call{'t', 33, 16500}));
}

TEST(Rates, TheDevicesStiffnessLimitCapsTheCouplingAtAnyRate) {
  Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  DeviceSpecs soft;
  soft.max_stiffness_N_per_m = 200.0;  // below the scene's coupling of 300 N/m
  scene.rates.servo_hz = 2000.0;
  EXPECT_DOUBLE_EQ(servo_params_for(scene, soft).coupling_N_per_m, 200.0);
  DeviceSpecs stiff;
  stiff.max_stiffness_N_per_m = 5000.0;
  scene.rates.servo_hz = 500.0;
  EXPECT_DOUBLE_EQ(servo_params_for(scene, stiff).coupling_N_per_m,
                   std::min(scene.device.coupling_N_per_m, scene.device.max_stiffness_N_per_m));
}

// A handle swinging along x at frequency_hz with amplitude_m: the servo's velocity estimate sees a known sinusoid.
class SwingDevice final : public Device {
 public:
  SwingDevice(double frequency_hz, double amplitude_m) : omega_(2.0 * std::numbers::pi * frequency_hz), a_(amplitude_m) {}
  const DeviceSpecs& specs() const noexcept override { return specs_; }
  bool read(double t_s, DevicePose* out) noexcept override {
    out->pos_m = Vec3(a_ * std::sin(omega_ * t_s), 0.0, 0.0);
    return true;
  }
  void write_force(const Vec3&) noexcept override {}

 private:
  DeviceSpecs specs_;
  double omega_, a_;
};

// Gain of the servo's velocity estimate at frequency_hz with the servo at rate_hz: the amplitude of the estimate
// (fitted over 20 whole periods after 0.2 s of settling) over the true velocity's, a * omega.
double velocity_gain(double rate_hz, double frequency_hz) {
  constexpr double kAmplitude_m = 1e-3;
  Rates rates;
  rates.servo_hz = rate_hz;
  // nothing published: an empty patch, the tool is always free
  test::ServoRig<SwingDevice> rig(ServoParams{}, 16, rates, frequency_hz, kAmplitude_m);
  const double omega = 2.0 * std::numbers::pi * frequency_hz;
  const double t_fit_s = 0.2, span_s = 20.0 / frequency_hz;
  double s_sin = 0.0, s_cos = 0.0;
  int64_t n = 0;
  for (int64_t i = 0; i < rates.ticks(t_fit_s + span_s); ++i) {
    const double t = static_cast<double>(i) / rates.servo_hz;
    rig.tick(i, t);
    if (t < t_fit_s) continue;
    // the estimate of the velocity half a tick back (a first difference), projected on sin and cos
    const double v = rig.servo->tool_velocity_m_per_s().x();
    s_sin += v * std::sin(omega * t);
    s_cos += v * std::cos(omega * t);
    ++n;
  }
  return 2.0 * std::hypot(s_sin, s_cos) / static_cast<double>(n) / (kAmplitude_m * omega);
}

TEST(Rates, TheVelocityFiltersCutOffIsTheSameAtEveryRate) {
  // the weight a tick at 1 kHz is the 0.3 the filter had as a per-tick constant: 1 kHz runs are unchanged
  EXPECT_EQ(low_pass_weight(kVelocityCutoff_hz, Rates{}.servo_period_s()), 0.3);
  // a one-pole low-pass passes 1/sqrt(2) at its cut-off, and half the cut-off's frequency ~ 0.89, at every rate
  // (a fixed 0.3 a tick gives 0.45 at 500 Hz and 0.97 at 4 kHz at 56.8 Hz)
  for (double rate : {500.0, 1000.0, 2000.0, 4000.0}) {
    const double at_cutoff = velocity_gain(rate, kVelocityCutoff_hz);
    EXPECT_NEAR(at_cutoff, std::sqrt(0.5), 0.02) << rate << " Hz";
    EXPECT_NEAR(velocity_gain(rate, 0.5 * kVelocityCutoff_hz), 1.0 / std::sqrt(1.25), 0.02) << rate << " Hz";
    RecordProperty("velocity_gain_at_cutoff_" + std::to_string(static_cast<int>(rate)), std::to_string(at_cutoff));
  }
}

TEST(Rates, TheVideoIsWrittenAtTheFrameRateWhateverTheServoRate) {
  const Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  for (double rate : {500.0, 1000.0, 2000.0, 4000.0}) {
    RecordOptions opt = test::quiet_options("rate_video_" + std::to_string(static_cast<int>(rate)));
    opt.duration_s = 0.1;
    opt.servo_rate_hz = rate;
    opt.video_path = (fs::path(opt.out_dir) / "v.mp4").string();
    auto r = record_scene(scene, opt);
    ASSERT_TRUE(r) << r.error().message;
    const auto j = nlohmann::json::parse(r.value().summary_json);
    ASSERT_TRUE(j["video"]["enabled"].get<bool>()) << j["video"].dump();
    EXPECT_EQ(j["video"]["frame_rate_hz"].get<int>(), 60) << rate << " Hz";
    EXPECT_EQ(j["video"]["frames"].get<int>(), 6) << rate << " Hz";
    EXPECT_EQ(j["servo_ticks"].get<int64_t>(), std::llround(0.1 * rate));
  }
}

struct Track {
  nlohmann::json summary;
  std::vector<double> t_s, tool_z_m, force_z_N;
};

Track record_at(double rate_hz) {
  const Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  RecordOptions opt = test::quiet_options("rate_" + std::to_string(static_cast<int>(rate_hz)), false);
  opt.servo_rate_hz = rate_hz;
  Track tr;
  auto r = record_scene(scene, opt);
  EXPECT_TRUE(r) << r.error().message;
  if (!r) return tr;
  tr.summary = nlohmann::json::parse(r.value().summary_json);
  std::ifstream csv(fs::path(opt.out_dir) / "haptic.csv");
  std::string line;
  std::getline(csv, line);
  while (std::getline(csv, line)) {
    std::stringstream ss(line);
    std::string cell;
    std::vector<double> v;
    while (std::getline(ss, cell, ',')) v.push_back(std::stod(cell));
    tr.t_s.push_back(v[1]);
    tr.tool_z_m.push_back(v[4]);
    tr.force_z_N.push_back(v[10]);
  }
  return tr;
}

TEST(Rates, RecordingsAt500HzTo4kHzTickAtTheirRateAndFollowTheSameHandAndForce) {
  const Track ref = record_at(1000.0);
  ASSERT_EQ(ref.t_s.size(), 1500u);
  for (double rate : {500.0, 2000.0, 4000.0}) {
    const Track tr = record_at(rate);
    const auto n = static_cast<std::size_t>(1.5 * rate);
    ASSERT_EQ(tr.t_s.size(), n) << rate;
    EXPECT_EQ(tr.summary["servo_ticks"].get<int64_t>(), static_cast<int64_t>(n));
    EXPECT_EQ(tr.summary["servo"]["rate_hz"].get<double>(), rate);
    // ticks 1 / rate apart
    double worst_dt = 0.0;
    for (std::size_t i = 1; i < n; ++i) worst_dt = std::max(worst_dt, std::abs(tr.t_s[i] - tr.t_s[i - 1] - 1.0 / rate));
    EXPECT_LT(worst_dt, 1e-9) << rate;
    // the scripted hand, the coupling's velocity term and the passivity guard all at the right period: the
    // handle's path and the force agree with the 1 kHz run at the same scene times
    double worst_z = 0.0, worst_f = 0.0;
    for (std::size_t i = 0; i < n; i += static_cast<std::size_t>(rate / 20)) {
      const auto k = static_cast<std::size_t>(std::lround(tr.t_s[i] * 1000.0));
      worst_z = std::max(worst_z, std::abs(tr.tool_z_m[i] - ref.tool_z_m[k]));
      worst_f = std::max(worst_f, std::abs(tr.force_z_N[i] - ref.force_z_N[k]));
    }
    // (measured: 36 um and 8 mN at 500 Hz; a servo left at a 1 ms period gives 109 mN there)
    EXPECT_LT(worst_z, 1e-4) << rate << " Hz: handle path differs by " << worst_z << " m";
    EXPECT_LT(worst_f, 0.03) << rate << " Hz: force differs by " << worst_f << " N";
  }
}

// A Session at rate_hz in lockstep, logging every tick: the cube pressed by the scripted hand with a purely viscous
// coupling (stiffness 0, no ramp), so every force sent in contact is -b_c times the servo's velocity estimate.
struct SessionRun {
  double period_s = 0;           // the servo's period as the session set it up
  std::vector<double> t_s, z_m, fz_N;
  std::vector<int> contact;
};

SessionRun run_session(double rate_hz) {
  Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  scene.duration_s = 0.3;  // the press, up to where the hand stops
  scene.device.coupling_N_per_m = 0.0;
  scene.device.ramp_s = 0.0;
  const Model model = load_model(scene).value();
  scene.rates.servo_hz = rate_hz;
  auto device = make_device(scene, "");
  EXPECT_TRUE(device) << device.error().message;
  const fs::path dir = test::fresh_dir("session_rate_" + std::to_string(static_cast<int>(rate_hz)));
  fs::create_directories(dir);
  const std::string csv = (dir / "haptic.csv").string();
  HapticLog log;
  const Status opened = log.open(csv);
  EXPECT_TRUE(opened) << opened.error().message;
  SessionOutputs out;
  out.log = &log;
  SessionRun r;
  {
    Session session(scene, model, device.value().get(), out);
    r.period_s = session.rates().servo_period_s();
    session.run_lockstep(scene.duration_s, [](int64_t, double) {});
  }
  const Status closed = log.close();
  EXPECT_TRUE(closed) << closed.error().message;
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string cell;
    std::vector<double> v;
    while (std::getline(ss, cell, ',')) v.push_back(std::stod(cell));
    r.t_s.push_back(v[1]);
    r.z_m.push_back(v[4]);
    r.fz_N.push_back(v[10]);
    r.contact.push_back(static_cast<int>(v[11]));
  }
  return r;
}

TEST(Rates, SessionAt500HzAnd2kHzTicksAtItsPeriodAndEstimatesVelocityWithIt) {
  const double b = load_scene(test::source_path("scenes/cube_press.json")).value().device.coupling_damping_Ns_per_m;
  for (double rate : {500.0, 2000.0}) {
    const SessionRun r = run_session(rate);
    EXPECT_DOUBLE_EQ(r.period_s, 1.0 / rate);
    const auto n = static_cast<std::size_t>(std::lround(0.3 * rate));
    ASSERT_EQ(r.t_s.size(), n) << rate;
    // the log's time column: one row every 1 / rate
    double worst_dt = 0.0;
    for (std::size_t i = 1; i < n; ++i) worst_dt = std::max(worst_dt, std::abs(r.t_s[i] - r.t_s[i - 1] - 1.0 / rate));
    EXPECT_LT(worst_dt, 1e-9) << rate;
    // the handle's velocity from its logged path (central difference over +-5 ms) against the servo's estimate
    // -F/b_c, in contact while the hand moves steadily down (0.2 .. 0.28 s); an estimate taken over a period
    // other than 1 / rate is off by the ratio of the two (x2 or x0.5 here)
    const auto h = static_cast<std::size_t>(std::lround(0.005 * rate));
    int compared = 0;
    double worst_rel = 0.0;
    for (std::size_t i = h; i + h < n; ++i) {
      if (r.t_s[i] < 0.2 || r.t_s[i] > 0.28 || r.contact[i] == 0) continue;
      const double v_path = (r.z_m[i + h] - r.z_m[i - h]) / (r.t_s[i + h] - r.t_s[i - h]);
      const double v_servo = -r.fz_N[i] / b;
      ASSERT_LT(v_path, -0.02) << rate << " Hz at " << r.t_s[i] << " s: the hand is not moving down";
      worst_rel = std::max(worst_rel, std::abs(v_servo - v_path) / std::abs(v_path));
      ++compared;
    }
    EXPECT_GT(compared, static_cast<int>(0.05 * rate)) << rate << " Hz: too few ticks in contact";
    EXPECT_LT(worst_rel, 0.05) << rate << " Hz: velocity estimate off by " << worst_rel * 100 << " %";
    RecordProperty("velocity_error_pct_" + std::to_string(static_cast<int>(rate)), std::to_string(worst_rel * 100));
  }
}

TEST(Rates, SweepNamesTheHighestRateBelowWhichNothingOverran) {
  const std::vector<double> rates{1000, 2000, 5000, 10000};
  EXPECT_DOUBLE_EQ(highest_clean_rate(rates, {0, 0, 0, 0}), 10000.0);
  EXPECT_DOUBLE_EQ(highest_clean_rate(rates, {0, 0, 3, 0}), 2000.0);  // a clean 10 kHz above an overrun is luck
  EXPECT_DOUBLE_EQ(highest_clean_rate(rates, {0, 1, 0, 0}), 1000.0);
  EXPECT_DOUBLE_EQ(highest_clean_rate(rates, {2, 0, 0, 0}), 0.0);
}

TEST(Rates, SweepsSecondVerdictCountsOnlyTheLoopsOwnOverruns) {
  // overruns per rate and, of them, the periods missed in stalls the machine took
  const std::vector<double> rates{1000, 2000, 5000, 10000};
  EXPECT_DOUBLE_EQ(highest_rate_clean_but_stalls(rates, {9, 12, 28, 392}, {9, 12, 18, 378}), 2000.0);
  EXPECT_DOUBLE_EQ(highest_rate_clean_but_stalls(rates, {9, 12, 28, 392}, {9, 12, 28, 392}), 10000.0);
  EXPECT_DOUBLE_EQ(highest_rate_clean_but_stalls(rates, {3, 0, 5, 0}, {2, 0, 5, 0}), 0.0);  // 1 kHz missed one itself
  EXPECT_DOUBLE_EQ(highest_rate_clean_but_stalls(rates, {0, 0, 4, 0}, {0, 0, 0, 0}), 2000.0);
  // the first verdict on the same runs is stricter
  EXPECT_DOUBLE_EQ(highest_clean_rate(rates, {9, 12, 28, 392}), 0.0);
}

TEST(Rates, SceneServoRateIsUsedAndTheCommandLineOverridesIt) {
  Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  EXPECT_DOUBLE_EQ(scene.rates.servo_hz, 1000.0);  // no "servo" object: the default
  scene.rates.servo_hz = 2000.0;
  scene.duration_s = 0.1;
  RecordOptions opt;
  opt.quiet = true;
  opt.render = false;
  opt.out_dir = test::fresh_dir("rate_scene");
  auto a = record_scene(scene, opt);
  ASSERT_TRUE(a) << a.error().message;
  auto ja = nlohmann::json::parse(a.value().summary_json);
  EXPECT_EQ(ja["servo"]["rate_hz"].get<double>(), 2000.0);
  EXPECT_EQ(ja["servo"]["rate_from"], "scene");
  EXPECT_EQ(ja["servo_ticks"].get<int64_t>(), 200);
  opt.out_dir = test::fresh_dir("rate_flag");
  opt.servo_rate_hz = 500.0;
  auto b = record_scene(scene, opt);
  ASSERT_TRUE(b) << b.error().message;
  auto jb = nlohmann::json::parse(b.value().summary_json);
  EXPECT_EQ(jb["servo"]["rate_hz"].get<double>(), 500.0);
  EXPECT_EQ(jb["servo"]["rate_from"], "--servo-rate");
  EXPECT_EQ(jb["servo_ticks"].get<int64_t>(), 50);
}

TEST(Rates, SummarySaysWhichLimitSetTheCoupling) {
  // cube_press asks for 300 N/m under a 700 N/m limit; the scripted hand's 6 Ns/m allows 2b/T/2 = 6000 N/m at 1 kHz
  Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  scene.duration_s = 0.05;
  scene.device.coupling_N_per_m = 20000.0;
  scene.device.max_stiffness_N_per_m = 1e5;
  RecordOptions opt;
  opt.quiet = true;
  opt.render = false;
  for (double rate : {1000.0, 10000.0}) {
    opt.out_dir = test::fresh_dir("rate_cap_" + std::to_string(static_cast<int>(rate)));
    opt.servo_rate_hz = rate;
    auto r = record_scene(scene, opt);
    ASSERT_TRUE(r) << r.error().message;
    const auto c = nlohmann::json::parse(r.value().summary_json)["coupling"];
    const double passive = CouplingLimit::kPassivityShare * 2.0 * scene.hand.damping_Ns_per_m * rate;
    EXPECT_DOUBLE_EQ(c["limits_N_per_m"]["passivity"].get<double>(), passive) << rate;
    EXPECT_DOUBLE_EQ(c["device_damping_Ns_per_m"].get<double>(), scene.hand.damping_Ns_per_m);
    if (rate == 1000.0) {
      EXPECT_DOUBLE_EQ(c["stiffness_N_per_m"].get<double>(), passive);
      EXPECT_EQ(c["bound"], "passivity 2b/T");
      EXPECT_TRUE(c["capped"].get<bool>());
    } else {
      EXPECT_DOUBLE_EQ(c["stiffness_N_per_m"].get<double>(), 20000.0);
      EXPECT_EQ(c["bound"], "scene coupling_N_per_m");
      EXPECT_FALSE(c["capped"].get<bool>());
    }
  }
}

}  // namespace
}  // namespace palpate
