// Bench plots drawn by gnuplot: the data file holds exactly the figures of the bench's JSON, the PNG is a real PNG
// of the requested size showing every series, the script redraws it from anywhere, and without gnuplot the table,
// JSON, data and script are all still there.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "render/png_io.h"
#include "support/cli_run.h"
#include "support/json_file.h"
#include "support/read_file.h"
#include "support/temp_root.h"
#include "tools/bench/plot.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

using test::CliRun;
using test::palpate;
using test::read_file;
using test::read_json;
using test::shell;

std::string tmp(const std::string& name) { return test::temp_path("plot_", name); }

std::string write(const std::string& name, const std::string& text) {
  const std::string path = tmp(name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// A small box pressed from above: a bench sim sweep of it takes about a second.
std::string box_scene() {
  return write("box.json", R"({"mesh": {"box_m": [0.06, 0.06, 0.06], "size_m": 0.06}, "trajectory": [
      {"t_s": 0, "pos_m": [0.004, 0.004, 0.045]}, {"t_s": 0.3, "pos_m": [0.004, 0.004, 0.012]}], "duration_s": 0.5})");
}

// One block of a plot data file: its series label, column names and rows.
struct Block {
  std::string label;
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
};

// Parses a data file as a reader would: "# series N: label", "# columns: ...", then rows of numbers.
std::vector<Block> read_data(const std::string& path) {
  std::ifstream f(path);
  EXPECT_TRUE(f.good()) << path;
  std::vector<Block> blocks;
  std::string line;
  while (std::getline(f, line)) {
    if (line.rfind("# series ", 0) == 0) {
      blocks.push_back({line.substr(line.find(": ") + 2), {}, {}});
    } else if (line.rfind("# columns: ", 0) == 0) {
      EXPECT_FALSE(blocks.empty()) << line;
      std::istringstream in(line.substr(11));
      for (std::string c; in >> c;) blocks.back().columns.push_back(c);
    } else if (!line.empty() && line[0] != '#') {
      EXPECT_FALSE(blocks.empty()) << line;
      std::vector<double> row;
      std::istringstream in(line);
      for (std::string v; in >> v;) row.push_back(std::strtod(v.c_str(), nullptr));
      EXPECT_EQ(row.size(), blocks.back().columns.size()) << line;
      blocks.back().rows.push_back(row);
    }
  }
  return blocks;
}

// The block with this label; an empty one (no label, no rows) when there is none.
Block find_block(const std::vector<Block>& blocks, const std::string& label) {
  for (const Block& b : blocks)
    if (b.label == label) return b;
  return {};
}

// Pixels within 3 levels of a colour "#rrggbb": the inside of a marker or a bar's border.
int pixels_of(const Image& im, const std::string& hex) {
  const int r = std::stoi(hex.substr(1, 2), nullptr, 16), g = std::stoi(hex.substr(3, 2), nullptr, 16),
            b = std::stoi(hex.substr(5, 2), nullptr, 16);
  int n = 0;
  for (std::size_t i = 0; i + 3 < im.rgba.size(); i += 4)
    n += std::abs(im.rgba[i] - r) <= 3 && std::abs(im.rgba[i + 1] - g) <= 3 && std::abs(im.rgba[i + 2] - b) <= 3;
  return n;
}

Image expect_png(const std::string& path, int width, int height) {
  auto im = read_png(path);
  EXPECT_TRUE(im.ok()) << (im.ok() ? "" : im.error().message);
  if (!im.ok()) return {};
  EXPECT_EQ(im.value().width, width);
  EXPECT_EQ(im.value().height, height);
  return im.value();
}

std::string stem(const std::string& png) { return png.substr(0, png.size() - 4); }

TEST(Plot, BenchSimDataMatchesItsJsonAndThePngShowsEveryIntegrator) {
  const std::string scene = box_scene(), json = tmp("sim.json"), png = tmp("sim.png");
  const CliRun r = palpate("bench sim " + scene + " -q --substeps 0,2 --json " + json + " --plot " + png);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("restyle: edit " + stem(png) + ".gp, then run `gnuplot " + stem(png) + ".gp`"), std::string::npos)
      << r.out;
  const auto j = read_json(json);
  const auto blocks = read_data(stem(png) + ".dat");
  // every stable row is a point of its integrator's series, with the JSON's figures to the last bit
  std::size_t stable = 0, points = 0;
  for (const auto& row : j["rows"]) {
    if (!row["stable"].get<bool>()) continue;
    ++stable;
    const Block b = find_block(blocks, row["integrator"].get<std::string>());
    ASSERT_FALSE(b.label.empty()) << row["integrator"];
    ASSERT_EQ(b.columns, (std::vector<std::string>{"frame_ms_p50", "node_error_rms_cell", "level", "substeps",
                                                    "iterations"}));
    int found = 0;
    for (const auto& p : b.rows)
      if (p[2] == row["level"].get<double>() && p[3] == row["substeps"].get<double>() &&
          p[4] == row["iterations"].get<double>()) {
        ++found;
        EXPECT_EQ(p[0], row["frame_ms"]["p50"].get<double>());
        EXPECT_EQ(p[1], std::max(row["node_error_cell"]["rms"].get<double>(), 1e-12));
      }
    EXPECT_EQ(found, 1) << row.dump();
  }
  for (const Block& b : blocks)
    if (b.label.rfind("Pareto", 0) != 0) points += b.rows.size();
  EXPECT_GE(stable, 4u);
  EXPECT_EQ(points, stable);  // and nothing else
  // the Pareto line runs through the rows the JSON marks, in order of cost
  const Block front = find_block(blocks, "Pareto front, level 4");
  ASSERT_FALSE(front.label.empty());
  std::vector<double> marked;
  for (const auto& row : j["rows"])
    if (row["pareto"].get<bool>()) marked.push_back(row["frame_ms"]["p50"].get<double>());
  std::sort(marked.begin(), marked.end());
  ASSERT_EQ(front.rows.size(), marked.size());
  for (std::size_t i = 0; i < marked.size(); ++i) EXPECT_EQ(front.rows[i][0], marked[i]);
  // an 800x500 PNG with every integrator's markers in its colour
  const Image im = expect_png(png, 800, 500);
  const std::map<std::string, std::string> colour{{"symplectic_euler", "#1e6ec8"}, {"implicit_euler", "#28963c"},
                                                  {"local_global", "#e68c14"}, {"rk4", "#823caa"}};
  for (const auto& [name, hex] : colour) {
    if (find_block(blocks, name).rows.empty()) continue;
    EXPECT_GT(pixels_of(im, hex), 8) << name << " not drawn";
  }
  EXPECT_FALSE(fs::exists(png + ".tmp"));
}

TEST(Plot, TheScriptRedrawsThePngFromAnyFolder) {
  const std::string scene = box_scene(), png = tmp("redraw.png");
  ASSERT_EQ(palpate("bench sim " + scene + " -q --integrators symplectic_euler,rk4 --plot " + png).code, 0);
  const std::string script = stem(png) + ".gp";
  // restyled: a larger figure, drawn by gnuplot alone from another folder
  std::string s = read_file(script);
  const std::string size = "size 800,500";
  ASSERT_NE(s.find(size), std::string::npos) << s;
  s.replace(s.find(size), size.size(), "size 1000,600");
  std::ofstream(script, std::ios::binary | std::ios::trunc) << s;
  fs::remove(png);
  const CliRun g = shell("cd / && gnuplot '" + script + "'");
  ASSERT_EQ(g.code, 0) << g.out;
  expect_png(png, 1000, 600);
}

TEST(Plot, BenchLoopHistogramIsTheJsonHistogram) {
  const std::string scene = box_scene(), json = tmp("loop.json"), png = tmp("loop.png");
  const CliRun r = palpate("bench loop --scene " + scene + " --seconds 0.3 --priority 0 --json " + json + " --plot " + png);
  ASSERT_EQ(r.code, 0) << r.out;
  const auto hist = read_json(json)["runs"][0]["latency_us"]["histogram_1us"];
  const auto blocks = read_data(stem(png) + ".dat");
  ASSERT_EQ(blocks.size(), 1u);
  EXPECT_EQ(blocks[0].columns, (std::vector<std::string>{"latency_us_bucket_centre", "ticks", "width"}));
  ASSERT_EQ(blocks[0].rows.size(), hist.size());
  for (std::size_t i = 0; i < hist.size(); ++i) {
    EXPECT_EQ(blocks[0].rows[i][0], hist[i][0].get<double>() + 0.5);  // bucket i holds [i, i+1) us
    EXPECT_EQ(blocks[0].rows[i][1], hist[i][1].get<double>());
    EXPECT_EQ(blocks[0].rows[i][2], 1.0);
  }
  const Image im = expect_png(png, 800, 500);
  EXPECT_GT(pixels_of(im, "#1f77b4"), 20);  // the bars' borders
}

TEST(Plot, BenchScaleSeriesAreTheJsonMedians) {
  const std::string json = tmp("scale.json"), png = tmp("scale.png");
  const CliRun r = palpate("bench scale scenes/bunny_touch.json --max-subdivisions 0 --duration 0.25 -q --json " + json +
                           " --plot " + png);
  ASSERT_EQ(r.code, 0) << r.out;
  const auto rows = read_json(json)["rows"];
  ASSERT_EQ(rows.size(), 2u);  // layered, full redraw
  const auto blocks = read_data(stem(png) + ".dat");
  ASSERT_EQ(blocks.size(), 4u);
  for (const auto& row : rows) {
    const bool full = row["full_redraw"].get<bool>();
    const Block render = find_block(blocks, full ? "render, full redraw" : "render, layered");
    ASSERT_EQ(render.rows.size(), 1u);
    EXPECT_EQ(render.rows[0][0], row["triangles"].get<double>());
    EXPECT_EQ(render.rows[0][1], row["render_ms"]["p50"].get<double>());
    if (full) continue;
    const Block sim = find_block(blocks, "sim"), wall = find_block(blocks, "wall ms per frame, layered");
    ASSERT_EQ(sim.rows.size(), 1u);
    ASSERT_EQ(wall.rows.size(), 1u);
    EXPECT_EQ(sim.rows[0][1], row["sim_ms"]["p50"].get<double>());
    EXPECT_DOUBLE_EQ(wall.rows[0][1], 1000.0 * row["wall_s_per_scene_s"].get<double>() / 60.0);
  }
  expect_png(png, 800, 500);
}

TEST(Plot, WithoutGnuplotTheTableJsonDataAndScriptAreStillWritten) {
  const std::string scene = box_scene(), json = tmp("nognu.json"), png = tmp("nognu.png");
  const std::string empty_dir = tmp("empty_path");
  fs::create_directories(empty_dir);
  const char* bin = std::getenv("PALPATE_BIN_DIR");
  const std::string exe = fs::absolute(std::string(bin ? bin : "build/bin") + "/palpate").string();
  const CliRun r = shell("PATH='" + empty_dir + "' " + exe + " bench sim " + scene +
                         " -q --integrators symplectic_euler --json " + json + " --plot " + png);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("palpate: plot '" + png + "': gnuplot not found on PATH (install the Debian package gnuplot-nox)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("draw it later with `gnuplot " + stem(png) + ".gp`"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("symplectic_euler    4 auto"), std::string::npos) << "the table is lost: " << r.out;
  EXPECT_EQ(read_json(json)["rows"].size(), 1u);
  EXPECT_EQ(read_data(stem(png) + ".dat").size(), 2u);  // the integrator and its front
  EXPECT_FALSE(fs::exists(png));
  EXPECT_FALSE(fs::exists(png + ".tmp"));
  // the deferred drawing works once gnuplot is there
  ASSERT_EQ(shell("gnuplot '" + stem(png) + ".gp'").code, 0);
  expect_png(png, 800, 500);
}

TEST(Plot, OutputsAreCheckedBeforeTheBenchRuns) {
  const std::string scene = box_scene();
  CliRun r = palpate("bench sim " + scene + " -q --plot " + tmp("figure.svg"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("palpate: plot '" + tmp("figure.svg") + "': name it FILE.png (FILE.dat and FILE.gp are written beside it)"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("symplectic_euler"), std::string::npos) << "ran anyway: " << r.out;
  // the box sweep has no figure: said before it runs, not skipped in silence after
  r = palpate("bench sim " + scene + " -q --box 2 --plot " + tmp("box.png"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("palpate: bench sim: --plot draws the scene replay's sweep; --box has no plot"), std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("symplectic_euler"), std::string::npos) << "ran anyway: " << r.out;
  EXPECT_FALSE(fs::exists(tmp("box.dat")));
  // a link where the data would go is never written through, and its target is untouched
  const std::string target = write("precious.txt", "keep me\n"), png = tmp("linked.png");
  fs::create_symlink(target, stem(png) + ".dat");
  r = palpate("bench loop --scene " + scene + " --seconds 0.1 --priority 0 --plot " + png);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("plot data '" + stem(png) + ".dat': is a symbolic link, not written through"), std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("rate_hz"), std::string::npos) << "ran anyway: " << r.out;
  std::ifstream in(target);
  std::string kept;
  std::getline(in, kept);
  EXPECT_EQ(kept, "keep me");
}

TEST(Plot, GnuplotFailureOrHangLeavesNoPng) {
  const std::string png = tmp("fail.png");
  // a script gnuplot refuses: its exit status and its message, no PNG and no temporary
  const std::string bad = write("bad.gp", "set terminal pngcairo size 300,200\nplot sin(x) with nonsense\n");
  auto st = render_with_gnuplot(bad, png);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("plot '" + png + "': gnuplot exited with status 1: "), std::string::npos)
      << st.error().message;
  EXPECT_NE(st.error().message.find("bad.gp\" line 2"), std::string::npos) << st.error().message;
  EXPECT_FALSE(fs::exists(png));
  EXPECT_FALSE(fs::exists(png + ".tmp"));
  // a script that never ends is stopped at the timeout
  const std::string slow = write("slow.gp", "set terminal pngcairo size 300,200\npause 60\nplot sin(x)\n");
  st = render_with_gnuplot(slow, png, 0.5);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().message, "plot '" + png + "': gnuplot did not finish within 0.5 s and was stopped");
  EXPECT_FALSE(fs::exists(png));
  EXPECT_FALSE(fs::exists(png + ".tmp"));
  // a PNG path that is a link is refused before gnuplot runs
  const std::string target = write("target.png", "not a png");
  fs::create_symlink(target, tmp("link.png"));
  const std::string good = write("good.gp", "set terminal pngcairo size 300,200\nplot sin(x)\n");
  st = render_with_gnuplot(good, tmp("link.png"));
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("is a symbolic link, not written through"), std::string::npos) << st.error().message;
  EXPECT_EQ(fs::file_size(target), 9u);
  // and the same script to a plain path makes a PNG of its size
  ASSERT_TRUE(render_with_gnuplot(good, tmp("good.png")).ok());
  expect_png(tmp("good.png"), 300, 200);
}

TEST(Plot, AnyTitleOrLabelIsDrawnVerbatimAtTheRequestedSize) {
  // quotes, underscores and carets would break a script or turn into sub/superscripts if not quoted
  PlotSpec spec;
  spec.width = 640;
  spec.height = 400;
  spec.title = "it's a_b^c {x} \"q\" \\n";
  spec.x_label = "x (µs)";
  spec.y_label = "y";
  PlotSeries s;
  s.label = "O'Brien_1";
  s.colour = "#ff0000";
  s.style = PlotStyle::kLinesPoints;
  s.x = {1, 10, 100, -1, std::nan("")};  // the last two cannot be drawn on log axes and are left out
  s.y = {2, 20, 5, 1, 1};
  spec.series = {s};
  const std::string png = tmp("quoted.png");
  ASSERT_TRUE(write_plot(spec, png).ok());
  expect_png(png, 640, 400);
  const auto blocks = read_data(stem(png) + ".dat");
  ASSERT_EQ(blocks.size(), 1u);
  EXPECT_EQ(blocks[0].label, "O'Brien_1");
  EXPECT_EQ(blocks[0].rows, (std::vector<std::vector<double>>{{1, 2}, {10, 20}, {100, 5}}));
  const std::string script = read_file(stem(png) + ".gp");
  EXPECT_NE(script.find("set title 'it''s a_b^c {x} \"q\" \\n' noenhanced"), std::string::npos) << script;
  // nothing to draw is an error before any file is written
  spec.series[0].x = {-1};
  spec.series[0].y = {1};
  auto st = write_plot(spec, tmp("empty.png"));
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().message, "plot '" + tmp("empty.png") + "': no finite points to plot");
  EXPECT_FALSE(fs::exists(tmp("empty.dat")));
}

}  // namespace
}  // namespace palpate
