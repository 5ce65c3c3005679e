#include "tools/bench/feel_figures.h"

#include <algorithm>
#include <cmath>
#include <complex>

namespace palpate {
namespace {

constexpr double kPi = 3.14159265358979323846;

// centred moving mean of v over 2 h + 1 samples (shorter at the ends)
std::vector<Vec3> moving_mean(const std::vector<Vec3>& v, int h) {
  const int n = static_cast<int>(v.size());
  std::vector<Vec3> prefix(v.size() + 1, Vec3::Zero());
  for (int i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + v[i];
  std::vector<Vec3> out(v.size());
  for (int i = 0; i < n; ++i) {
    const int a = std::max(0, i - h), b = std::min(n, i + h + 1);
    out[i] = (prefix[b] - prefix[a]) / static_cast<double>(b - a);
  }
  return out;
}

// power of the Hann-windowed, mean-removed signal per DFT bin 0 .. n/2
std::vector<double> power_spectrum(const std::vector<double>& x) {
  const int n = static_cast<int>(x.size());
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= n;
  std::vector<double> w(x.size());
  for (int i = 0; i < n; ++i) w[i] = (x[i] - mean) * 0.5 * (1.0 - std::cos(2.0 * kPi * i / (n - 1)));
  std::vector<double> p(static_cast<std::size_t>(n / 2 + 1), 0.0);
  for (int k = 0; k <= n / 2; ++k) {
    // twiddles by recurrence would drift over thousands of samples: take them from the index product mod n
    std::complex<double> s = 0.0;
    for (int i = 0; i < n; ++i) {
      const double a = -2.0 * kPi * static_cast<double>((static_cast<int64_t>(k) * i) % n) / n;
      s += w[i] * std::complex<double>(std::cos(a), std::sin(a));
    }
    p[k] = std::norm(s) / n;
  }
  return p;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::min<double>(v.size() - 1, std::floor(q * (v.size() - 1) + 0.5)));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace

std::vector<std::array<bool, kFeelEvents>> feel_events(const std::vector<FeelTick>& trace) {
  std::vector<std::array<bool, kFeelEvents>> ev(trace.size(), std::array<bool, kFeelEvents>{});
  for (std::size_t i = 0; i < trace.size(); ++i) {
    const ContactState c = trace[i].contact, c0 = i ? trace[i - 1].contact : ContactState::kFree;
    auto& e = ev[i];
    e[static_cast<int>(FeelEvent::kEntry)] = c0 != ContactState::kTouch && c == ContactState::kTouch;
    e[static_cast<int>(FeelEvent::kRelease)] = c0 == ContactState::kTouch && c != ContactState::kTouch;
    e[static_cast<int>(FeelEvent::kGrab)] = c0 != ContactState::kGrab && c == ContactState::kGrab;
    e[static_cast<int>(FeelEvent::kGrabRelease)] = c0 == ContactState::kGrab && c != ContactState::kGrab;
    e[static_cast<int>(FeelEvent::kRegion)] = trace[i].region_changed;
    e[static_cast<int>(FeelEvent::kCut)] = trace[i].cut || (c0 == ContactState::kCut) != (c == ContactState::kCut);
  }
  return ev;
}

FeelFigures feel_figures(const std::vector<FeelTick>& trace, const FeelSettings& s) {
  FeelFigures f;
  const int n = static_cast<int>(trace.size());
  f.ticks = n;
  if (n < 2) return f;
  const auto ev = feel_events(trace);
  const int window = std::max(1, static_cast<int>(std::lround(s.event_window_s / s.period_s)));
  const int half = std::max(1, static_cast<int>(std::lround(0.5 * s.trend_s / s.period_s)));

  // per tick: the force step, the part the device's motion explains, and whether it lies in an event's window
  std::vector<double> step(trace.size(), 0.0), excess(trace.size(), 0.0);
  std::vector<int> in_window(trace.size(), 0);
  for (int i = 1; i < n; ++i) {
    const Vec3 dx = trace[i].tool_m - trace[i - 1].tool_m;
    const Vec3 dx0 = i > 1 ? Vec3(trace[i - 1].tool_m - trace[i - 2].tool_m) : Vec3::Zero();
    const double explained = s.coupling_N_per_m * dx.norm() + s.damping_Ns_per_m * (dx - dx0).norm() / s.period_s;
    step[i] = (trace[i].force_N - trace[i - 1].force_N).norm();
    excess[i] = std::max(0.0, step[i] - explained);
    for (int k = 0; k < kFeelEvents; ++k) {
      if (!ev[i][k]) continue;
      auto& e = f.events[k];
      ++e.count;
      e.max_step_N = std::max(e.max_step_N, step[i]);
      for (int j = i; j < std::min(n, i + window); ++j) in_window[j] |= 1 << k;
    }
  }
  for (int i = 1; i < n; ++i)
    for (int k = 0; k < kFeelEvents; ++k)
      if (in_window[i] & (1 << k)) f.events[k].max_excess_N = std::max(f.events[k].max_excess_N, excess[i]);
  // every tick in or leaving contact: nothing excused but an event tick's jump limit
  for (int i = 1; i < n; ++i) {
    if (trace[i].contact == ContactState::kFree && trace[i - 1].contact == ContactState::kFree) continue;
    bool event = false;
    for (int k = 0; k < kFeelEvents; ++k) event |= ev[i][k];
    const double wild = excess[i] - (event ? s.jump_limit_N_per_tick : 0.0);
    f.excess_ticks += wild > s.excess_threshold_N;
    if (step[i] > s.step_threshold_N && wild > s.excess_threshold_N) {
      ++f.wild_steps;
      f.max_wild_excess_N = std::max(f.max_wild_excess_N, wild);
    }
  }

  std::vector<Vec3> force(trace.size()), tool(trace.size());
  for (int i = 0; i < n; ++i) {
    force[i] = trace[i].force_N;
    tool[i] = trace[i].tool_m;
  }
  const std::vector<Vec3> trend = moving_mean(force, half);
  std::vector<double> mag(trace.size());
  for (int i = 0; i < n; ++i) mag[i] = force[i].norm();
  std::vector<Vec3> mag3(trace.size());
  for (int i = 0; i < n; ++i) mag3[i] = Vec3(mag[i], 0, 0);
  const std::vector<Vec3> mag_trend = moving_mean(mag3, half);

  // steady contact: same contact kind as the tick before, outside every event window
  std::vector<double> steady_steps;
  double r_min = INFINITY, r_max = -INFINITY, slide_mean = 0.0;
  for (int i = 0; i < n; ++i) {
    if (trace[i].contact != ContactState::kFree) ++f.contact_ticks;
    if (i + 1 < n) f.energy_into_hand_J += force[i].dot(tool[i + 1] - tool[i]);
    if (i == 0 || trace[i].contact == ContactState::kFree || trace[i - 1].contact != trace[i].contact || in_window[i])
      continue;
    ++f.steady_ticks;
    steady_steps.push_back(step[i]);
    f.max_step_N = std::max(f.max_step_N, step[i]);
    f.steps_over += step[i] > s.step_threshold_N;
    f.max_excess_N = std::max(f.max_excess_N, excess[i]);
    f.excess_over += excess[i] > s.excess_threshold_N;
    // lateral: off the direction of the force's trend
    const double tn = trend[i].norm(), tp = trend[i - 1].norm();
    if (tn > 0.0 && tp > 0.0) {
      const Vec3 u = trend[i] / tn, u0 = trend[i - 1] / tp;
      const Vec3 lat = force[i] - force[i].dot(u) * u, lat0 = force[i - 1] - force[i - 1].dot(u0) * u0;
      if (lat.norm() > s.flip_floor_N && lat0.norm() > s.flip_floor_N && lat.dot(lat0) < 0.0) ++f.lateral_flips;
    }
    // sliding: the device moves over the trend window; depth about constant: the trend changes little across it
    const int a = std::max(0, i - half), b = std::min(n - 1, i + half);
    const double speed = (tool[b] - tool[a]).norm() / ((b - a) * s.period_s);
    const double mt = mag_trend[i].x();
    if (speed >= s.sliding_speed_m_per_s && mt > 0.0 &&
        std::abs(mag_trend[b].x() - mag_trend[a].x()) < 0.05 * mt) {
      ++f.sliding_ticks;
      const double r = mag[i] - mt;
      r_min = std::min(r_min, r);
      r_max = std::max(r_max, r);
      slide_mean += mt;
    }
  }
  f.p99_step_N = quantile(steady_steps, 0.99);
  if (f.sliding_ticks > 0) f.ripple = (r_max - r_min) / (slide_mean / static_cast<double>(f.sliding_ticks));

  // spectrum of each steady contact stretch: energy above buzz_hz over all but the mean
  double above = 0.0, total = 0.0;
  std::size_t longest = 0;
  for (int i = 0; i < n;) {
    const bool steady = trace[i].contact != ContactState::kFree;
    int j = i;
    while (j < n && trace[j].contact == trace[i].contact) ++j;
    const int len = j - i;
    if (steady && len >= s.min_run_ticks) {
      std::vector<double> sum(static_cast<std::size_t>(len / 2 + 1), 0.0);
      for (int c = 0; c < 3; ++c) {
        std::vector<double> x(static_cast<std::size_t>(len));
        for (int k = 0; k < len; ++k) x[k] = force[i + k][c];
        const std::vector<double> p = power_spectrum(x);
        for (std::size_t k = 0; k < p.size(); ++k) sum[k] += p[k];
      }
      for (std::size_t k = 1; k < sum.size(); ++k) {
        const double hz = static_cast<double>(k) / (len * s.period_s);
        total += sum[k];
        if (hz > s.buzz_hz) above += sum[k];
      }
      if (static_cast<std::size_t>(len) > longest) {
        longest = static_cast<std::size_t>(len);
        f.spectrum_hz.clear();
        f.spectrum_power.clear();
        for (std::size_t k = 1; k < sum.size(); ++k) {
          f.spectrum_hz.push_back(static_cast<double>(k) / (len * s.period_s));
          f.spectrum_power.push_back(sum[k]);
        }
      }
    }
    i = j;
  }
  f.buzz_share = total > 0.0 ? above / total : 0.0;
  return f;
}

}  // namespace palpate
