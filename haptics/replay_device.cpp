#include "haptics/replay_device.h"

#include "core/input_file.h"
#include "core/limits.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

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
    if (!rows.empty() && !(r.t_s > rows.back().t_s))
      return make_error("replay '", path, "': line ", std::to_string(line_no), ": t_s ", cells[static_cast<std::size_t>(ct)],
                        " does not increase");
    rows.push_back(r);
  }
  if (rows.empty()) return make_error("replay '", path, "': no rows");
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

ReplayDevice::ReplayDevice(const DeviceSpecs& specs, std::vector<ReplayRow> rows) : specs_(specs), rows_(std::move(rows)) {}

bool ReplayDevice::read(double t_s, DevicePose* out) noexcept {
  // rows are at tick times printed to 1 us: a row belongs to t_s when within half a microsecond
  const double t = t_s + 5e-7;
  if (t < rows_[cursor_].t_s) cursor_ = 0;  // played backwards: restart the scan
  while (cursor_ + 1 < rows_.size() && rows_[cursor_ + 1].t_s <= t) ++cursor_;
  const ReplayRow& r = rows_[cursor_];
  out->pos_m = r.pos_m;
  out->orientation = Quat::Identity();
  out->buttons = r.buttons;
  return !r.rejected;
}

}  // namespace palpate
