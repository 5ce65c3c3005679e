#include "tools/bench/bench_png.h"

#include "core/thread_cpu.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/scene.h"
#include "core/stats.h"
#include "render/png_io.h"
#include "runtime/record/frame_files.h"
#include "runtime/record/recorder.h"

namespace palpate {
namespace {

namespace fs = std::filesystem;

struct Candidate {
  const char* name;
  PngCodec codec;
  int level;
  bool keep_alpha;
  PngFilter filter;  // libdeflate only (libpng+zlib filters with SUB)
  std::unique_ptr<PngEncoder> encoder;
  std::vector<double> ms;      // per encode, wall
  std::vector<double> cpu_ms;  // per encode, this thread's CPU time (what the load of other processes leaves out)
  double bytes = 0.0;      // summed over the first pass
  bool exact = true;       // every frame decoded back to the same pixels
};

// CPU seconds (user + system) used so far by every thread of this process.
double process_cpu_s() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

// One way of writing a recording's frames.
struct WriterSetup {
  const char* name;
  const char* folder;
  PngCodec codec;
  bool keep_alpha;
  int threads;
  std::vector<double> wall_per_scene_s;
  std::vector<double> cpu_per_scene_s;  // user + system CPU of every thread of the process
  std::string state_hash;
  int frames = 0;
};

// Records `scene_path` with each writer setup in turn, o.repetitions times; appends the table to *out.
Status compare_recordings(const BenchPngOptions& o, std::string* out, std::string* last_folder) {
  auto scene = load_scene(o.record);
  if (!scene) return scene.error();
  if (scene.value().run_mode != RunMode::kLockstep) return make_error("bench png: scene '", o.record, "' is not lockstep");
  std::vector<WriterSetup> setups;
  setups.push_back({"zlib RGBA, 1 thread", "zlib_rgba_1", PngCodec::kZlib, true, 1, {}, {}, "", 0});
  setups.push_back({"zlib RGB, 1 thread", "zlib_rgb_1", PngCodec::kZlib, false, 1, {}, {}, "", 0});
  setups.push_back({"libdeflate RGB, 1 thread", "deflate_rgb_1", PngCodec::kLibdeflate, false, 1, {}, {}, "", 0});
  setups.push_back({"libdeflate RGB, 2 threads", "deflate_rgb_2", PngCodec::kLibdeflate, false, 2, {}, {}, "", 0});
  for (int rep = 0; rep < o.repetitions; ++rep)
    for (auto& w : setups) {
      RecordOptions ro;
      ro.out_dir = (fs::path(o.out_dir) / w.folder).string();
      ro.quiet = true;
      // as `palpate record` does by default: the MP4 beside the frames
      ro.video_path = (fs::path(ro.out_dir) / "recording.mp4").string();
      ro.video_optional = true;
      ro.png_codec = w.codec;
      ro.png_keep_alpha = w.keep_alpha;
      ro.png_threads = w.threads;
      const double cpu0 = process_cpu_s();
      auto r = record_scene(scene.value(), ro);
      if (!r) return r.error();
      const auto j = nlohmann::json::parse(r.value().summary_json);
      w.wall_per_scene_s.push_back(j["wall_s_per_scene_s"].get<double>());
      w.cpu_per_scene_s.push_back((process_cpu_s() - cpu0) / j["duration_s"].get<double>());
      if (!w.state_hash.empty() && w.state_hash != r.value().state_hash)
        return make_error("bench png: ", w.name, ": state hash changed between repetitions");
      w.state_hash = r.value().state_hash;
      w.frames = r.value().frames_written;
      std::fprintf(stderr, "bench png: %s, pass %d: %.3f s wall, %.3f s CPU per scene-second\n", w.name, rep + 1,
                   w.wall_per_scene_s.back(), w.cpu_per_scene_s.back());
    }
  char line[256];
  std::snprintf(line, sizeof line, "recordings of %s (lockstep, %d passes, configurations interleaved):\n",
                o.record.c_str(), o.repetitions);
  *out += line;
  std::snprintf(line, sizeof line, "%-28s %10s %8s %8s %8s %10s %8s\n", "frames written by", "wall/s p50", "min",
                "max", "speedup", "cpu/s p50", "frames");
  *out += line;
  const double base = percentile(setups.front().wall_per_scene_s, 0.5);
  for (const auto& w : setups) {
    const double p50 = percentile(w.wall_per_scene_s, 0.5);
    std::snprintf(line, sizeof line, "%-28s %10.3f %8.3f %8.3f %7.2fx %10.3f %8d\n", w.name, p50,
                  *std::min_element(w.wall_per_scene_s.begin(), w.wall_per_scene_s.end()),
                  *std::max_element(w.wall_per_scene_s.begin(), w.wall_per_scene_s.end()), base / p50,
                  percentile(w.cpu_per_scene_s, 0.5), w.frames);
    *out += line;
    if (w.state_hash != setups.front().state_hash)
      return make_error("bench png: ", w.name, ": state hash ", w.state_hash, " differs from ", setups.front().state_hash);
  }
  *out += "state hash (every configuration): " + setups.front().state_hash + "\n\n";
  *last_folder = (fs::path(o.out_dir) / setups.back().folder).string();
  return Ok{};
}

}  // namespace

Result<std::string> run_bench_png(const BenchPngOptions& o_in) {
  BenchPngOptions o = o_in;
  // the output is checked before minutes of recording: never a device or a link replaced at the end
  if (!o.json_path.empty())
    if (auto st = check_output_target(o.json_path, "bench json"); !st) return st.error();
  std::string out;
  if (!o.record.empty()) {
    std::string folder;
    if (auto st = compare_recordings(o, &out, &folder); !st) return st.error();
    if (o.folder.empty()) o.folder = folder;
  }
  if (o.folder.empty()) return make_error("bench png: give a recording folder or --record SCENE");
  fs::path dir = fs::path(o.folder) / "frames";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) dir = o.folder;
  auto listed = list_frame_files(dir.string());
  if (!listed) return make_error("bench png: folder '", o.folder, "': ", listed.error().message);
  std::vector<fs::path> files;
  for (const FrameFile& f : listed.value()) files.emplace_back(f.path);
  // at most o.frames frames, spread over the whole recording (still, moving and cut frames alike)
  std::vector<Image> frames;
  const std::size_t n = std::min(files.size(), static_cast<std::size_t>(o.frames));
  for (std::size_t i = 0; i < n; ++i) {
    auto img = read_png(files[i * files.size() / n].string());
    if (!img) return make_error("bench png: ", img.error().message);
    frames.push_back(std::move(img).value());
  }

  std::vector<Candidate> cands;
  // libdeflate L2 SUB was the default before; L1 with no filter is used now
  cands.push_back({"libpng+zlib L1 RGBA", PngCodec::kZlib, 1, true, PngFilter::kSub, nullptr, {}, {}, 0, true});
  cands.push_back({"libpng+zlib L1 RGB", PngCodec::kZlib, 1, false, PngFilter::kSub, nullptr, {}, {}, 0, true});
  cands.push_back({"libdeflate L2 RGB sub", PngCodec::kLibdeflate, 2, false, PngFilter::kSub, nullptr, {}, {}, 0, true});
  cands.push_back({"libdeflate L2 RGB up", PngCodec::kLibdeflate, 2, false, PngFilter::kUp, nullptr, {}, {}, 0, true});
  cands.push_back({"libdeflate L2 RGB paeth", PngCodec::kLibdeflate, 2, false, PngFilter::kPaeth, nullptr, {}, {}, 0, true});
  cands.push_back({"libdeflate L2 RGB none", PngCodec::kLibdeflate, 2, false, PngFilter::kNone, nullptr, {}, {}, 0, true});
  cands.push_back({"libdeflate L1 RGB sub", PngCodec::kLibdeflate, 1, false, PngFilter::kSub, nullptr, {}, {}, 0, true});
  cands.push_back({"libdeflate L1 RGB up", PngCodec::kLibdeflate, 1, false, PngFilter::kUp, nullptr, {}, {}, 0, true});
  cands.push_back({"libdeflate L1 RGB none (used)", PngCodec::kLibdeflate, 1, false, PngFilter::kNone, nullptr, {}, {}, 0, true});
  cands.push_back({"libdeflate L4 RGB none", PngCodec::kLibdeflate, 4, false, PngFilter::kNone, nullptr, {}, {}, 0, true});
  for (auto& c : cands) {
    c.encoder = std::make_unique<PngEncoder>(c.codec, c.level);
    c.encoder->set_keep_alpha(c.keep_alpha);
    c.encoder->set_filter(c.filter);
  }
  // side by side: each frame goes through every encoder in turn, so machine load falls on all alike
  int rgb_frames = 0;
  for (int rep = 0; rep < o.repetitions; ++rep)
    for (std::size_t f = 0; f < frames.size(); ++f)
      for (auto& c : cands) {
        const Image& img = frames[f];
        const double c0 = thread_cpu_ms();
        const auto t0 = std::chrono::steady_clock::now();
        const Status st = c.encoder->encode(img.width, img.height, img.rgba.data(), files[f].string());
        const std::chrono::duration<double, std::milli> dt = std::chrono::steady_clock::now() - t0;
        c.cpu_ms.push_back(thread_cpu_ms() - c0);
        if (!st) return make_error("bench png: ", st.error().message);
        c.ms.push_back(dt.count());
        if (rep == 0) {
          c.bytes += static_cast<double>(c.encoder->bytes().size());
          if (&c == &cands.back() && c.encoder->last_rgb()) ++rgb_frames;
          auto back = decode_png(c.encoder->bytes().data(), c.encoder->bytes().size(), c.name);
          c.exact = c.exact && back && back.value().rgba == img.rgba;
        }
      }

  const double base = percentile(cands.front().cpu_ms, 0.5);
  char line[256];
  std::snprintf(line, sizeof line, "png encoders: %zu frames of %s (%dx%d, %d opaque), %d passes, in memory\n",
                frames.size(), dir.string().c_str(), frames.front().width, frames.front().height, rgb_frames,
                o.repetitions);
  out += line;
  std::snprintf(line, sizeof line, "%-30s %8s %8s %8s %10s %8s %9s\n", "encoder", "cpu_p50", "wall_p50", "wall_p90",
                "kB/frame", "speedup", "lossless");
  out += line;
  nlohmann::json j;
  j["folder"] = o.folder;
  j["frames"] = frames.size();
  j["repetitions"] = o.repetitions;
  j["rows"] = nlohmann::json::array();
  for (const auto& c : cands) {
    const double cpu = percentile(c.cpu_ms, 0.5), p50 = percentile(c.ms, 0.5), p90 = percentile(c.ms, 0.9);
    const double kb = c.bytes / static_cast<double>(frames.size()) / 1024.0;
    std::snprintf(line, sizeof line, "%-30s %8.2f %8.2f %8.2f %10.1f %7.2fx %9s\n", c.name, cpu, p50, p90, kb,
                  base / cpu, c.exact ? "yes" : "NO");
    out += line;
    j["rows"].push_back({{"encoder", c.name}, {"cpu_p50_ms", cpu}, {"wall_p50_ms", p50}, {"wall_p90_ms", p90},
                         {"kB_per_frame", kb}, {"cpu_speedup_vs_rgba_zlib", base / cpu}, {"lossless", c.exact}});
  }
  if (!o.json_path.empty())
    if (auto st = write_file_atomic(o.json_path, j.dump(2) + "\n", "bench json"); !st) return st.error();
  for (const auto& c : cands)
    if (!c.exact) return make_error("bench png: ", c.name, " did not decode back to the same pixels");
  return out;
}

}  // namespace palpate
