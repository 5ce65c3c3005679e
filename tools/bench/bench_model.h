#pragma once
/// `palpate bench model`: the model's error against the continuum it stands for, per lattice level, beside what the
/// level costs — uniaxial compression (shortening = strain x side), a cantilever's tip deflection
/// (F L^3 / (3 E I)) and Hertz indentation by the sphere tool (F = 4/3 E* sqrt(R) d^(3/2)); at large strain 30 %
/// compression against the Neo-Hookean closed form and a 40 mm pull against Richardson extrapolation over levels. Every equilibrium is
/// the simulation's own: the lattice stepped by its integrator until it is at rest (sim/reference/settle.h); Hertz runs the
/// servo's sphere god-object and the frame stage with the device held still (runtime/session/tool_hold.h).

#include <string>
#include <vector>

#include "core/result.h"
#include "core/scene.h"
#include "sim/reference/hertz_reference.h"
#include "tools/bench/plot.h"

namespace palpate {

/// What to run. Plain data.
struct BenchModelOptions {
  std::vector<int> levels{3, 4, 5, 6};               ///< lattice levels (the cantilever needs >= 4: 1 cell across)
  int compression_max_level = 5;                     ///< compression rows stop here (uniform strain is exact at every level;
                                                     ///< level 6 costs 13 s for the same -5e-5)
  std::vector<std::string> references{"compression", "cantilever", "hertz", "pull"};  ///< which references to run
                                                     ///< (also "hertz-solved": the contact solved, opt-in)
  double young_modulus_Pa = 1e5;                     ///< E of every case
  double density_kg_per_m3 = 1070.0;                 ///< rho
  double stiffness_damping_s = 0.02;                 ///< Rayleigh beta: how fast each run comes to rest
  IntegratorKind integrator = IntegratorKind::kImplicitEuler;  ///< what steps every run to rest
  std::vector<double> poisson_ratios{0.0, 0.25, 0.4, 0.45, 0.49};  ///< material.model "volumetric" rows, one set per nu
  std::vector<double> large_strain_poisson_ratios{0.0, 0.25, 0.45, 0.49};  ///< material.model "neo_hookean" rows:
                                                     ///< 30 % compression, and the 40 mm pull
  std::vector<int> pull_levels{3, 4, 5};             ///< three consecutive levels of the pull (Richardson)
  MaterialModel poisson_model = MaterialModel::kVolumetric;  ///< material.model of those rows
  int poisson_level = 6;                             ///< level of those rows' cantilever and Hertz (compression: 4)
  std::vector<int> adaptive_levels{4, 5};            ///< coarse levels of the "adaptive vs uniform" Hertz rows (springs,
                                                     ///< nu 0.25, and adaptive_poisson_ratios): the lattice refined to
                                                     ///< adaptive_fine_level near the tool
  int adaptive_fine_level = 6;                       ///< the fine level of those rows (and the uniform level they aim at)
  double adaptive_radius_m = 0.004;                  ///< cells closer than this to the contact are split to the fine level
                                                     ///< (0.8 contact radii; twice as far into the body; coarser rings
                                                     ///< within twice the next one's radius: sim/lattice/graded_zone.h)
  bool adaptive_uniform_fine = true;                 ///< run the uniform fine level beside them (most of their time)
  bool solved_contact = false;                       ///< the "hertz" and adaptive rows' sphere loads the lattice where
                                                     ///< the contact puts it (device.contact "solved"), not by Hertz
  std::vector<double> adaptive_poisson_ratios;       ///< also those rows for material.model poisson_model at each nu
                                                     ///< (beside the springs ones); empty: springs only
  std::vector<int> solved_adaptive_levels;           ///< coarse levels of graded "hertz-solved" rows (springs; none: empty)
  std::vector<int> solved_fine_levels{7, 8};         ///< their fine levels, near the contact
  double solved_zone = 1.0;                          ///< their fine zone's radius over the contact radius sqrt(R d)
  int solved_block_scale = 1;                        ///< every hertz-solved block this many times 8 x 8 x 4 cm (1, 2, 4)
  std::string press_scene;                           ///< a scene whose tool press is solved per press_levels (tools/bench/
                                                     ///< bench_press.h); empty: none
  std::vector<int> press_levels{3, 4, 5};            ///< lattice levels of that press
  double press_young_modulus_Pa = 1e4;               ///< E of that press (0: the scene's)
  std::string json_path;                             ///< write the rows as JSON here when not empty
  std::string plot_path;                             ///< log-log plot of force error against ms per frame (PNG)
};

/// One Hertz indentation by the sphere tool.
struct HertzToolCheck {
  double force_N = 0.0;            ///< the coupling force at rest (its z component, pushing the device up)
  double depth_m = 0.0;            ///< how far the surface under the sphere's centre went down (Hertz's approach d)
  double sphere_depth_m = 0.0;     ///< the sphere's lowest point below the block's rest top (<= depth_m: where the
                                   ///< lattice's dimple is narrower than the sphere, the sphere rests on its rim)
  double closed_form_N = 0.0;      ///< 4/3 E* sqrt(R) depth_m^(3/2), E* = E / (1 - nu^2) (nu the lattice's)
  double rel_error = 0.0;          ///< force_N / closed_form_N - 1
  std::size_t nodes = 0, springs = 0;
  int force_nodes = 0;             ///< lattice nodes the contact force was spread over
  int64_t solved_frames = 0;       ///< frames loaded by the solved contact (device.contact "solved")
  int64_t frames = 0;              ///< sim frames to rest
  int64_t region_moves = 0;        ///< times the region (a refined lattice's fine zone) moved while at it
  double ms_per_frame_p50 = 0.0;   ///< frame stage thread CPU time per frame (median)
  double step_ms_p50 = 0.0;        ///< the integrator step alone, thread CPU per stepped frame (median)
  double cg_iterations_p50 = 0.0;  ///< conjugate gradient iterations per stepped frame (median; implicit Euler)
};

/// A block 8 x 8 x 4 cm of `material` (floor fixed) at lattice `level`, pressed by a sphere tool of radius 10 cm
/// whose device is held so the sphere goes about 0.25 mm deep (contact radius 5 mm), run until at rest; with
/// refine.level > 0 the lattice is refined near the tool (lattice.refine); solved_contact: the scene's
/// device.contact "solved" (the push goes where the surface meets the sphere, sim/contact/solved_contact.h).
Result<HertzToolCheck> check_hertz_tool(const MaterialSpec& material, int level, IntegratorKind integrator,
                                        const RefineSpec& refine = {}, bool solved_contact = false);

/// Runs every case; returns the table as text. Errors name the case, its level or the output path.
Result<std::string> run_bench_model(const BenchModelOptions& options, PlotSpec* plot = nullptr);

}  // namespace palpate
