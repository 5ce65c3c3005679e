// Analytic references per integrator: damped oscillator, hanging chain sag, chain wave speed, undamped energy.
#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

#include "sim/sim_test_util.h"

namespace palpate {
namespace {

using test::make_chain;
using test::opts;

// m x'' = -k x - c x' along the spring axis: m = 10 g, k = 4 N/m (w0 = 20 rad/s), zeta = 0.025.
constexpr double kMass = 0.01, kK = 4.0, kC = 0.01, kA = 0.002, kLen = 0.01;

struct OscCase {
  IntegratorKind kind;
  double rate_hz;
  double max_period_err;   // |T_num / T - 1|
  double amp_lo, amp_hi;   // bounds on A_num(1 s) / A(1 s), amplitude from the oscillator's energy
};

class DampedOscillator : public testing::TestWithParam<OscCase> {};

TEST_P(DampedOscillator, PeriodAndAmplitudeMatchClosedForm) {
  const OscCase& p = GetParam();
  Lattice lat = make_chain(1, kLen, kK, kMass, kC);
  lat.x_m[1].x() += kA;
  const double w0 = std::sqrt(kK / kMass), zeta = kC / (2.0 * std::sqrt(kK * kMass));
  const double wd = w0 * std::sqrt(1.0 - zeta * zeta);
  const double dt = 1.0 / p.rate_hz;
  IntegratorWorkspace ws;
  std::vector<double> crossings;
  double prev = kA;
  const int steps = static_cast<int>(std::lround(p.rate_hz));
  for (int s = 1; s <= steps; ++s) {
    step_lattice(&lat, opts(p.kind), dt, {}, &ws);
    const double x = lat.x_m[1].x() - kLen;
    if ((prev > 0.0) != (x > 0.0)) crossings.push_back((s - 1 + prev / (prev - x)) * dt);
    prev = x;
  }
  ASSERT_TRUE(test::all_finite(lat));
  ASSERT_GE(crossings.size(), 4u);
  const double half_period = (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  const double period_err = std::abs(2.0 * half_period / (2.0 * M_PI / wd) - 1.0);
  // amplitude from energy: A = sqrt((m v^2 + k x^2) / k), analytic envelope A0 exp(-zeta w0 t) (to first order)
  const double x = lat.x_m[1].x() - kLen, v = lat.v_m_per_s[1].x();
  const double amp = std::sqrt((kMass * v * v + kK * x * x) / kK);
  const double t = steps * dt;
  const double xa = kA * std::exp(-zeta * w0 * t) * (std::cos(wd * t) + zeta * w0 / wd * std::sin(wd * t));
  const double va = -kA * std::exp(-zeta * w0 * t) * (w0 * w0 / wd) * std::sin(wd * t);
  const double amp_ref = std::sqrt((kMass * va * va + kK * xa * xa) / kK);
  const double ratio = amp / amp_ref;
  EXPECT_LT(period_err, p.max_period_err) << integrator_name(p.kind) << " at " << p.rate_hz << " Hz";
  EXPECT_GT(ratio, p.amp_lo) << integrator_name(p.kind) << " at " << p.rate_hz << " Hz";
  EXPECT_LT(ratio, p.amp_hi) << integrator_name(p.kind) << " at " << p.rate_hz << " Hz";
  if (p.kind == IntegratorKind::kExplicitEuler) {
    // forward Euler on a linear oscillator is the recurrence x' = x + h v, v' = v + h (-k x - c v) / m, whose
    // amplitude after `steps` steps is known exactly; the scheme must match it to round-off while the motion
    // stays linear (a start 20x smaller keeps the grown swing inside the spring's 1 cm length)
    Lattice small = make_chain(1, kLen, kK, kMass, kC);
    const double a0 = kA / 20.0;
    small.x_m[1].x() += a0;
    IntegratorWorkspace ws2;
    for (int s = 0; s < steps; ++s) step_lattice(&small, opts(p.kind), dt, {}, &ws2);
    const double xs = small.x_m[1].x() - kLen, vs = small.v_m_per_s[1].x();
    double xe = a0, ve = 0.0;
    for (int s = 0; s < steps; ++s) {
      const double a = (-kK * xe - kC * ve) / kMass;
      xe += dt * ve;
      ve += dt * a;
    }
    EXPECT_LT(std::abs(xe), kLen);
    const double got = std::sqrt((kMass * vs * vs + kK * xs * xs) / kK);
    const double predicted = std::sqrt((kMass * ve * ve + kK * xe * xe) / kK);
    EXPECT_NEAR(got / predicted, 1.0, 1e-9) << "predicted " << predicted / a0 << "x at " << p.rate_hz << " Hz";
  }
}

// Bounds follow each scheme's amplification factor at h w0 = 1/3 (60 Hz) and 1/50 (1 kHz):
// implicit Euler loses amplitude as (1 + h^2 w^2)^(-t/2h) (0.04 at 60 Hz, 0.82 at 1 kHz) and lags in phase by
// atan(h w) / (h w); explicit Euler gains (1 + h^2 w^2 - h c/m)^(t/2h); RK4 is accurate to (h w)^4.
INSTANTIATE_TEST_SUITE_P(
    Schemes, DampedOscillator,
    testing::Values(OscCase{IntegratorKind::kRk4, 60, 2e-3, 0.99, 1.01},
                    OscCase{IntegratorKind::kRk4, 1000, 1e-4, 0.9999, 1.0001},
                    OscCase{IntegratorKind::kSymplecticEuler, 60, 1e-2, 0.8, 1.2},
                    OscCase{IntegratorKind::kSymplecticEuler, 1000, 1e-3, 0.99, 1.01},
                    OscCase{IntegratorKind::kImplicitEuler, 60, 5e-2, 0.02, 0.1},
                    OscCase{IntegratorKind::kImplicitEuler, 1000, 1e-3, 0.78, 0.86},
                    OscCase{IntegratorKind::kLocalGlobal, 60, 5e-2, 0.02, 0.1},
                    OscCase{IntegratorKind::kLocalGlobal, 1000, 1e-3, 0.78, 0.86},
                    OscCase{IntegratorKind::kExplicitEuler, 60, 5e-2, 10.0, 30.0},
                    OscCase{IntegratorKind::kExplicitEuler, 1000, 1e-3, 1.1, 1.3}),
    [](const testing::TestParamInfo<OscCase>& i) {
      return std::string(integrator_name(i.param.kind)) + "_" + std::to_string(static_cast<int>(i.param.rate_hz)) + "hz";
    });

// Spring j from the top carries (N - j + 1) m g, so the chain stretches by m g N (N + 1) / (2 k) in all.
TEST(HangingChain, StaticSagMatchesClosedForm) {
  const int n = 10;
  const double k = 100.0, m = 0.01, g = 9.81, a = 0.01;
  for (IntegratorKind kind : {IntegratorKind::kImplicitEuler, IntegratorKind::kLocalGlobal, IntegratorKind::kSymplecticEuler}) {
    Lattice lat = make_chain(n, a, k, m, 2.0, -Vec3::UnitZ());
    lat.gravity_m_per_s2 = Vec3(0, 0, -g);
    IntegratorWorkspace ws;
    for (int f = 0; f < 1200; ++f) step_lattice(&lat, opts(kind, 0, kind == IntegratorKind::kLocalGlobal ? 50 : 4), 1.0 / 60.0, {}, &ws);
    const double total = -(lat.x_m[n].z() - lat.rest_m[n].z());
    EXPECT_NEAR(total, m * g * n * (n + 1) / (2.0 * k), 1e-6 * total) << integrator_name(kind);
    for (int j = 1; j <= n; ++j) {
      const double stretch = (lat.x_m[j] - lat.x_m[j - 1]).norm() - a;
      EXPECT_NEAR(stretch, (n - j + 1) * m * g / k, 1e-6 * a) << integrator_name(kind) << " spring " << j;
    }
  }
}

// A wide longitudinal pulse on a long chain travels at the long-wave speed a sqrt(k/m).
TEST(ChainWave, LongWaveSpeedIsASqrtKOverM) {
  const int n = 400;
  const double a = 0.01, k = 50.0, m = 0.005, sigma = 8.0;
  const double speed = a * std::sqrt(k / m);  // 1 m/s
  for (IntegratorKind kind : {IntegratorKind::kRk4, IntegratorKind::kSymplecticEuler}) {
    Lattice lat = make_chain(n, a, k, m, 0.0, Vec3::UnitX(), true);
    // a right-moving pulse: u(i) = A exp(-((i - i0)/sigma)^2 / 2), v = -c du/dx
    const double i0 = 100.0, amp = 1e-4;
    for (int i = 1; i < n; ++i) {
      const double q = (i - i0) / sigma, u = amp * std::exp(-0.5 * q * q);
      lat.x_m[i].x() += u;
      lat.v_m_per_s[i].x() = -speed * (-q / (sigma * a)) * u;
    }
    IntegratorWorkspace ws;
    const double t_end = 1.5;  // the peak moves 150 nodes
    const int frames = static_cast<int>(std::lround(t_end * 60.0));
    for (int f = 0; f < frames; ++f) step_lattice(&lat, opts(kind), 1.0 / 60.0, {}, &ws);
    // peak by a parabola through the largest displacement and its neighbours
    int best = 1;
    for (int i = 1; i < n; ++i)
      if (lat.x_m[i].x() - lat.rest_m[i].x() > lat.x_m[best].x() - lat.rest_m[best].x()) best = i;
    const double ym = lat.x_m[best - 1].x() - lat.rest_m[best - 1].x(), y0 = lat.x_m[best].x() - lat.rest_m[best].x(),
                 yp = lat.x_m[best + 1].x() - lat.rest_m[best + 1].x();
    const double peak = best + 0.5 * (ym - yp) / (ym - 2 * y0 + yp);
    const double measured = (peak - i0) * a / (frames / 60.0);
    EXPECT_NEAR(measured / speed, 1.0, 0.01) << integrator_name(kind);
  }
}

// Undamped lattice, random kick: symplectic Euler keeps the energy bounded (no drift), implicit Euler and the
// local/global solver dissipate it, the paper's explicit Euler adds to it.
TEST(UndampedLattice, EnergyBoundedForSymplecticDecayingForImplicitGrowingForExplicit) {
  LatticeSpec spec = test::spec_for(3, 40, 20, 10);
  spec.damping_Ns_per_m = 0.0;
  spec.fix_floor = true;
  const Lattice base = test::make_block(3, 4, spec);
  auto run = [&](IntegratorKind kind, double* e_max) {
    Lattice lat = base;
    test::kick(&lat, 1e-4);
    const double e0 = test::energy_J(lat);
    IntegratorWorkspace ws;
    *e_max = e0;
    for (int f = 0; f < 300 && test::all_finite(lat); ++f) {
      step_lattice(&lat, opts(kind), 1.0 / 60.0, {}, &ws);
      *e_max = std::max(*e_max, test::energy_J(lat));
    }
    return test::all_finite(lat) ? test::energy_J(lat) / e0 : INFINITY;
  };
  double e_max = 0.0;
  const double sym = run(IntegratorKind::kSymplecticEuler, &e_max);
  EXPECT_GT(sym, 0.7);
  EXPECT_LT(e_max / 1e-4, 1.3);
  EXPECT_LT(run(IntegratorKind::kImplicitEuler, &e_max), 0.1);
  EXPECT_LT(run(IntegratorKind::kLocalGlobal, &e_max), 0.1);
  EXPECT_GT(run(IntegratorKind::kExplicitEuler, &e_max), 10.0);
}

}  // namespace
}  // namespace palpate
