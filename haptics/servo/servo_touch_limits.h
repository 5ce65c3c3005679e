#pragma once
/// The touch servo's distances and angles, shared by its parts (servo.cpp, servo_touch_queries.cpp). Internal.

namespace palpate::servo_touch {

/// a point tool is a god-object sphere of this radius whose proxy is the surface point under it
inline constexpr double kPointClearance_m = 1e-6;
/// the god-object's move passes over faces turned further than 120 degrees from the contact's side (proxy_solver.cpp)
inline constexpr double kFarSideCos = -0.5;
/// a surface coming back through a free tool by another way than the point nearest it is caught when the tool was
/// within this of the surface (beyond its radius), outside, at the last tick and is within it, inside, now: a surface
/// seen only from afar, or not at all, starts no touch (the patch's first triangles can face away from the tool)
inline constexpr double kReturnReach_m = 0.005;

}  // namespace palpate::servo_touch
