#pragma once
/// The displacement colours' range of a scripted recording, from a first pass: the same lockstep run without frames
/// or outputs, so the colour map is fixed before the first frame and every frame of the run compares.

#include <atomic>

#include "core/scene.h"
#include "runtime/session/model.h"

namespace palpate {

/// Whether a recording colours by displacement or strain with a range the scene does not give, on a device whose run
/// a first pass can repeat (scripted: the trajectory).
bool needs_color_pass(const Scene& scene, bool render, DeviceDriver driver);

/// Runs scene (lockstep, its scripted device, no renderer, log or writer) and returns the largest displacement from
/// rest (metres) of a surface vertex the frames may move, or its largest strain when the scene colours by strain,
/// over every frame, rounded up to 1, 2 or 5 times a power of ten; 0 when nothing moved, the pass failed, or `stop`
/// was set (checked every frame). Costs the run's simulation once more (bunny_pull: 0.39 s beside a 1.02 s recording).
double color_pass_range(const Scene& scene, const Model& model, const std::atomic<bool>* stop);

}  // namespace palpate
