#pragma once
/// Holding the tool still against a model until the object comes to rest: the servo and the frame stage of a
/// recording, in lockstep, with the device clamped at one position. The equilibrium is the simulation's own (the
/// scene's integrator and damping stepped frame by frame), read when every node has stopped and the force holds.
/// Used by `palpate bench model` (Hertz indentation by the sphere tool) and the tests.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/result.h"
#include "core/scene.h"
#include "core/types.h"
#include "runtime/session/model.h"

namespace palpate {

/// Where to hold the device and when the object counts as at rest. Plain data.
struct ToolHoldOptions {
  Vec3 device_pos_m = Vec3::Zero();   ///< the device's position (a sphere tool's centre), held from approach_s on
  Vec3 start_pos_m = Vec3::Zero();    ///< with approach_s > 0: where the device starts, moving straight to device_pos_m
  double approach_s = 0.0;            ///< how long that approach takes (0: held at device_pos_m from the start)
  double max_s = 20.0;                ///< scene seconds before giving up
  double rest_move_rel = 1e-2;        ///< at rest, three frames running: no node moves more than this fraction of
                                      ///< the largest displacement from rest in a frame ...
  bool record_ticks = false;          ///< keep every tick's force and the ticks at which the region moved (result)
  double rest_force_rel = 1e-3;       ///< ... and the push (the frame's mean force along itself) changes by less than
                                      ///< this fraction (the sphere's centre jitters by micrometres sideways in the
                                      ///< dimple it presses, and the frames alternate 17, 17, 16 servo ticks)
};

/// What the held tool came to. Plain data.
struct ToolHoldResult {
  bool at_rest = false;               ///< false: max_s ran out first
  int64_t frames = 0;                 ///< sim frames run (1/60 s each) until rest
  Vec3 force_N = Vec3::Zero();        ///< force sent to the device, mean over the last three frames' ticks
  Vec3 proxy_m = Vec3::Zero();        ///< the proxy on the last tick (a sphere tool's centre)
  int32_t contact_tri = -1;           ///< the triangle under the proxy (-1: no contact)
  Vec3 contact_bary = Vec3::Zero();   ///< the point under the proxy in it
  double max_node_speed_m_per_s = 0.0;///< at the end
  std::size_t nodes = 0, springs = 0; ///< lattice size
  int force_nodes = 0;                ///< lattice nodes the contact force was spread over in the last frame
  int64_t solved_frames = 0;          ///< frames whose push went where the solved contact put it (device.contact)
  double sim_ms_p50 = 0.0;            ///< frame stage thread CPU time per frame (median)
  double step_ms_p50 = 0.0;           ///< the integrator step alone, thread CPU per stepped frame (median)
  double cg_iterations_p50 = 0.0;     ///< implicit Euler: conjugate gradient iterations per stepped frame (median)
  int64_t region_moves = 0;           ///< times the region followed the contact (a refined lattice: its fine zone moved)
  int64_t substeps = 0;               ///< integrator substeps over all frames
  std::vector<Vec3> vertices_m;       ///< the deformed mesh at the end
  std::vector<Vec3> tick_force_N;     ///< with record_ticks: the force sent on every servo tick
  std::vector<int64_t> region_move_ticks;  ///< with record_ticks: the first tick after each frame that moved the region
};

/// Runs the scene's servo and frame stage (no rendering) with the device at options.device_pos_m from t = 0.
/// Errors name the scene when its device cannot be made.
Result<ToolHoldResult> hold_tool(const Scene& scene, const Model& model, const ToolHoldOptions& options);

}  // namespace palpate
