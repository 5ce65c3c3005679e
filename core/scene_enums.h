#pragma once
/// The enums scenes, the command line and summary.json spell as text, each with one name table: text is turned
/// into an enum once, where it is read (the scene parser, the command line), and written back from the same table.

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace palpate {

/// Which integrator steps the lattice.
enum class IntegratorKind { kExplicitEuler, kSymplecticEuler, kImplicitEuler, kLocalGlobal, kRk4 };
/// How a material lattice turns E and nu into forces (scene key material.model; sim/material/material.h): central springs
/// only (nu = 1/4 whatever is asked), springs for the shear modulus plus a per-cell volume term for the asked nu, or
/// a per-cell Neo-Hookean solid (large strain) with a fifth of the stiffness left to the springs.
enum class MaterialModel { kSprings, kVolumetric, kNeoHookean };
/// How the tool interacts with the model.
enum class InteractionMode { kTouch, kPull, kCut };
/// Which clock drives a recording.
enum class RunMode { kLockstep, kRealtime };
/// How the mesh is drawn.
enum class RenderStyle { kSolid, kWireframe, kBoth };
/// How the surface is coloured: by each vertex's displacement from rest, or in one colour; auto: by displacement in
/// touch and pull, in one colour in cut mode (a piece cut free moves as a body: its displacement is not the tissue's).
enum class RenderColor { kAuto, kDisplacement, kStrain, kNone };
/// `both` style: the wireframe is left out when the mesh's median edge is shorter than this on screen, in pixels
/// (scene key render.wire_min_edge_px; see Renderer::set_wire_min_edge_px).
inline constexpr double kWireMinEdgePxDefault = 2.0;
/// A mesh whose median edge is shorter than this on screen, in pixels, is drawn clustered to about this edge: 1.5
/// px is the edge of an equilateral triangle one pixel in area
/// (scene key render.lod_min_edge_px; 0: always the mesh itself; see render/mesh_lod.h).
inline constexpr double kLodMinEdgePxDefault = 1.5;
/// Which off-screen GL the renderer asks for (auto: OSMesa, else EGL surfaceless).
enum class RenderBackend { kAuto, kOsmesa, kEgl };
/// Where the device's poses come from.
enum class DeviceDriver { kScripted, kShm, kPlugin, kReplay, kBrowser };

/// An enum's names, in the order they are listed in errors and help.
template <typename E, std::size_t N>
struct NameTable {
  std::array<std::pair<E, const char*>, N> entries;

  constexpr const char* name(E e) const {
    for (const auto& [v, n] : entries)
      if (v == e) return n;
    return "?";
  }
  std::optional<E> parse(std::string_view text) const {
    for (const auto& [v, n] : entries)
      if (text == n) return v;
    return std::nullopt;
  }
  /// "a, b, c": for "'x' is not one of: a, b, c".
  std::string list() const {
    std::string s;
    for (const auto& [v, n] : entries) s += (s.empty() ? "" : ", ") + std::string(n);
    return s;
  }
};

// one table per enum, found by overload on the enum type: names(E{})
constexpr NameTable<IntegratorKind, 5> names(IntegratorKind) {
  return {{{{IntegratorKind::kExplicitEuler, "explicit_euler"},
            {IntegratorKind::kSymplecticEuler, "symplectic_euler"},
            {IntegratorKind::kImplicitEuler, "implicit_euler"},
            {IntegratorKind::kLocalGlobal, "local_global"},
            {IntegratorKind::kRk4, "rk4"}}}};
}
constexpr NameTable<MaterialModel, 3> names(MaterialModel) {
  return {{{{MaterialModel::kSprings, "springs"}, {MaterialModel::kVolumetric, "volumetric"},
            {MaterialModel::kNeoHookean, "neo_hookean"}}}};
}
constexpr NameTable<InteractionMode, 3> names(InteractionMode) {
  return {{{{InteractionMode::kTouch, "touch"}, {InteractionMode::kPull, "pull"}, {InteractionMode::kCut, "cut"}}}};
}
constexpr NameTable<RunMode, 2> names(RunMode) {
  return {{{{RunMode::kLockstep, "lockstep"}, {RunMode::kRealtime, "realtime"}}}};
}
constexpr NameTable<RenderStyle, 3> names(RenderStyle) {
  return {{{{RenderStyle::kSolid, "solid"}, {RenderStyle::kWireframe, "wireframe"}, {RenderStyle::kBoth, "both"}}}};
}
constexpr NameTable<RenderColor, 4> names(RenderColor) {
  return {{{{RenderColor::kAuto, "auto"},
            {RenderColor::kDisplacement, "displacement"},
            {RenderColor::kStrain, "strain"},
            {RenderColor::kNone, "none"}}}};
}
constexpr NameTable<RenderBackend, 3> names(RenderBackend) {
  return {{{{RenderBackend::kAuto, "auto"}, {RenderBackend::kOsmesa, "osmesa"}, {RenderBackend::kEgl, "egl"}}}};
}
constexpr NameTable<DeviceDriver, 5> names(DeviceDriver) {
  return {{{{DeviceDriver::kScripted, "scripted"},
            {DeviceDriver::kShm, "shm"},
            {DeviceDriver::kPlugin, "plugin"},
            {DeviceDriver::kReplay, "replay"},
            {DeviceDriver::kBrowser, "browser"}}}};
}

/// The name of an enum value as scenes and summary.json write it.
template <typename E>
constexpr const char* name_of(E e) {
  return names(E{}).name(e);
}
/// The value called `text`, or nothing for an unknown name.
template <typename E>
std::optional<E> from_name(std::string_view text) {
  return names(E{}).parse(text);
}

}  // namespace palpate
