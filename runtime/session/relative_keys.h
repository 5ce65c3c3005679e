#pragma once
/// Model-relative trajectory keys: "pos_rel" (a point of the model's box) and "surface" (snap to the surface
/// along the approach), resolved into pos_m once the model is loaded, so a scene keeps working when its mesh changes.

#include "core/result.h"
#include "core/scene.h"
#include "runtime/session/model.h"

namespace palpate {

/// Resolves, in order, every key of scene->trajectory that needs the model: pos_rel becomes
/// box.min + pos_rel * box.extent (the rest mesh's box, world axes); with surface, the key moves to the first
/// front-facing surface crossed by the ray from the previous key's position through it (toward the box centre for
/// the first key), then depth_m further along that ray. Resolved keys are plain pos_m keys afterwards (pos_rel and
/// surface cleared); keys that need nothing are left alone. Errors name the
/// scene and the key ("scene 'a.json': trajectory[2]: surface: the approach from [..] toward [..] misses the model").
Status resolve_relative_keys(const Model& model, Scene* scene);

}  // namespace palpate
