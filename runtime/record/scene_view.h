#pragma once
/// What a recording's frames look from: the scene's camera around the model (and a scripted tool), and the plane a
/// browser's pointer moves the tool on in that view.

#include "core/aabb.h"
#include "core/scene.h"
#include "haptics/devices/browser_device.h"
#include "render/camera.h"

namespace palpate {

/// The camera a scene's frames are drawn with, around the model's rest box: its render.view_from, framing the
/// whole box or, with render.frame_radius_m, the sphere around render.look_at_m. A scripted touch or pull frames the
/// tool at its keyframes too (held within a quarter of the box's diagonal of it), so it is drawn whole.
Camera scene_camera(const Scene& scene, const Aabb& model_box_m);
/// The same for a run whose poses come from `driver` (a command line's --device instead of the scene's).
Camera scene_camera(const Scene& scene, const Aabb& model_box_m, DeviceDriver driver);

/// The view plane of a camera for the browser device: centred on what it looks at, its axes those of the image, as
/// wide and high as the image is there (the tool at depth 0 lies under the pointer), depth +-1 half the box diagonal.
BrowserView browser_view(const Camera& cam, double aspect, double diagonal_m);

}  // namespace palpate
