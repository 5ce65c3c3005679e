#pragma once
/// Servo: one haptic tick — read the device, find the contact point P_s on the latest surface patch,
/// compute F = k_c (P_s - P_t) - b_c v, clamp, send it, and report a HapticSample to the sim thread.

#include <array>
#include <cstdint>

#include "core/rates.h"
#include "core/scene.h"
#include "core/spsc_queue.h"
#include "core/triple_buffer.h"
#include "haptics/devices/device.h"
#include "haptics/force/friction.h"
#include "haptics/servo/haptic_sample.h"
#include "haptics/force/jump_limit.h"
#include "haptics/servo/local_model.h"
#include "haptics/force/passivity_guard.h"

namespace palpate {

/// How the servo turns the latest sim snapshot into a force every tick.
enum class ForceModel : uint8_t {
  kHoldFrame,      ///< the force computed when a sim frame arrives is held until the next (the naive baseline)
  kStaticSurface,  ///< the proxy on the last frame's surface, the tool position fresh every tick
  kLocalModel,     ///< as kStaticSurface, plus the object's linearised response at the contact (multirate)
};

/// Cut-off of the servo's tool velocity estimate (first difference, one-pole low-pass), Hz: the same at every
/// servo rate. Its weight at 1 kHz is 0.3 a tick exactly (low_pass_weight), the estimate's weight before the
/// cut-off was given in Hz, so recordings at 1 kHz are unchanged bit for bit.
inline constexpr double kVelocityCutoff_hz = 56.766580404873906;

/// Servo parameters, validated by the scene loader; read-only while running. The defaults are the scene's
/// (core/scene.h's scene_defaults(), their one owner); the servo's own are only those no scene key sets.
struct ServoParams {
  InteractionMode mode = scene_defaults().mode;
  double coupling_N_per_m = scene_defaults().device.coupling_N_per_m;                  ///< k_c
  double coupling_damping_Ns_per_m = scene_defaults().device.coupling_damping_Ns_per_m; ///< b_c
  double grab_radius_m = scene_defaults().grab_radius_m;  ///< pull: grab distance on button press
  double velocity_cutoff_hz = kVelocityCutoff_hz;  ///< the tool velocity estimate's low-pass cut-off
  bool passivity = scene_defaults().device.passivity;  ///< energy-based passivity observer/controller on
  double ramp_s = scene_defaults().device.ramp_s;      ///< force ramp-in time at start and after a reset
  ForceModel force_model = ForceModel::kLocalModel;    ///< between-frame force
  double blade_length_m = scene_defaults().blade_length_m;  ///< cut: blade edge from the tool tip along its +z axis
  double cut_resistance_Ns_per_m = scene_defaults().cut_resistance_Ns_per_m;  ///< cut: viscous resistance to the
                                                                              ///< blade across its edge in material
  double tool_radius_m = 0.0;             ///< touch: > 0 makes the tool a sphere of this radius (the proxy is its
                                          ///< centre, kept this far outside the surface); 0 = a point (the
                                          ///< scene's tool_shape decides, not its drawn radius)
  FrictionParams friction;                ///< touch: Coulomb friction in the proxy (both coefficients 0: none)
  /// > 0: a step at a contact event, a region change or a cut reaches the device at most this fast
  /// (haptics/force/jump_limit.h); 0 = no limit
  double jump_limit_N_per_tick = scene_defaults().device.jump_limit_N_per_tick;
  /// touch: the force follows the patch's interpolated normals across a face (LocalModel::normal, which the sim
  /// takes over faces meeting at less than this crease angle), so a faceted surface is felt as the smooth one it
  /// stands for; 0: felt as its facets
  double force_shading_deg = scene_defaults().device.force_shading_deg;
  /// A grab takes the local model's prediction between frames (kLocalModel). Right for a lattice that settles within a
  /// frame as the static compliance says (implicit Euler, local/global, explicit Euler's damped substeps): without it
  /// the held point and the coupling trade the pull frame by frame, and a lattice softer than the coupling swings up
  /// (a person's pull on the E 10 kPa bunny_pull gave the hand 7.6 J, on bunny_pull_explicit 9.29 J). Wrong for one
  /// stepped symplectically, whose nodes carry their inertia from frame to frame: the static prediction put the held
  /// point up to 10 mm off for a few ticks each frame (steps of 2-4 N, the hand given energy it never put in, on the
  /// spring bunny_pull_springs shaken at 5 Hz). servo_params_for sets it from the scene's integrator.
  bool predict_grab = scene_defaults().lattice.integrator != IntegratorKind::kSymplecticEuler;
  bool surface_blend = true;              ///< a patch with blend_s > 0 moves over its frame; false takes each frame's
                                          ///< surface at its first tick (the comparison of `palpate bench force`)
};

/// Counters the servo keeps (read after the run, or approximately while it runs).
struct ServoCounters {
  int64_t ticks = 0;             ///< ticks run
  int64_t dropped_samples = 0;   ///< samples lost to a full queue
  int64_t rejected_inputs = 0;   ///< non-finite or out-of-workspace device readings
  int64_t no_readings = 0;       ///< ticks on which the device had no reading (read() returned false)
  double max_force_N = 0.0;      ///< largest force magnitude sent
  int64_t passivity_activations = 0;  ///< ticks on which the passivity controller added damping
  double passivity_dissipated_J = 0.0;///< energy it dissipated
  int64_t ramps = 0;             ///< force ramp-ins started (start and resets)
};

/// The servo's state machine. Thread: servo (tick); constructed and inspected elsewhere before/after.
class Servo {
 public:
  /// rates: the run's (Scene::rates), read every tick for the period; must outlive the servo.
  Servo(const ServoParams& params, const Rates& rates, Device* device, SpscQueue<HapticSample>* samples,
        TripleBuffer<LocalModel>* model);
  Servo(const ServoParams&, Rates&&, Device*, SpscQueue<HapticSample>*, TripleBuffer<LocalModel>*) = delete;

  /// One tick at scene time t_s. Thread: servo. Never allocates, locks, logs, throws or blocks.
  void tick(int64_t tick_index, double t_s) noexcept;

  /// How late the thread woke for the next tick (reported in its sample). Thread: servo.
  void set_wake_latency_ns(int64_t ns) noexcept { wake_latency_us_ = static_cast<float>(ns) * 1e-3f; }

  /// The tool velocity estimate after the last tick, m/s (read between ticks).
  const Vec3& tool_velocity_m_per_s() const noexcept { return tool_vel_m_per_s_; }
  /// Counters so far.
  const ServoCounters& counters() const noexcept { return counters_; }
  /// The last sample produced.
  const HapticSample& last_sample() const noexcept { return last_; }
  /// The controls the servo runs under (the scene's own until a device brings a change).
  const Controls& controls() const noexcept { return controls_; }

 private:
  // touch: a god-object — a sphere's centre held tool_radius_m outside the surface (a point tool: a sphere of
  // vanishing radius, the proxy the surface point under it), with Coulomb friction
  void update_touch(const LocalModel& m, const Vec3& tool) noexcept;
  // a person changed the controls (a device pose with a larger seq): the mode's parameters and the tool's radius
  // from now on, no contact, and no patch felt until the session's own (LocalModel::controls_seq) arrives
  void apply_controls(const Controls& c) noexcept;
  // whether the tool lies outside the surface by at least r (where a touch may end)
  bool tool_outside(const LocalModel& m, const Vec3& tool, double r) const noexcept;
  // the same judged at the surface point q (triangle slot, barycentric b) nearest the tool; *normal_out (if given):
  // the smooth normal there
  bool outside_of(const LocalModel& m, int slot, const Vec3& b, const Vec3& q, const Vec3& tool, double r,
                  Vec3* normal_out) const noexcept;
  // force shading: this tick's turn of the coupling's spring (shade_) for the god-object at c (its contact point in
  // patch slot `slot` at barycentric `bary`), its path bounded by path_m as the proxy's was (0: unbounded)
  void update_shading(const LocalModel& m, const Vec3& c, int slot, const Vec3& bary, const Vec3& tool, double r,
                      double path_m) noexcept;
  // force shading: the normal the coupling's force should follow where the facets alone hold the proxy at `at`: the
  // smooth normal at its contact point, faded out where it differs from the facets' push (from the device to `at`) by
  // more than a quarter of the crease angle and gone from half of it, or where the contact is not one convex spot
  // (then the push itself). The force is turned about the device from the push toward it; the god-object stays where
  // the facets hold it
  // (slot, bary: at's contact point when known, else slot -1)
  Vec3 shaded_normal(const LocalModel& m, const Vec3& at, int slot, const Vec3& bary, const Vec3& tool,
                     double r) const noexcept;
  // whether the tool's move from `from` starts a touch (sets the side it came from)
  bool touch_begins(const LocalModel& m, const Vec3& from, const Vec3& tool, double r, bool* back, int* slot) noexcept;
  // a free tool: the surface point nearest it, remembered so the next tick can carry its path with the surface, and
  // whether the tool is outside the surface there (by r)
  void track_nearest(const LocalModel& m, const Vec3& tool, double r) noexcept;
  // the step this tick that the device's motion does not explain is an event (entry, release, grab, region, cut)
  bool jump_event(const LocalModel& m, ContactState before) noexcept;
  void update_pull(const LocalModel& m, const Vec3& tool, bool button) noexcept;
  // cut: the blade cuts while the button is held and the edge crosses the surface or its tip is inside
  void update_cut(const LocalModel& m, const Vec3& tool, const Vec3& axis, bool button) noexcept;
  // the surface the tick feels: the latest patch, moved from the frame before's corners toward its own over the
  // frame (src.blend_s > 0), so a frame's change reaches the hand in steps of a tick's share; src otherwise
  const LocalModel& surface_at(const LocalModel& src, double t_s) noexcept;
  // closest point on the patch to p; returns false when the patch is empty
  // (side: when non-null, only triangles facing the same way — turned less than acos(min_cos) from it — so the far
  // side of a thin part is never taken)
  bool closest_on_patch(const LocalModel& m, const Vec3& p, int* slot, Vec3* point, Vec3* bary,
                        const Vec3* side = nullptr, double min_cos = 0.0) const noexcept;
  // position of the material point (tri, bary) in the latest patch (false when its triangle is not in it)
  static bool material_point(const LocalModel& m, int32_t tri, const Vec3& bary, Vec3* point) noexcept;

  // with no jump limit a point tool still rolls over a convex facet edge at most this much of the coupling's force a
  // tick beyond the device's step: pressed d into the surface, a point held at the edge would otherwise snap onto
  // the next face by about d sin(turn) in one tick (0.15 N at 1 mm and 25 degrees); a sphere wider than its depth
  // never does
  static constexpr double kPointRoll_N_per_tick = 0.02;

  ServoParams params_;
  std::array<ServoParams, 3> mode_params_;  // the parameters of each InteractionMode (a touch's sphere and friction
                                            // only in touch): what a mode switch takes
  Controls controls_;                       // the controls in force
  bool restart_pending_ = false;            // controls changed: the next good reading starts the tool's path afresh
  bool controls_event_ = false;             // controls changed: this tick's step is an event (jump limit)
  bool push_event_ = false;                 // the surface's move pushed the proxy further than its path: an event
  bool back_ = false;                       // touching a two-sided surface from the back of its faces
  int32_t back_part_ = 0;                   // the part touched so (LocalModel::part)
  bool bary_turned_ = false;                // bary_ is in a turned face's corner order
  LocalModel turned_;                       // the tick's patch, that part turned over, while back_ (turn_over)
  const Rates& rates_;
  Device* device_;
  SpscQueue<HapticSample>* samples_;
  TripleBuffer<LocalModel>* model_;
  ServoCounters counters_;
  HapticSample last_;
  DevicePose pose_;            // last good device pose
  Vec3 prev_tool_m_ = Vec3::Zero();
  Vec3 tool_vel_m_per_s_ = Vec3::Zero();
  bool have_pose_ = false;
  bool prev_button_ = false;
  ContactState contact_ = ContactState::kFree;
  int32_t tri_ = -1;           // triangle holding P_s
  Vec3 bary_ = Vec3::Zero();   // P_s in that triangle
  int32_t near_tri_ = -1;          // free touch tool: the triangle holding the surface point nearest it last tick
  Vec3 near_bary_ = Vec3::Zero();  // that point in it
  Vec3 near_m_ = Vec3::Zero();     // and where it was
  bool near_outside_ = false;      // and whether the tool was just outside the surface there (kReturnReach_m)
  Vec3 near_normal_ = Vec3::UnitZ();  // and the surface's smooth normal there: the side the tool was on
  bool unseen_ = false;            // free touch tool: its path has left what the patch covers
  Vec3 unseen_from_m_ = Vec3::Zero();  // where it was last seen (the start of the path judged when it is seen again)
  Vec3 proxy_m_ = Vec3::Zero();
  Vec3 contact_point_m_ = Vec3::Zero();  // touch: the surface point under the proxy (== proxy_m_ for a point tool)
  Vec3 god_m_sample_ = Vec3::Zero();     // this tick's god-object before the prediction (HapticSample::god_pos_m)
  Vec3 contact_normal_ = Vec3::UnitZ();  // touch: surface normal at the proxy (which side we are on)
  double shade_full_cos_ = 1.0;          // force shading: cosines of a quarter and half the crease angle (1: off)
  double shade_none_cos_ = 1.0;
  Quat shade_ = Quat::Identity();        // touch: this tick's force shading (applied to the coupling)
  Vec3 shade_n_ = Vec3::Zero();          // touch: the shaded normal the force follows (zero: none yet this touch)
  Vec3 shade_push_ = Vec3::Zero();       // touch: the facets' push it was shaded from, last tick
  Vec3 shade_free_m_ = Vec3::Zero();     // touch with friction: the god-object as the facets alone would hold it
  Vec3 cut_force_N_ = Vec3::Zero();      // cut: blade resistance this tick
  Vec3 god_m_ = Vec3::Zero();            // touch: the god-object's centre on the latest frame's surface
  Vec3 contact_frame_m_ = Vec3::Zero();  // touch: the surface point under it on that surface (before prediction)
  FrictionState friction_;               // touch: stick or slide, and the trail
  JumpLimit jump_;                       // the step at an event, returning to zero at jump_limit_N_per_tick
  int64_t jump_frame_ = -1;              // the frame the limit last saw
  bool jump_model_ = false;              // whether that frame had a contact model
  // the proxy moved by the object's response predicted since the frame (kLocalModel)
  Vec3 predicted_proxy(const LocalModel& m, const Vec3& tool, double t_s) const noexcept;

  LocalModel surface_;             // the blended patch (surface_at)
  bool surface_moved_ = false;     // this tick's surface differs from the last tick's
  int64_t seen_frame_ = -1;        // the frame the last tick read
  double surface_start_s_ = 0.0;   // the first tick that saw surface_'s frame
  double surface_alpha_ = -1.0;    // its corners' share of the way from tri_from_m to tri_m
  // where each corner of surface_ starts its way: tri_from_m, or, for a triangle the servo was still moving when the
  // frame came (a realtime frame early, the last one's way not done), where the servo had it
  std::array<std::array<Vec3, 3>, LocalModel::kMaxTriangles> from_corners_{};
  // the last patch's triangle ids by slot, for that lookup: an open-addressed table (id + 1, 0 empty; slot)
  static constexpr int kIdTable = 2 * LocalModel::kMaxTriangles;
  std::array<int32_t, kIdTable> id_key_{};
  std::array<int16_t, kIdTable> id_slot_{};
  Vec3 from_f0_N_ = Vec3::Zero();  // the contact model's force and compliance at the frame before
  Mat3 from_compliance_m_per_N_ = Mat3::Zero();

  PassivityGuard guard_;
  Vec3 held_force_N_ = Vec3::Zero();  // kHoldFrame: force of the last frame
  int64_t held_frame_ = -2;           // kHoldFrame: frame it was computed on
  float wake_latency_us_ = 0.0f;  // set by the runner before each tick
  double ramp_start_s_ = 0.0;  // force scale ramps 0 -> 1 from here
  bool ramp_pending_ = true;   // restart the ramp at the next good reading
};

}  // namespace palpate
