#pragma once
/// The end-of-recording note when the tool never touched the model: how close the tool came, instead of a
/// silent zero-force recording.

#include <string>
#include <vector>

#include "core/scene.h"
#include "haptics/devices/replay_device.h"
#include "runtime/session/frame_stats.h"
#include "runtime/session/model.h"

namespace palpate {

/// For a recording whose servo never sent a force: one line saying so and why, e.g. "no contact in 4.0 s: the
/// trajectory stays 12 mm from the surface at its closest" (distances from the tool positions in `rows` to the
/// rest surface; pull counts only button presses, cut only rows with the button held). Thread: any.
std::string no_contact_note(const Scene& scene, const Model& model, const std::vector<ReplayRow>& rows);

/// For a touch recording whose free tool was deep inside the object (FrameStats::tool_inside_frames): one line
/// saying when and how deep, e.g. "the tool was inside the object without touching it from 0.28 s, in 73 frames, at
/// least 9.4 mm under its rest surface: the touch was lost (the tool went through) or never began"; when only the
/// every-tick check saw it (FrameStats::tool_inside_ticks, proxy_inside_ticks), the ticks and whether the tool or the
/// held proxy was inside; empty when neither was. Thread: any.
std::string tool_inside_note(const FrameStats& stats);

}  // namespace palpate
