#include "haptics/servo/cpu_steal.h"

#include <sys/resource.h>
#include <unistd.h>

#include <charconv>
#include <fstream>
#include <sstream>
#include <string>

namespace palpate {
namespace {

// The steal value (8th number after the label) of a /proc/stat cpu line; false when the line has fewer numbers.
bool steal_of_line(std::string_view rest, int64_t* steal) {
  int64_t v = 0;
  for (int i = 0; i < 8; ++i) {
    while (!rest.empty() && rest.front() == ' ') rest.remove_prefix(1);
    const auto [end, ec] = std::from_chars(rest.data(), rest.data() + rest.size(), v);
    if (ec != std::errc()) return false;
    rest.remove_prefix(static_cast<std::size_t>(end - rest.data()));
  }
  *steal = v;
  return true;
}

}  // namespace

Result<StealTicks> parse_proc_stat_steal(std::string_view text, int cpu) {
  StealTicks out;
  bool have_total = false;
  const std::string want = cpu >= 0 ? "cpu" + std::to_string(cpu) : std::string();
  while (!text.empty()) {
    const std::size_t nl = text.find('\n');
    const std::string_view line = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view() : text.substr(nl + 1);
    const std::size_t sp = line.find(' ');
    if (sp == std::string_view::npos) continue;
    const std::string_view label = line.substr(0, sp);
    if (label != "cpu" && (want.empty() || label != want)) continue;
    int64_t steal = 0;
    if (!steal_of_line(line.substr(sp), &steal))
      return make_error("/proc/stat: line \"", std::string(line.substr(0, 80)), "\" has no steal column (8th value)");
    if (label == "cpu") {
      out.total = steal;
      have_total = true;
    } else {
      out.cpu = steal;
    }
  }
  if (!have_total) return make_error("/proc/stat: no \"cpu\" line");
  return out;
}

Result<StealTicks> read_proc_stat_steal(int cpu) {
  std::ifstream in("/proc/stat");
  if (!in) return make_error("/proc/stat: cannot be read");
  std::ostringstream s;
  s << in.rdbuf();
  return parse_proc_stat_steal(s.str(), cpu);
}

double clock_ticks_ms(int64_t ticks) {
  static const long hz = sysconf(_SC_CLK_TCK);
  return static_cast<double>(ticks) * 1000.0 / static_cast<double>(hz > 0 ? hz : 100);
}

ThreadSwitches this_thread_switches() noexcept {
  rusage ru{};
  if (getrusage(RUSAGE_THREAD, &ru) != 0) return {};
  return {static_cast<int64_t>(ru.ru_nvcsw), static_cast<int64_t>(ru.ru_nivcsw)};
}

}  // namespace palpate
