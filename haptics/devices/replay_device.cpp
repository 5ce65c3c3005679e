#include "haptics/devices/replay_device.h"

#include "core/input_file.h"
#include "core/limits.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <cstdint>
#include <tuple>

namespace palpate {
namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream s(line);
  while (std::getline(s, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

bool to_double(const std::string& s, double* v) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  *v = std::strtod(s.c_str(), &end);
  return errno == 0 && end == s.c_str() + s.size();
}

std::vector<ScheduledTick> schedule_ticks(const std::vector<ReplayRow>& rows) {
  std::vector<ScheduledTick> t;
  t.reserve(rows.size());
  for (const ReplayRow& r : rows) t.push_back({r.tick, r.frame, r.model_frame});
  return t;
}

}  // namespace

Result<std::vector<ReplayRow>> parse_haptic_csv(const std::string& text_in, const std::string& path) {
  // CRLF and CR-only line ends read as LF (a log passed through another system's tools)
  std::string text;
  text.reserve(text_in.size());
  for (std::size_t i = 0; i < text_in.size(); ++i) {
    if (text_in[i] != '\r') text += text_in[i];
    else if (i + 1 == text_in.size() || text_in[i + 1] != '\n') text += '\n';
  }
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line)) return make_error("replay '", path, "': empty file");
  const std::vector<std::string> head = split(line);
  auto col = [&](const std::string& name) {
    for (std::size_t i = 0; i < head.size(); ++i)
      if (head[i] == name) return static_cast<int>(i);
    return -1;
  };
  const int ct = col("t_s"), cx = col("tool_x_m"), cy = col("tool_y_m"), cz = col("tool_z_m"), cb = col("buttons");
  const int cr = col("rejected");
  const int cs = col("force_scale");
  const int ctick = col("tick"), cf = col("frame"), cmf = col("model_frame");
  // the controls a person changed (all five columns, or none: a log from before they were written)
  const int cc = col("controls"), cmode = col("mode"), ck = col("stiffness_scale"), crad = col("tool_radius_m"),
            cres = col("resets");
  const bool controlled = cc >= 0;
  if (controlled)
    for (const auto& [c, name] : {std::pair{cmode, "mode"}, {ck, "stiffness_scale"}, {crad, "tool_radius_m"}, {cres, "resets"}})
      if (c < 0) return make_error("replay '", path, "': line 1: column 'controls' without column '", name, "'");
  const bool scheduled = ctick >= 0 && cf >= 0 && cmf >= 0;
  for (const auto& [c, name] : {std::pair{ct, "t_s"}, {cx, "tool_x_m"}, {cy, "tool_y_m"}, {cz, "tool_z_m"}, {cb, "buttons"}})
    if (c < 0) return make_error("replay '", path, "': line 1: no column '", name, "'");

  std::vector<ReplayRow> rows;
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty()) continue;
    const std::vector<std::string> cells = split(line);
    if (cells.size() != head.size())
      return make_error("replay '", path, "': line ", std::to_string(line_no), ": ", std::to_string(cells.size()),
                        " fields, header has ", std::to_string(head.size()));
    ReplayRow r;
    double v[5] = {};
    const int cols[5] = {ct, cx, cy, cz, cb};
    for (int k = 0; k < 5; ++k)
      if (!to_double(cells[static_cast<std::size_t>(cols[k])], &v[k]) || !std::isfinite(v[k]))
        return make_error("replay '", path, "': line ", std::to_string(line_no), ": column '",
                          head[static_cast<std::size_t>(cols[k])], "': '", cells[static_cast<std::size_t>(cols[k])],
                          "' is not a finite number");
    r.t_s = v[0];
    r.pos_m = Vec3(v[1], v[2], v[3]);
    if (v[4] < 0 || v[4] > 4294967295.0 || v[4] != std::floor(v[4]))
      return make_error("replay '", path, "': line ", std::to_string(line_no), ": buttons '",
                        cells[static_cast<std::size_t>(cb)], "' is not a 32-bit mask");
    r.buttons = static_cast<uint32_t>(v[4]);
    r.rejected = cr >= 0 && cells[static_cast<std::size_t>(cr)] == "1";
    if (cs >= 0) {
      const std::string& cell = cells[static_cast<std::size_t>(cs)];
      if (!to_double(cell, &r.force_scale) || !(r.force_scale >= 0.0 && r.force_scale <= 1.0))
        return make_error("replay '", path, "': line ", std::to_string(line_no), ": column 'force_scale': '", cell,
                          "' is not a number from 0 to 1");
    }
    if (scheduled) {
      r.scheduled = true;
      for (const auto& [c, out, low] : {std::tuple{ctick, &r.tick, int64_t{0}}, {cf, &r.frame, int64_t{-1}},
                                        {cmf, &r.model_frame, int64_t{-1}}}) {
        const std::string& cell = cells[static_cast<std::size_t>(c)];
        char* end = nullptr;
        errno = 0;
        const long long n = std::strtoll(cell.c_str(), &end, 10);
        if (cell.empty() || errno != 0 || end != cell.c_str() + cell.size() || n < low)
          return make_error("replay '", path, "': line ", std::to_string(line_no), ": column '",
                            head[static_cast<std::size_t>(c)], "': '", cell, "' is not a whole number of at least ",
                            std::to_string(low));
        *out = n;
      }
    }
    r.line = line_no;
    if (controlled) {
      auto whole = [&](int c, int64_t lo, int64_t hi, int64_t* out) {
        const std::string& cell = cells[static_cast<std::size_t>(c)];
        char* end = nullptr;
        errno = 0;
        const long long n = std::strtoll(cell.c_str(), &end, 10);
        if (cell.empty() || errno != 0 || end != cell.c_str() + cell.size() || n < lo || n > hi) return false;
        *out = n;
        return true;
      };
      int64_t seq = 0, mode = 0, resets = 0;
      double k = 0.0, radius = 0.0;
      const char* bad = !whole(cc, 0, INT64_MAX, &seq)                                                   ? "controls"
                        : !whole(cmode, 0, 2, &mode)                                                     ? "mode"
                        : !to_double(cells[static_cast<std::size_t>(ck)], &k) || !(k > 0.0 && k <= 1e3) ? "stiffness_scale"
                        : !to_double(cells[static_cast<std::size_t>(crad)], &radius) || !(radius >= 0.0 && radius <= 1.0)
                            ? "tool_radius_m"
                        : !whole(cres, 0, INT64_MAX, &resets) ? "resets"
                                                              : nullptr;
      if (bad) {
        const int c = col(bad);
        return make_error("replay '", path, "': line ", std::to_string(line_no), ": column '", bad, "': '",
                          cells[static_cast<std::size_t>(c)], "' is not a valid value");
      }
      if (!rows.empty() && seq < rows.back().controls.seq)
        return make_error("replay '", path, "': line ", std::to_string(line_no), ": column 'controls' goes back from ",
                          std::to_string(rows.back().controls.seq), " to ", std::to_string(seq));
      r.controls.seq = seq;
      r.controls.mode = static_cast<InteractionMode>(mode);
      r.controls.stiffness_scale = k;
      r.controls.tool_radius_m = radius;
      r.controls.resets = resets;
    }
    if (!rows.empty() && !(r.t_s > rows.back().t_s))
      return make_error("replay '", path, "': line ", std::to_string(line_no), ": t_s ", cells[static_cast<std::size_t>(ct)],
                        " does not increase");
    rows.push_back(r);
  }
  if (rows.empty()) return make_error("replay '", path, "': no rows");
  if (auto sch = replay_schedule(rows, {}, path); !sch) return sch.error();
  return rows;
}

Result<std::vector<ReplayRow>> load_haptic_csv(const std::string& path_in) {
  std::string path = path_in;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) path = (std::filesystem::path(path) / "haptic.csv").string();
  // only a regular file of bounded size: not /dev/zero, a FIFO or a log larger than any recording
  auto text = read_input_file(path, "replay", kMaxReplayFileBytes);
  if (!text) return text.error();
  return parse_haptic_csv(text.value(), path);
}

std::vector<int64_t> read_skipped_frames(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path dir =
      std::filesystem::is_directory(path, ec) ? std::filesystem::path(path) : std::filesystem::path(path).parent_path();
  auto text = read_input_file((dir / "summary.json").string(), "summary", kMaxReplayFileBytes);
  if (!text) return {};
  const auto j = nlohmann::json::parse(text.value(), nullptr, false);
  std::vector<int64_t> out;
  if (!j.is_object() || !j.contains("sim") || !j["sim"].is_object()) return out;
  const auto& s = j["sim"].value("skipped_frames", nlohmann::json::array());
  if (!s.is_array()) return out;
  for (const auto& f : s)
    if (f.is_number_integer()) out.push_back(f.get<int64_t>());
  return out;
}

Result<std::optional<RunSchedule>> replay_schedule(const std::vector<ReplayRow>& rows, const std::vector<int64_t>& skipped,
                                                   const std::string& path) {
  if (rows.empty() || !rows.front().scheduled) return std::optional<RunSchedule>();
  auto sch = make_run_schedule(schedule_ticks(rows), skipped, "replay '" + path + "'");
  if (!sch) return sch.error();
  return std::optional<RunSchedule>(std::move(sch).value());
}

ReplayDevice::ReplayDevice(const DeviceSpecs& specs, std::vector<ReplayRow> rows, std::optional<RunSchedule> schedule)
    : specs_(specs), rows_(std::move(rows)), schedule_(std::move(schedule)) {}

bool ReplayDevice::read(double t_s, DevicePose* out) noexcept {
  // rows are at tick times printed to 1 us: a row belongs to t_s when within half a microsecond
  const double t = t_s + 5e-7;
  if (t < rows_[cursor_].t_s) cursor_ = 0;  // played backwards: restart the scan
  while (cursor_ + 1 < rows_.size() && rows_[cursor_ + 1].t_s <= t) ++cursor_;
  const ReplayRow& r = rows_[cursor_];
  out->pos_m = r.pos_m;
  out->orientation = Quat::Identity();
  out->buttons = r.buttons;
  out->force_scale = r.force_scale;  // the recorded driver's fade, as it scaled that tick's force
  out->controls = r.controls;        // what the recording's person had set by that tick
  return !r.rejected;
}

}  // namespace palpate
