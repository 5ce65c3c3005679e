#include "tools/commands/hand_fuzz.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <random>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/scene.h"
#include "tools/bench/bench_feel.h"
#include "tools/commands/scene_command.h"
#include "tools/commands/scene_target.h"
#include "tools/commands/scene_trajectory.h"
#include "runtime/session/surface_queries.h"

namespace palpate {
namespace {

namespace fs = std::filesystem;

constexpr double kClear_m = 0.01;  // a hand starts and ends this far out of the surface (less where a part is near)

nlohmann::ordered_json vec_json(const Vec3& v) {
  auto um = [](double x) { return std::round(x * 1e7) / 1e7; };
  return {um(v.x()), um(v.y()), um(v.z())};
}

// keyframes of the hand's target, built move by move
class Keys {
 public:
  explicit Keys(const Vec3& start) : at_(start) { add(); }
  // to p at speed (m/s)
  void to(const Vec3& p, double speed_m_per_s) {
    t_s_ += std::max(0.02, (p - at_).norm() / speed_m_per_s);
    at_ = p;
    add();
  }
  void hold(double dt_s) {
    t_s_ += dt_s;
    add();
  }
  void button(bool down) {
    t_s_ += 0.02;
    button_ = down;
    add();
  }
  const Vec3& at() const { return at_; }
  double t_s() const { return t_s_; }
  nlohmann::ordered_json take() { return std::move(keys_); }

 private:
  void add() {
    nlohmann::ordered_json k;
    k["t_s"] = std::round(t_s_ * 1e6) / 1e6;
    k["pos_m"] = vec_json(at_);
    if (button_) k["button"] = true;
    keys_.push_back(k);
  }
  Vec3 at_;
  double t_s_ = 0.0;
  bool button_ = false;
  nlohmann::ordered_json keys_ = nlohmann::ordered_json::array();
};

// One hand: the scene it ran (the model's generated scene with its own tool, material and trajectory).
struct Hand {
  std::string kind;              // press | stroke | pull | cut
  uint64_t seed = 0;             // what makes it
  nlohmann::ordered_json scene;  // the scene file's content
};

// a mesh's generated scenes and where hands can work on it
struct ModelBase {
  std::string path;
  nlohmann::ordered_json touch, pull, cut;  // cut: null when the model has none
  std::unique_ptr<Model> model;             // the touch scene's model (surface points)
};

double uniform(std::mt19937_64& g, double a, double b) { return std::uniform_real_distribution<double>(a, b)(g); }
// 10^U(log a, log b): speeds spread over decades
double log_uniform(std::mt19937_64& g, double a, double b) { return std::exp(uniform(g, std::log(a), std::log(b))); }
Vec3 random_unit(std::mt19937_64& g) {
  std::normal_distribution<double> n(0.0, 1.0);
  for (;;) {
    const Vec3 v(n(g), n(g), n(g));
    if (v.norm() > 1e-6) return v.normalized();
  }
}
Vec3 tangent(std::mt19937_64& g, const Vec3& normal) {
  const Vec3 v = random_unit(g);
  const Vec3 t = v - v.dot(normal) * normal;
  return t.norm() > 1e-6 ? Vec3(t.normalized()) : Vec3(normal.unitOrthogonal());
}

Result<ModelBase> model_base(const std::string& path) {
  ModelBase b;
  b.path = fs::absolute(path).string();
  SceneRequest rq;
  rq.mesh_path = b.path;
  rq.young_modulus_Pa = 300e3;
  auto touch = generate_scene(rq);
  if (!touch) return touch.error();
  b.touch = touch.value().json;
  rq.mode = InteractionMode::kPull;
  auto pull = generate_scene(rq);
  if (!pull) return pull.error();
  b.pull = pull.value().json;
  rq.mode = InteractionMode::kCut;
  auto cut = generate_scene(rq);
  if (cut) b.cut = cut.value().json;
  // the mesh by its absolute path, so a kept hand's scene runs from any folder
  for (auto* j : {&b.touch, &b.pull, &b.cut})
    if (!j->is_null()) (*j)["mesh"]["file"] = b.path;
  auto scene = parse_scene(b.touch.dump(), "hand.json");
  if (!scene) return scene.error();
  auto model = load_model(scene.value());
  if (!model) return model.error();
  b.model = std::make_unique<Model>(std::move(model.value()));
  return b;
}

// a surface point a tool coming from a random side meets, and its outward normal
bool pick_point(std::mt19937_64& g, const Model& model, Vec3* P, Vec3* n) {
  const Aabb box = Aabb::of(model.rest.vertices_m);
  for (int tries = 0; tries < 12; ++tries) {
    const Vec3 from = random_unit(g);
    bool offset = false;
    std::vector<SurfaceHit> more;
    const auto hit = surface_from(model, box, from, kGrabRadius_m, &offset, &more);
    if (!hit) continue;
    const std::size_t k = std::uniform_int_distribution<std::size_t>(0, more.size())(g);
    *P = k == 0 ? hit->point_m : more[k - 1].point_m;
    *n = k == 0 ? hit->normal : more[k - 1].normal;
    return true;
  }
  return false;
}

// the way out from P along n, shortened where another part stands in front of it
double clearance(const Model& model, const Vec3& P, const Vec3& n) {
  const auto block = first_ray_hit(model, P + 1e-6 * n, n, kClear_m, false);
  return block ? std::max(0.5 * block->distance_m, 1e-3) : kClear_m;
}

void touch_keys(std::mt19937_64& g, const Vec3& P, const Vec3& n, double clear_m, bool stroke, Keys* k) {
  const Vec3 out = P + clear_m * n;
  k->hold(0.3);
  k->to(P + std::min(0.003, clear_m) * n, 0.05);
  // pressed: shallow, or to the device's force limit and beyond (the hand's spring pushes on)
  auto depth = [&] { return uniform(g, 0.0, 1.0) < 0.4 ? uniform(g, 0.015, 0.04) : uniform(g, 0.0005, 0.008); };
  k->to(P - depth() * n, log_uniform(g, 0.005, 0.1));
  k->hold(uniform(g, 0.1, 0.5));
  const int moves = stroke ? 1 + static_cast<int>(uniform(g, 0.0, 3.0)) : static_cast<int>(uniform(g, 0.0, 2.0));
  for (int i = 0; i < moves; ++i) {
    if (stroke) {
      // across the surface at 1-200 mm/s, for at most 2.5 s
      const double speed = log_uniform(g, 0.001, 0.2);
      const double length = std::min(uniform(g, 0.005, 0.04), 2.5 * speed);
      const Vec3 u = tangent(g, n);
      k->to(k->at() + length * u - uniform(g, -0.003, 0.003) * n, speed);
      if (uniform(g, 0.0, 1.0) < 0.3) k->to(k->at() - length * u, speed);  // and back along the same path
    } else if (uniform(g, 0.0, 1.0) < 0.5) {
      // lift off and press again nearby
      const Vec3 at = k->at() + (k->at() - P).dot(n) * -n;  // back onto P's plane
      k->to(at + uniform(g, 0.001, 0.006) * n, log_uniform(g, 0.01, 0.2));
      k->to(at + uniform(g, 0.002, 0.005) * tangent(g, n) - depth() * n, log_uniform(g, 0.005, 0.1));
    } else {
      k->to(P - depth() * n, log_uniform(g, 0.005, 0.1));
    }
    k->hold(uniform(g, 0.05, 0.3));
  }
  k->to(k->at() + (out - k->at()).dot(n) * n, log_uniform(g, 0.02, 0.2));
  k->hold(0.2);
}

void pull_keys(std::mt19937_64& g, const Vec3& P, const Vec3& n, double clear_m, Keys* k) {
  const Vec3 grab = P + 0.002 * n;
  k->hold(0.2);
  k->to(grab, 0.05);
  k->button(true);
  // pulled out and aside, then shaken sideways as a person's hand does (0.5-5 Hz)
  const Vec3 u = tangent(g, n);
  const Vec3 pulled = grab + uniform(g, 0.003, 0.015) * n + uniform(g, -0.005, 0.005) * u;
  k->to(pulled, log_uniform(g, 0.005, 0.05));
  const double hz = log_uniform(g, 0.5, 5.0), amp_m = uniform(g, 0.001, 0.006);
  const double shake_s = std::min(2.0, std::max(1.0, 3.0 / hz));
  const double dt = 1.0 / (8.0 * hz);
  const double t0 = k->t_s();
  for (double t = dt; t <= shake_s + 1e-9; t += dt) {
    const Vec3 p = pulled + amp_m * std::sin(2.0 * 3.14159265358979 * hz * t) * u;
    k->to(p, 1e9);
    k->hold(t0 + t - k->t_s());
  }
  k->button(false);
  k->to(k->at() + clear_m * n, 0.05);
  k->hold(0.2);
}

// FNV-1a of the model's file name: the same seed makes other hands on another model
uint64_t name_hash(const std::string& path) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : fs::path(path).filename().string()) h = (h ^ c) * 0x100000001b3ull;
  return h;
}

Hand make_hand(const ModelBase& b, uint64_t seed) {
  std::mt19937_64 g(seed * 0x9E3779B97F4A7C15ull + name_hash(b.path));
  Hand h;
  h.seed = seed;
  const double r = uniform(g, 0.0, 1.0);
  h.kind = r < 0.35 ? "press" : r < 0.75 ? "stroke" : r < 0.9 ? "pull" : "cut";
  if (h.kind == "cut" && b.cut.is_null()) h.kind = "stroke";
  if (h.kind == "cut") {
    // the generated blade pass at another speed
    h.scene = b.cut;
    const double scale = log_uniform(g, 0.4, 2.5);
    for (auto& key : h.scene["trajectory"]) key["t_s"] = key["t_s"].get<double>() * scale;
    h.scene["duration_s"] = h.scene["trajectory"].back()["t_s"].get<double>() + 0.2;
    h.scene["name"] = "hand_" + std::to_string(seed) + "_cut";
    return h;
  }
  const bool pull = h.kind == "pull";
  h.scene = pull ? b.pull : b.touch;
  Vec3 P = Vec3::Zero(), n = Vec3::UnitZ();
  if (!pick_point(g, *b.model, &P, &n)) {
    // none found from random sides: the generated scene's own point (its first press)
    h.kind = pull ? "pull" : "press";
    h.scene["name"] = "hand_" + std::to_string(seed) + "_" + h.kind;
    return h;
  }
  const double clear_m = clearance(*b.model, P, n);
  Keys k(P + clear_m * n);
  if (pull) pull_keys(g, P, n, clear_m, &k);
  else touch_keys(g, P, n, clear_m, h.kind == "stroke", &k);
  h.scene["trajectory"] = k.take();
  h.scene["duration_s"] = std::round((k.t_s() + 0.1) * 1e3) / 1e3;
  // materials a user names: soft tissue, a firm one, a stiff part
  const double m = uniform(g, 0.0, 1.0);
  h.scene["material"]["young_modulus_Pa"] = m < 0.25 ? 50e3 : m < 0.75 ? 300e3 : 10e6;
  if (!pull) {
    if (uniform(g, 0.0, 1.0) < 0.5) {
      h.scene["device"]["tool_shape"] = "sphere";
      h.scene["device"]["tool_radius_m"] = std::round(uniform(g, 0.001, 0.004) * 1e5) / 1e5;
    }
    if (uniform(g, 0.0, 1.0) < 0.5) {
      const double mus = uniform(g, 0.2, 0.8);
      h.scene["material"]["static_friction"] = std::round(mus * 100) / 100;
      h.scene["material"]["dynamic_friction"] = std::round(mus * uniform(g, 0.5, 1.0) * 100) / 100;
    }
  }
  h.scene["name"] = "hand_" + std::to_string(seed) + "_" + h.kind;
  return h;
}

// what a hand found; fails when the god-object's invariant broke, the lattice went NaN, a wild step reached the hand
// or the contact's steps and flips passed 1 % of its ticks
struct HandResult {
  std::string model, kind;
  uint64_t seed = 0;
  std::string error;
  FeelRun run;
  bool failed() const {
    const FeelFigures& f = run.figures;
    const double contact = std::max<int64_t>(1, f.contact_ticks), steady = std::max<int64_t>(1, f.steady_ticks);
    return !error.empty() || run.tool_inside_ticks + run.proxy_inside_ticks > 0 || run.nan_events > 0 ||
           f.wild_steps > 0 || static_cast<double>(f.excess_ticks) > 0.01 * contact ||
           static_cast<double>(f.lateral_flips) > 0.01 * steady;
  }
};

nlohmann::json to_json(const HandResult& h) {
  const FeelFigures& f = h.run.figures;
  nlohmann::json j{{"model", h.model}, {"seed", h.seed}, {"kind", h.kind}, {"failed", h.failed()}};
  if (!h.error.empty()) {
    j["error"] = h.error;
    return j;
  }
  j.update({{"contact_ticks", f.contact_ticks},
            {"tool_inside_ticks", h.run.tool_inside_ticks},
            {"proxy_inside_ticks", h.run.proxy_inside_ticks},
            {"wild_steps", f.wild_steps},
            {"max_wild_excess_N", f.max_wild_excess_N},
            {"excess_ticks", f.excess_ticks},
            {"lateral_flips", f.lateral_flips},
            {"steady_ticks", f.steady_ticks},
            {"buzz_share", f.buzz_share},
            {"energy_into_hand_J", f.energy_into_hand_J},
            {"nan_events", h.run.nan_events}});
  return j;
}

struct Totals {
  bool closed = true;  // every model closed (the crossings are judged only where the surface has an inside)
  int64_t hands = 0, failed = 0, errors = 0, contact = 0, steady = 0, inside = 0, proxy = 0, wild = 0, excess = 0,
          flips = 0, nan = 0;
  double max_wild_N = 0.0, max_buzz = 0.0, max_energy_J = -INFINITY;
  void add(const HandResult& h) {
    ++hands;
    failed += h.failed();
    if (!h.error.empty()) {
      ++errors;
      return;
    }
    const FeelFigures& f = h.run.figures;
    contact += f.contact_ticks;
    steady += f.steady_ticks;
    inside += h.run.tool_inside_ticks;
    proxy += h.run.proxy_inside_ticks;
    wild += f.wild_steps;
    excess += f.excess_ticks;
    flips += f.lateral_flips;
    nan += h.run.nan_events;
    max_wild_N = std::max(max_wild_N, f.max_wild_excess_N);
    max_buzz = std::max(max_buzz, f.buzz_share);
    max_energy_J = std::max(max_energy_J, f.energy_into_hand_J);
  }
};

void print_row(const std::string& name, const Totals& t) {
  const double c = static_cast<double>(std::max<int64_t>(1, t.contact)), s = static_cast<double>(std::max<int64_t>(1, t.steady));
  std::printf("%-22s %6s %5lld %6lld %8lld %7lld %7lld %6lld %8.3f %8.2f %7.2f %7.3f %9.3f %5lld\n", name.c_str(),
              t.closed ? "yes" : "open", static_cast<long long>(t.hands), static_cast<long long>(t.failed), static_cast<long long>(t.contact),
              static_cast<long long>(t.inside), static_cast<long long>(t.proxy), static_cast<long long>(t.wild),
              t.max_wild_N, 100.0 * static_cast<double>(t.excess) / c, 100.0 * static_cast<double>(t.flips) / s,
              100.0 * t.max_buzz, std::isfinite(t.max_energy_J) ? 1e3 * t.max_energy_J : 0.0, static_cast<long long>(t.nan));
}

}  // namespace

int run_hand_fuzz(const HandFuzzOptions& o) {
  if (o.models.empty()) {
    std::fprintf(stderr, "palpate: bench feel --hands: no model given (mesh files: OBJ, OFF, PLY, STL ...)\n");
    return 1;
  }
  if (!o.json_path.empty())
    if (auto st = check_output_target(o.json_path, "bench json"); !st) {
      std::fprintf(stderr, "palpate: bench feel: %s\n", st.error().message.c_str());
      return 1;
    }
  if (!o.keep_dir.empty()) {
    std::error_code ec;
    fs::create_directories(o.keep_dir, ec);
    if (ec) {
      std::fprintf(stderr, "palpate: bench feel: --keep '%s': %s\n", o.keep_dir.c_str(), ec.message().c_str());
      return 1;
    }
  }
  BenchFeelOptions fo;
  fo.step_threshold_N = o.step_threshold_N;
  fo.excess_threshold_N = o.excess_threshold_N;
  std::vector<HandResult> results;
  std::vector<std::pair<std::string, Totals>> per_model;
  // a model that cannot be used (missing, broken, flat) is named and skipped: the others' hands still run, and the
  // exit status says one was skipped
  std::vector<std::string> skipped;
  bool progress_open = false;  // a progress line is on stderr without its end
  for (const std::string& path : o.models) {
    auto base = model_base(path);
    if (!base) {
      std::fprintf(stderr, "palpate: bench feel --hands: skipped: %s\n", base.error().message.c_str());
      skipped.push_back(path);
      continue;
    }
    const std::string name = fs::path(path).filename().string();
    Totals totals;
    totals.closed = base.value().model->closed;
    // models by their mesh, grid, lattice level and mode (a touch model knows whether its surface is closed)
    std::map<std::string, std::unique_ptr<Model>> models;
    for (int i = 0; i < o.hands; ++i) {
      const uint64_t seed = o.seed + static_cast<uint64_t>(i);
      Hand hand = make_hand(base.value(), seed);
      if (o.force_shading_deg >= 0.0) hand.scene["device"]["force_shading_deg"] = o.force_shading_deg;
      HandResult r;
      r.model = name;
      r.kind = hand.kind;
      r.seed = seed;
      const std::string text = hand.scene.dump(1);
      auto scene = parse_scene(text, "hand.json");
      if (!scene) {
        r.error = scene.error().message;
      } else {
        const std::string key = hand.scene["mesh"].dump() + hand.scene["grid"].dump() +
                                hand.scene["lattice"]["level"].dump() + hand.scene["interaction"]["mode"].dump();
        auto& model = models[key];
        if (!model) {
          auto m = load_model(scene.value());
          if (m) model = std::make_unique<Model>(std::move(m.value()));
          else r.error = m.error().message;
        }
        if (model) {
          auto run = run_feel(scene.value(), *model, fo);
          if (run) r.run = std::move(run.value());
          else r.error = run.error().message;
        }
      }
      r.run.trace.clear();
      r.run.trace.shrink_to_fit();
      totals.add(r);
      if (r.failed()) {
        const FeelFigures& f = r.run.figures;
        // the progress line ends first, so the report starts a line of its own on a terminal and in a log
        if (progress_open) std::fputc('\n', stderr);
        std::fflush(stderr);
        progress_open = false;
        std::printf("FAIL %s hand %llu (%s): ", name.c_str(), static_cast<unsigned long long>(seed), r.kind.c_str());
        if (!r.error.empty()) std::printf("%s\n", r.error.c_str());
        else
          std::printf("tool inside %lld, proxy inside %lld (first at %.3f s), wild steps %lld (excess %.3f N), excess "
                      "ticks %lld of %lld, flips %lld of %lld, nan %lld\n",
                      static_cast<long long>(r.run.tool_inside_ticks), static_cast<long long>(r.run.proxy_inside_ticks),
                      r.run.through_first_t_s, static_cast<long long>(f.wild_steps), f.max_wild_excess_N,
                      static_cast<long long>(f.excess_ticks), static_cast<long long>(f.contact_ticks),
                      static_cast<long long>(f.lateral_flips), static_cast<long long>(f.steady_ticks),
                      static_cast<long long>(r.run.nan_events));
        if (!o.keep_dir.empty()) {
          const std::string out = (fs::path(o.keep_dir) / (fs::path(path).stem().string() + "_hand_" +
                                                           std::to_string(seed) + ".json")).string();
          if (auto st = write_file_atomic(out, text + "\n", "hand scene"); !st)
            std::fprintf(stderr, "palpate: bench feel: %s\n", st.error().message.c_str());
        }
      } else {
        std::fprintf(stderr, "\r%s: %d of %d hands run", name.c_str(), i + 1, o.hands);
        progress_open = true;
      }
      std::fflush(stdout);
      results.push_back(std::move(r));
    }
    if (progress_open) std::fprintf(stderr, "\n");
    progress_open = false;
    per_model.emplace_back(name, totals);
  }
  std::printf("\nhands: steps are |dF| per tick on every contact tick, event ticks excused up to the jump limit\n");
  std::printf("%-22s %6s %5s %6s %8s %7s %7s %6s %8s %8s %7s %7s %9s %5s\n", "model", "closed", "hands", "failed", "contact",
              "tool_in", "proxy_in", "wild", "wild_N", "excess%", "flips%", "buzz%", "energy_mJ", "nan");
  Totals all;
  for (const auto& [name, t] : per_model) print_row(name, t);
  for (const HandResult& r : results) all.add(r);
  for (const auto& pm : per_model) all.closed = all.closed && pm.second.closed;
  print_row("all", all);
  std::printf("(tool_in, proxy_in: ticks through the surface; on an open model (closed: open), a path that crossed it an odd number of times and is away from it; wild: steps above %g N beyond the device's motion by more than %g N; excess%%: contact ticks beyond it "
              "by more than %g N; flips%%: of steady ticks; buzz: the largest share above 100 Hz)\n",
              o.step_threshold_N, o.excess_threshold_N, o.excess_threshold_N);
  if (!o.json_path.empty()) {
    nlohmann::json out{{"seed", o.seed}, {"hands_per_model", o.hands}, {"hands", nlohmann::json::array()}};
    for (const HandResult& r : results) out["hands"].push_back(to_json(r));
    if (auto st = write_file_atomic(o.json_path, out.dump(1) + "\n", "bench json"); !st) {
      std::fprintf(stderr, "palpate: bench feel: %s\n", st.error().message.c_str());
      return 1;
    }
  }
  if (!skipped.empty()) {
    std::printf("skipped %zu model(s) that could not be used:", skipped.size());
    for (const std::string& s : skipped) std::printf(" %s", s.c_str());
    std::printf("\n");
  }
  return all.errors > 0 || !skipped.empty() ? 1 : 0;
}

}  // namespace palpate
