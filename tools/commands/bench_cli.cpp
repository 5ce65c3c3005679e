#include "tools/commands/bench_cli.h"

#include <cstdio>
#include <memory>
#include <string>

#include "core/limits.h"
#include "core/rates.h"
#include "core/scene.h"
#include "tools/bench/bench_feel.h"
#include "tools/bench/bench_force.h"
#include "tools/bench/bench_loop.h"
#include "tools/bench/bench_mesh.h"
#include "tools/bench/bench_model.h"
#include "tools/bench/bench_png.h"
#include "tools/bench/bench_scale.h"
#include "tools/bench/bench_sim.h"
#include "tools/commands/cli_checks.h"
#include "tools/commands/hand_fuzz.h"
#include "tools/bench/plot.h"

namespace palpate {
namespace {

// Every benchmark's options, as parsed.
// a list default as the text the option shows and parses ("0.25", "0.45", ...)
std::vector<std::string> number_texts(const std::vector<double>& values) {
  std::vector<std::string> out;
  for (double v : values) out.push_back(CLI::detail::to_string(v));
  return out;
}

struct BenchArgs {
  BenchLoopOptions loop;
  BenchForceOptions force;
  BenchFeelOptions feel;
  HandFuzzOptions hands;
  std::string sim_scene;
  BenchSimOptions sim;
  std::string scale_scene = "scenes/bunny_pull_springs.json";
  BenchScaleOptions scale;
  bool scale_no_full = false;
  BenchModelOptions model;
  std::string model_integrator = integrator_name(BenchModelOptions{}.integrator);
  std::string poisson_model = name_of(BenchModelOptions{}.poisson_model);
  std::string model_contact = "prescribed";
  std::vector<std::string> poisson_text = number_texts(BenchModelOptions{}.poisson_ratios);
  std::vector<std::string> large_strain_text = number_texts(BenchModelOptions{}.large_strain_poisson_ratios);
  std::vector<std::string> adaptive_poisson_text{"none"};
  BenchPngOptions png;
  BenchMeshOptions mesh;
  CLI::App *loop_cmd = nullptr, *force_cmd = nullptr, *feel_cmd = nullptr, *sim_cmd = nullptr, *scale_cmd = nullptr, *model_cmd = nullptr,
           *png_cmd = nullptr, *mesh_cmd = nullptr;
};

void add_loop(CLI::App* bench, BenchArgs& a) {
  auto* c = a.loop_cmd = bench->add_subcommand("loop", "Servo loop timing alone or beside the sim / record pipeline");
  BenchLoopOptions& lo = a.loop;
  c->add_option("--scene", lo.scene, "Scene whose device, model and pipeline are used")->capture_default_str();
  c->add_option("--rate", lo.rate_hz, "Servo rate in Hz (default: the scene's servo.rate_hz)")
      ->check(finite_range(100.0, 50000.0));
  c->add_option("--seconds", lo.seconds, "Seconds per run")->check(finite_range(0.1, 3600.0))->capture_default_str();
  c->add_option("--load", lo.load, "none | sim | record")->check(CLI::IsMember({"none", "sim", "record"}))
      ->capture_default_str();
  c->add_option("--spin-us", lo.spin_us,
                "Spin this many us before each deadline (default: adaptive, following how late the sleep returns)")
      ->check(CLI::Range(0, 1000));
  c->add_option("--spin-compare", lo.spin_compare, "Fixed windows (us) also run at each rate, side by side")
      ->delimiter(',')->check(CLI::Range(0, 1000));
  c->add_option("--priority", lo.priority, "SCHED_FIFO priority, 0 = normal scheduling")->check(CLI::Range(0, 99))
      ->capture_default_str();
  c->add_flag("--sweep", lo.sweep,
              "Try 1, 2, 5 and 10 kHz; report the highest rate such that it and every lower rate had no overruns");
  c->add_flag("--live", lo.live,
              "With --load record: each run again with the live view served and a client fetching it as the page "
              "does (rows side by side)");
  c->add_option("--json", lo.json_path, "Write the figures (with the latency histogram) as JSON");
  c->add_option("--plot", lo.plot_path, "Draw the wake-latency histogram (log-log) with gnuplot: FILE.png, "
                "its data FILE.dat and script FILE.gp");
}

void add_force(CLI::App* bench, BenchArgs& a) {
  auto* c = a.force_cmd = bench->add_subcommand(
      "force", "Force between sim frames against a reference stepped at the servo rate (per force model)");
  c->add_option("scenes", a.force.scenes, "Scenes to replay in lockstep")->capture_default_str();
  c->add_option("--json", a.force.json_path, "Write the figures as JSON");
}

void add_feel(CLI::App* bench, BenchArgs& a) {
  auto* c = a.feel_cmd = bench->add_subcommand("feel", "What the hand feels: force steps per tick against the device's "
                                               "motion, ripple, event steps, buzz above 100 Hz (lockstep)");
  c->add_option("scenes", a.feel.scenes, "Scenes (default: every shipped scene)");
  c->add_option("--json", a.feel.json_path, "Write the figures as JSON");
  c->add_option("--plot", a.feel.plot_path, "Force traces with gnuplot: FILE.png (and FILE_spectrum.png, the spectra), "
                "their data FILE.dat and scripts FILE.gp");
  c->add_option("--step-threshold", a.feel.step_threshold_N, "Steps counted above this (N)")
      ->check(finite_range(0.0, 100.0))
      ->capture_default_str();
  c->add_option("--device", a.feel.device,
                "The hand: scripted (the scene's script) or replay:PATH (a recorded haptic.csv or its folder, e.g. a "
                "browser or device session recorded in realtime, replayed in lockstep on the scene it was recorded from)")
      ->capture_default_str();
  c->add_option("--duration", a.feel.duration_s, "Scene seconds (default: the scene's, or the replayed log's length)")
      ->check(finite_range(0.001, 86400.0));
  c->add_option("--hands", a.hands.hands,
                "N seeded random hands per model (the arguments are then mesh files): presses to the force limit, "
                "strokes at 1-200 mm/s, lift-offs, pulls shaken sideways, blade passes; point and sphere tools, soft "
                "and stiff materials. Reports proxy crossings, wild steps, flips, buzz, energy, NaN per hand and model")
      ->check(CLI::Range(1, 100000));
  c->add_option("--force-shading", a.feel.force_shading_deg,
                "Every scene's or hand's device.force_shading_deg: faces meeting at less than this many degrees are "
                "felt as one smooth surface (0: as facets)")
      ->check(finite_range(0.0, 180.0));
  c->add_option("--seed", a.hands.seed, "With --hands: the first hand's seed (hand i is seed + i)")->capture_default_str();
  c->add_option("--keep", a.hands.keep_dir, "With --hands: write the scene of every hand that fails into this folder");
}

void add_sim(CLI::App* bench, BenchArgs& a) {
  auto* c = a.sim_cmd =
      bench->add_subcommand("sim", "Speed against error per integrator x level x substeps/iterations (lockstep)");
  BenchSimOptions& so = a.sim;
  c->add_option("scene", a.sim_scene, "Scene whose interaction is replayed, e.g. scenes/bunny_pull.json")->required();
  c->add_option("--json", so.json_path, "Write the rows as JSON");
  c->add_option("--plot", so.plot_path, "Plot node error against ms per frame (log axes, Pareto front) "
                "with gnuplot: FILE.png, its data FILE.dat and script FILE.gp");
  c->add_option("--integrators", so.integrators, "Integrators to sweep (default: all)")->delimiter(',');
  c->add_option("--levels", so.levels, "Lattice levels to sweep (default: the scene's)")->delimiter(',')
      ->check(CLI::Range(1, kMaxGridLevels));
  c->add_option("--substeps", so.substeps, "Substeps per frame to sweep, 0 = automatic")->delimiter(',')
      ->check(CLI::Range(0, kMaxSubsteps))->capture_default_str();
  c->add_option("--iterations", so.iterations, "Newton / local-global iterations to sweep, 0 = default")
      ->delimiter(',')->check(CLI::Range(0, kMaxIterations))->capture_default_str();
  c->add_option("--ref-substeps", so.reference_substeps, "RK4 substeps per frame of the reference")
      ->check(CLI::Range(2, kMaxSubsteps))->capture_default_str();
  c->add_option("--duration", so.duration_s, "Scene seconds to replay (overrides the scene)")
      ->check(finite_range(Rates{}.frame_period_s(), 3600.0));
  c->add_option("--box", so.box_cells, "Box lattices of N cells per axis (powers of two) instead of the replay, "
                "e.g. 4,8,16 = 125, 729, 4913 nodes")->delimiter(',')->check(CLI::Range(1, 128));
  c->add_flag("--quiet,-q", so.quiet, "No progress lines");
}

void add_scale(CLI::App* bench, BenchArgs& a) {
  auto* c = a.scale_cmd = bench->add_subcommand(
      "scale", "Record a scene on its model subdivided 0..N times, cached layer beside full redraw (lockstep; "
               "about 1.6 min with the defaults here, progress on stderr)");
  BenchScaleOptions& sco = a.scale;
  c->add_option("scene", a.scale_scene, "Scene whose interaction is recorded")->capture_default_str();
  c->add_option("--max-subdivisions", sco.max_subdivisions,
                "Largest midpoint subdivision (bunny: 0 = 3.7k, 1 = 14.7k, 2 = 58.8k, 3 = 235k, 4 = 940k, 5 = 3.76M, "
                "6 = 15.0M triangles; as many as the machine's memory holds)")
      ->check(CLI::Range(0, 7))->capture_default_str();
  c->add_option("--duration", sco.duration_s, "Scene seconds to record (overrides the scene)")
      ->check(finite_range(Rates{}.frame_period_s(), 3600.0));
  c->add_flag("--no-full", a.scale_no_full, "Skip the full-redraw runs beside the cached-layer ones");
  c->add_option("--json", sco.json_path, "Write the rows as JSON");
  c->add_option("--plot", sco.plot_path, "Plot ms per frame against triangles (log-log) with gnuplot: "
                "FILE.png, its data FILE.dat and script FILE.gp");
  c->add_flag("--quiet,-q", sco.quiet, "No progress lines");
}

void add_model(CLI::App* bench, BenchArgs& a) {
  auto* c = a.model_cmd = bench->add_subcommand(
      "model", "Model error against closed-form continuum references per lattice level, each run to rest by the "
               "simulation, beside ms per frame (about 6 min with the defaults on an idle 2-core machine, every nu and the "
               "40 mm pull rows included; --references hertz --poisson none --large-strain none is the quick look; "
               "progress on stderr)");
  c->alias("material");
  BenchModelOptions& mo = a.model;
  c->add_option("--levels", mo.levels, "Lattice levels (the cantilever runs from 4)")->delimiter(',')
      ->check(CLI::Range(2, 7))->capture_default_str();
  c->add_option("--young-modulus", mo.young_modulus_Pa, "E in Pa")->check(finite_range(1.0, 1e12))->capture_default_str();
  c->add_option("--damping", mo.stiffness_damping_s, "Rayleigh beta in s (how fast the runs come to rest)")
      ->check(finite_range(0.0, 10.0))->capture_default_str();
  c->add_option("--references", mo.references, "Which references: compression, cantilever, hertz, pull, hertz-solved (the contact solved under the "
                "sphere at two depths, not in the default), none")->delimiter(',')
      ->capture_default_str();
  c->add_option("--integrator", a.model_integrator, "Integrator that steps every run to rest")->capture_default_str();
  c->add_option("--poisson", a.poisson_text, "Poisson ratios of the material.model 'volumetric' rows, each in "
                "[0, 0.49] (none: --poisson none)")->delimiter(',')->capture_default_str();
  c->add_option("--large-strain", a.large_strain_text, "Poisson ratios of the material.model "
                "'neo_hookean' rows: 30 % compression against the closed form, 40 mm pull against Richardson "
                "extrapolation over --pull-levels, each in [0, 0.49] (none: --large-strain none)")->delimiter(',')->capture_default_str();
  c->add_option("--pull-levels", mo.pull_levels, "Three consecutive levels of the 40 mm pull (Richardson)")
      ->delimiter(',')->check(CLI::Range(3, 7))->capture_default_str();
  c->add_option("--poisson-model", a.poisson_model, "material.model of those rows (and of --adaptive-poisson's): "
                "volumetric or neo_hookean")
      ->capture_default_str();
  c->add_option("--poisson-level", mo.poisson_level, "Level of those rows' cantilever and Hertz")
      ->check(CLI::Range(4, 7))->capture_default_str();
  c->add_option("--compression-max-level", mo.compression_max_level, "Highest level of the compression rows (uniform "
                "strain is exact at every level; 6 adds about 15 s)")->check(CLI::Range(2, 7))->capture_default_str();
  c->add_option("--adaptive", mo.adaptive_levels, "Coarse levels of the 'adaptive vs uniform' Hertz rows: the lattice "
                "refined to --adaptive-fine near the tool, beside the uniform coarse and fine levels (0: none)")
      ->delimiter(',')->check(CLI::Range(0, 6))->capture_default_str();
  c->add_option("--adaptive-fine", mo.adaptive_fine_level, "Fine level of those rows")->check(CLI::Range(3, 7))
      ->capture_default_str();
  c->add_option("--adaptive-radius", mo.adaptive_radius_m, "Cells closer than this to the contact (twice this into "
                "the body) are split to --adaptive-fine, coarser rings within twice the next one's reach (m)")
      ->check(finite_range(1e-4, 0.1))->capture_default_str();
  c->add_option("--adaptive-poisson", a.adaptive_poisson_text, "Poisson ratios of more such rows, material.model "
                "--poisson-model (beside the springs ones), each in [0, 0.49] (none: springs only)")
      ->delimiter(',')->capture_default_str();
  c->add_flag_callback("--adaptive-no-fine", [&mo] { mo.adaptive_uniform_fine = false; }, "Leave out the uniform "
                       "fine level beside the adaptive rows (most of their time: uniform level 6 runs about 190 ms a frame)");
  c->add_option("--contact", a.model_contact, "How the 'hertz' rows' sphere loads the lattice: prescribed "
                "(Hertz's pressure) or solved (where the surface, deformed by the push, meets the sphere: Hertz only the "
                "check; device.contact; the adaptive rows too)")->check(CLI::IsMember({"prescribed", "solved"}))->capture_default_str();
  c->add_option("--solved-adaptive", mo.solved_adaptive_levels, "Coarse levels of graded hertz-solved rows (springs): "
                "the block graded from each to every --solved-fine level near the contact (none: empty)")
      ->delimiter(',')->check(CLI::Range(3, 7));
  c->add_option("--solved-fine", mo.solved_fine_levels, "Fine levels of those rows")->delimiter(',')
      ->check(CLI::Range(4, 8))->capture_default_str();
  c->add_option("--solved-zone", mo.solved_zone, "Their fine zone's radius in contact radii sqrt(R d) (twice that into "
                "the body, coarser rings within twice the next one's)")->check(finite_range(0.1, 20.0))->capture_default_str();
  c->add_option("--solved-block-scale", mo.solved_block_scale, "Every hertz-solved block this many times 8 x 8 x 4 cm, "
                "same cells: 1, 2 or 4 (the held floor and sides further away)")->check(CLI::IsMember({1, 2, 4}))
      ->capture_default_str();
  c->add_option("--press", mo.press_scene, "Also solve this scene's tool press (the tool a rigid sphere of its radius, "
                "the contact found from the lattice's deformation) at --press-levels");
  c->add_option("--press-levels", mo.press_levels, "Lattice levels of that press")->delimiter(',')
      ->check(CLI::Range(2, 6))->capture_default_str();
  c->add_option("--press-young-modulus", mo.press_young_modulus_Pa, "E of that press in Pa (0: the scene's)")
      ->check(finite_range(0.0, 1e12))->capture_default_str();
  c->add_option("--json", mo.json_path, "Write the rows as JSON");
  c->add_option("--plot", mo.plot_path, "Plot force error against ms per frame (log-log) as PNG");
}

void add_png(CLI::App* bench, BenchArgs& a) {
  auto* c = a.png_cmd = bench->add_subcommand(
      "png", "PNG encoders side by side on a recording's frames (ms per frame, size, lossless check)");
  BenchPngOptions& po = a.png;
  c->add_option("folder", po.folder, "Recording folder (frames/frame_*.png), e.g. out/bunny_pull (default with "
                "--record: the last recording made)");
  c->add_option("--record", po.record, "Also record this lockstep scene with each frame writer (zlib RGBA / RGB, "
                "libdeflate RGB, 1 and 2 threads) in turn, --reps times: wall per scene-second and state hashes "
                "(about 47 s for scenes/bunny_pull.json here, a line per pass on stderr)");
  c->add_option("--out,-o", po.out_dir, "Folder for the --record recordings")->capture_default_str();
  c->add_option("--frames", po.frames, "Frames used, spread over the recording")->check(CLI::Range(1, 100000))
      ->capture_default_str();
  c->add_option("--reps", po.repetitions, "Passes over the frames")->check(CLI::Range(1, 1000))->capture_default_str();
  c->add_option("--json", po.json_path, "Write the rows as JSON");
}

void add_mesh(CLI::App* bench, BenchArgs& a) {
  auto* c = a.mesh_cmd = bench->add_subcommand("mesh", "Mesh loading with the reader in a child process against in "
                                               "this process, alternately (median and fastest ms, ratio)");
  c->add_option("files", a.mesh.files, "Valid mesh files (e.g. scenes/bunny.obj)")->required();
  c->add_option("--reps", a.mesh.repetitions, "Loads per way and file")->check(CLI::Range(1, 1000))
      ->capture_default_str();
}

// Runs the benchmark the command line chose: the table (and any JSON) first; the plot is drawn after, so a missing
// gnuplot loses neither.
int run_bench(BenchArgs& a) {
  // the default scenes are found from any folder, not only the repository root
  if (*a.loop_cmd && a.loop_cmd->get_option("--scene")->count() == 0) a.loop.scene = locate_default(a.loop.scene);
  if (*a.force_cmd && a.force_cmd->get_option("scenes")->count() == 0)
    for (auto& s : a.force.scenes) s = locate_default(s);
  if (*a.scale_cmd && a.scale_cmd->get_option("scene")->count() == 0) a.scale_scene = locate_default(a.scale_scene);
  if (*a.loop_cmd) return run_bench_loop(a.loop);
  if (*a.force_cmd) return run_bench_force(a.force);
  if (*a.feel_cmd) {
    // the random hands make their own scenes and devices; options of the scripted runs do not apply to them
    const bool hands = a.feel_cmd->get_option("--hands")->count() > 0;
    for (const char* opt : {"--device", "--plot", "--duration"})
      if (hands && a.feel_cmd->get_option(opt)->count() > 0) {
        std::fprintf(stderr, "palpate: bench feel: %s does not apply with --hands (each hand is a scripted scene of its "
                     "own)\n", opt);
        return 2;
      }
    for (const char* opt : {"--seed", "--keep"})
      if (!hands && a.feel_cmd->get_option(opt)->count() > 0) {
        std::fprintf(stderr, "palpate: bench feel: %s needs --hands N\n", opt);
        return 2;
      }
  }
  if (*a.feel_cmd && a.feel_cmd->get_option("--hands")->count() > 0) {
    a.hands.models = a.feel.scenes;
    a.hands.json_path = a.feel.json_path;
    a.hands.step_threshold_N = a.feel.step_threshold_N;
    a.hands.force_shading_deg = a.feel.force_shading_deg;
    return run_hand_fuzz(a.hands);
  }
  if (*a.feel_cmd) {
    if (a.feel.scenes.empty()) a.feel.scenes_dir = locate_default(a.feel.scenes_dir);
    return run_bench_feel(a.feel);
  }
  if (*a.model_cmd && !integrator_from_name(a.model_integrator, &a.model.integrator)) {
    std::fprintf(stderr, "palpate: bench model: --integrator '%s' is not one of: explicit_euler, symplectic_euler, "
                 "implicit_euler, local_global, rk4\n", a.model_integrator.c_str());
    return 2;
  }
  if (*a.model_cmd) {
    const auto pm = from_name<MaterialModel>(a.poisson_model);
    if (!pm || *pm == MaterialModel::kSprings) {
      std::fprintf(stderr, "palpate: bench model: --poisson-model '%s' is not one of: volumetric, neo_hookean\n",
                   a.poisson_model.c_str());
      return 2;
    }
    a.model.poisson_model = *pm;
    a.model.solved_contact = a.model_contact == "solved";
    std::string bad;
    if (!parse_number_list(a.poisson_text, "--poisson", 0.0, 0.49, &a.model.poisson_ratios, &bad) ||
        !parse_number_list(a.large_strain_text, "--large-strain", 0.0, 0.49, &a.model.large_strain_poisson_ratios,
                           &bad) ||
        !parse_number_list(a.adaptive_poisson_text, "--adaptive-poisson", 0.0, 0.49, &a.model.adaptive_poisson_ratios,
                           &bad)) {
      std::fprintf(stderr, "palpate: bench model: %s\n", bad.c_str());
      return 2;
    }
  }
  a.scale.full_redraw = !a.scale_no_full;
  PlotSpec plot;
  std::string plot_path;
  Result<std::string> table = std::string();
  if (*a.scale_cmd) {
    table = run_bench_scale(a.scale_scene, a.scale, &plot);
    plot_path = a.scale.plot_path;
  } else if (*a.model_cmd) {
    table = run_bench_model(a.model, &plot);
    plot_path = a.model.plot_path;
  } else if (*a.png_cmd) {
    table = run_bench_png(a.png);
  } else if (*a.mesh_cmd) {
    table = run_bench_mesh(a.mesh);
  } else if (a.sim.box_cells.empty()) {
    table = run_bench_sim(a.sim_scene, a.sim, &plot);
    plot_path = a.sim.plot_path;
  } else {
    table = run_bench_sim_box(a.sim_scene, a.sim);
  }
  if (!table) {
    std::fprintf(stderr, "palpate: %s\n", table.error().message.c_str());
    return 1;
  }
  std::fputs(table.value().c_str(), stdout);
  return plot_path.empty() ? 0 : write_plot_and_report(plot, plot_path);
}

}  // namespace

Subcommand add_bench_command(CLI::App& app) {
  auto a = std::make_shared<BenchArgs>();
  auto* bench = app.add_subcommand("bench", "Benchmarks: figures as tables, JSON and plots");
  bench->require_subcommand(1);
  add_loop(bench, *a);
  add_force(bench, *a);
  add_feel(bench, *a);
  add_sim(bench, *a);
  add_scale(bench, *a);
  add_model(bench, *a);
  add_png(bench, *a);
  add_mesh(bench, *a);
  return {bench, [a] { return run_bench(*a); }};
}

}  // namespace palpate
