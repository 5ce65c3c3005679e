#include "tools/bench/plot.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <thread>

#include "core/atomic_file.h"

extern char** environ;

namespace palpate {
namespace {

namespace fs = std::filesystem;

// Shortest text that reads back as the same double (what the JSON outputs print, too).
std::string number(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

// One line of text: control characters become spaces.
std::string one_line(std::string s) {
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  return s;
}

// A gnuplot single-quoted string: no escapes are processed inside, a quote is written twice.
std::string quoted(const std::string& s) {
  std::string q = "'";
  for (char c : one_line(s)) {
    q += c;
    if (c == '\'') q += '\'';
  }
  return q + "'";
}

// A column name for the header: no spaces.
std::string column(std::string s) {
  for (char& c : s)
    if (static_cast<unsigned char>(c) <= 0x20 || c == 0x7f) c = '_';
  return s.empty() ? "_" : s;
}

bool row_ok(const PlotSpec& spec, const PlotSeries& s, std::size_t i) {
  const double x = s.x[i], y = s.y[i];
  if (!std::isfinite(x) || !std::isfinite(y)) return false;
  if ((spec.log_x && x <= 0) || (spec.log_y && y <= 0)) return false;
  return s.style != PlotStyle::kBoxes || (i < s.width.size() && std::isfinite(s.width[i]) && s.width[i] > 0);
}

std::size_t rows_of(const PlotSeries& s) { return std::min(s.x.size(), s.y.size()); }

bool has_points(const PlotSpec& spec, const PlotSeries& s) {
  for (std::size_t i = 0; i < rows_of(s); ++i)
    if (row_ok(spec, s, i)) return true;
  return false;
}

// gnuplot's error lines, short: the echo of the offending script line and its caret marker are dropped.
std::string summarise_stderr(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    lines.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  std::string out;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string& l = lines[i];
    if (l.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (l.find_first_not_of(" \t^") == std::string::npos) continue;  // the caret marker
    if (i + 1 < lines.size() && !lines[i + 1].empty() && lines[i + 1].find_first_not_of(" \t^") == std::string::npos)
      continue;  // the echoed script line above a caret
    if (!out.empty()) out += " / ";
    out += one_line(l.substr(l.find_first_not_of(" \t")));
  }
  if (out.size() > 400) out = out.substr(0, 400) + " ...";
  return out;
}

std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", s);
  return buf;
}

}  // namespace

Result<PlotPaths> plot_paths(const std::string& png_path) {
  const fs::path p(png_path);
  if (p.extension() != ".png" || p.stem().empty())
    return make_error("plot '", png_path, "': name it FILE.png (FILE.dat and FILE.gp are written beside it)");
  PlotPaths out;
  out.png = png_path;
  out.data = fs::path(p).replace_extension(".dat").string();
  out.script = fs::path(p).replace_extension(".gp").string();
  return out;
}

Status check_plot_targets(const std::string& png_path) {
  if (auto st = check_output_target(png_path, "plot"); !st) return st;
  auto paths = plot_paths(png_path);
  if (!paths) return paths.error();
  if (auto st = check_output_target(paths.value().data, "plot data"); !st) return st;
  return check_output_target(paths.value().script, "plot script");
}

std::string plot_data_text(const PlotSpec& spec) {
  std::string t = "# " + one_line(spec.title) + "\n";
  if (!spec.what.empty()) t += "# " + one_line(spec.what) + "\n";
  t += "# One block per series (gnuplot: index N), blocks separated by two blank lines.\n";
  int block = 0;
  for (const PlotSeries& s : spec.series) {
    if (!has_points(spec, s)) continue;
    t += "\n\n# series " + std::to_string(block++) + ": " + one_line(s.label) + "\n# columns: ";
    t += column(spec.x_column);
    t += ' ';
    t += column(spec.y_column);
    if (s.style == PlotStyle::kBoxes) t += " width";
    for (const PlotColumn& c : s.extra) {
      t += ' ';
      t += column(c.name);
    }
    t += '\n';
    for (std::size_t i = 0; i < rows_of(s); ++i) {
      if (!row_ok(spec, s, i)) continue;
      t += number(s.x[i]);
      t += ' ';
      t += number(s.y[i]);
      if (s.style == PlotStyle::kBoxes) {
        t += ' ';
        t += number(s.width[i]);
      }
      for (const PlotColumn& c : s.extra) {
        t += ' ';
        t += i < c.values.size() ? number(c.values[i]) : std::string("NaN");
      }
      t += '\n';
    }
  }
  return t;
}

std::string plot_script_text(const PlotSpec& spec, const std::string& data_name, const std::string& png_name) {
  std::string t;
  t += "# " + one_line(spec.title) + "\n";
  if (!spec.what.empty()) t += "# " + one_line(spec.what) + "\n";
  t += "# Drawn by palpate from " + one_line(data_name) + ". Restyle: edit this file, then run `gnuplot " +
       one_line(fs::path(png_name).replace_extension(".gp").filename().string()) + "`.\n";
  t += "# The data and the PNG are beside this script, wherever it is run from.\n";
  t += "slash(s, i) = i < 1 ? 0 : (s[i:i] eq '/' ? i : slash(s, i - 1))\n";
  t += "here = exists('ARG0') ? ARG0[1:slash(ARG0, strlen(ARG0))] : ''\n";
  t += "data = here." + quoted(data_name) + "\n\n";
  t += "set terminal pngcairo size " + std::to_string(spec.width) + "," + std::to_string(spec.height) +
       " enhanced font 'DejaVu Sans,11' linewidth 1.3 background '#ffffff'\n";
  t += "# palpate runs this with -e 'palpate_to_stdout = 1' and writes the PNG itself (atomically)\n";
  t += "if (!exists('palpate_to_stdout')) { set output here." + quoted(png_name) + " }\n\n";
  t += "set title " + quoted(spec.title) + " noenhanced font ',13'\n";
  t += "set xlabel " + quoted(spec.x_label) + " noenhanced\n";
  t += "set ylabel " + quoted(spec.y_label) + " noenhanced\n";
  for (const auto& [axis, log] : {std::pair{"x", spec.log_x}, std::pair{"y", spec.log_y}}) {
    if (log) t += std::string("set logscale ") + axis + " 10\nset format " + axis + " '10^{%L}'\n";
    else t += std::string("set format ") + axis + " '%g'\n";
  }
  if (spec.x_min > 0) t += "set xrange [" + number(spec.x_min) + ":*]\n";
  if (spec.y_min > 0) t += "set yrange [" + number(spec.y_min) + ":*]\n";
  t += "set border 3 lw 1.2\nset tics nomirror out\n";
  t += "set grid xtics ytics mxtics mytics back lt 1 lw 1 lc rgb '#d8d8d8', lt 1 lw 0.6 lc rgb '#efefef'\n";
  if (spec.key_outside) t += "set key outside right top vertical Left reverse spacing 1.2 samplen 2 width -3\n";
  else t += "set key " + spec.key + " opaque box lc rgb '#c0c0c0' spacing 1.15 samplen 2.5 width 1\n";
  t += "set style fill transparent solid 0.3 border\n\n";
  // bars and plain lines are drawn first, so markers sit on top of them
  std::vector<std::string> under, over;
  int block = 0;
  for (const PlotSeries& s : spec.series) {
    if (!has_points(spec, s)) continue;
    std::string c = "data index " + std::to_string(block++);
    const std::string colour = " lc rgb " + quoted(s.colour);
    const std::string pt = " pt " + std::to_string(s.point_type);
    const std::string dash = s.dashed ? " dt 2" : "";
    switch (s.style) {
      case PlotStyle::kPoints: c += " using 1:2 with points" + pt + " ps 1.1" + colour; break;
      case PlotStyle::kLines: c += " using 1:2 with lines lw 1.8" + dash + colour; break;
      case PlotStyle::kLinesPoints: c += " using 1:2 with linespoints lw 1.6" + dash + pt + " ps 1.2" + colour; break;
      case PlotStyle::kBoxes: c += " using 1:2:3 with boxes" + colour; break;
    }
    c += s.label.empty() ? " notitle" : " title " + quoted(s.label) + " noenhanced";
    (s.style == PlotStyle::kLines || s.style == PlotStyle::kBoxes ? under : over).push_back(c);
  }
  std::vector<std::string> clauses = under;
  clauses.insert(clauses.end(), over.begin(), over.end());
  t += "plot ";
  for (std::size_t i = 0; i < clauses.size(); ++i) t += (i ? ", \\\n     " : "") + clauses[i];
  t += "\n";
  return t;
}

Status render_with_gnuplot(const std::string& script_path, const std::string& png_path, double timeout_s) {
  auto opened = AtomicFile::open(png_path, "plot");
  if (!opened) return opened.error();
  AtomicFile& out = opened.value();
  auto fail = [&](const std::string& why) -> Status {
    out.discard();
    return make_error("plot '", png_path, "': ", why);
  };
  int err_pipe[2];
  if (::pipe2(err_pipe, O_CLOEXEC) != 0) return fail(std::string("cannot make a pipe for gnuplot: ") + std::strerror(errno));
  // gnuplot writes the PNG to its standard output, which is the temporary; its messages come back through the pipe
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&fa, fileno(out.stream()), 1);
  posix_spawn_file_actions_adddup2(&fa, err_pipe[1], 2);
  std::string a0 = "gnuplot", a1 = "-e", a2 = "palpate_to_stdout = 1", a3 = script_path;
  char* argv[] = {a0.data(), a1.data(), a2.data(), a3.data(), nullptr};
  pid_t pid = -1;
  const int rc = ::posix_spawnp(&pid, "gnuplot", &fa, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  ::close(err_pipe[1]);
  if (rc != 0) {
    ::close(err_pipe[0]);
    if (rc == ENOENT) return fail("gnuplot not found on PATH (install the Debian package gnuplot-nox)");
    return fail(std::string("cannot run gnuplot: ") + std::strerror(rc));
  }
  // its messages until it closes stderr (it exits), or the deadline
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  auto ms_left = [&] {
    return std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  };
  std::string messages;
  bool timed_out = false;
  for (;;) {
    const auto left = ms_left();
    if (left <= 0) {
      timed_out = true;
      break;
    }
    pollfd p{err_pipe[0], POLLIN, 0};
    const int n = ::poll(&p, 1, static_cast<int>(std::min<int64_t>(left, 1000)));
    if (n < 0 && errno == EINTR) continue;
    if (n == 0) continue;
    char buf[4096];
    const ssize_t k = ::read(err_pipe[0], buf, sizeof buf);
    if (k > 0) {
      if (messages.size() < 65536) messages.append(buf, static_cast<std::size_t>(k));
    } else if (k == 0 || errno != EINTR) {
      break;
    }
  }
  ::close(err_pipe[0]);
  int status = 0;
  while (!timed_out) {
    const pid_t w = ::waitpid(pid, &status, WNOHANG);
    if (w == pid || (w < 0 && errno != EINTR)) break;
    if (ms_left() <= 0) timed_out = true;
    else std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (timed_out) {
    ::kill(pid, SIGKILL);
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return fail("gnuplot did not finish within " + seconds_text(timeout_s) + " s and was stopped");
  }
  const std::string said = summarise_stderr(messages);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const std::string how = WIFEXITED(status) ? "exited with status " + std::to_string(WEXITSTATUS(status))
                                              : "was killed by signal " + std::to_string(WTERMSIG(status));
    return fail("gnuplot " + how + (said.empty() ? std::string() : ": " + said));
  }
  // what gnuplot wrote starts as a PNG (the temporary is write-only: read it through its name, never a link)
  unsigned char sig[8] = {};
  static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  const int rfd = ::open(out.temp_path().c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  const ssize_t got = rfd >= 0 ? ::pread(rfd, sig, sizeof sig, 0) : -1;
  if (rfd >= 0) ::close(rfd);
  if (got != static_cast<ssize_t>(sizeof sig) || std::memcmp(sig, kPng, sizeof sig) != 0)
    return fail("gnuplot exited without writing a PNG" + (said.empty() ? std::string() : ": " + said));
  return out.commit();
}

Status write_plot(const PlotSpec& spec, const std::string& png_path) {
  auto paths_r = plot_paths(png_path);
  if (!paths_r) return paths_r.error();
  const PlotPaths& paths = paths_r.value();
  bool any = false;
  for (const PlotSeries& s : spec.series) any = any || has_points(spec, s);
  if (!any) return make_error("plot '", png_path, "': no finite points to plot");
  if (auto st = write_file_atomic(paths.data, plot_data_text(spec), "plot data"); !st) return st;
  const std::string data_name = fs::path(paths.data).filename().string();
  const std::string png_name = fs::path(paths.png).filename().string();
  if (auto st = write_file_atomic(paths.script, plot_script_text(spec, data_name, png_name), "plot script"); !st) return st;
  if (auto st = render_with_gnuplot(paths.script, paths.png); !st)
    return make_error(st.error().message, "; ", paths.data, " and ", paths.script,
                      " are written: draw it later with `gnuplot ", paths.script, "`");
  return Ok{};
}

int write_plot_and_report(const PlotSpec& spec, const std::string& png_path) {
  if (auto st = write_plot(spec, png_path); !st) {
    std::fflush(stdout);
    std::fprintf(stderr, "palpate: %s\n", st.error().message.c_str());
    return 1;
  }
  const PlotPaths paths = plot_paths(png_path).value();
  std::printf("plot     %s (drawn by gnuplot from %s and %s; restyle: edit %s, then run `gnuplot %s`)\n",
              paths.png.c_str(), paths.data.c_str(), paths.script.c_str(), paths.script.c_str(), paths.script.c_str());
  std::fflush(stdout);
  return 0;
}

}  // namespace palpate
