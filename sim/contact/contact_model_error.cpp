#include "sim/contact/contact_model_error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace palpate {
namespace {

// One measured Hertz force error: model, nu, contact radius over cell edge, force error.
struct HertzPoint {
  MaterialModel model;
  double nu;
  double cells;
  double error;
};

// `palpate bench model` (docs/material.md gives the commands): E 1e5 Pa, implicit Euler, levels 3-6 of the Hertz
// block, whose contact radius of 5 mm is 0.25, 0.5, 1 and 2 cells there.
constexpr HertzPoint kHertzCalibration[] = {
    {MaterialModel::kSprings, 0.25, 0.25, 3.73},   {MaterialModel::kSprings, 0.25, 0.5, 0.94},
    {MaterialModel::kSprings, 0.25, 1.0, 0.10},    {MaterialModel::kSprings, 0.25, 2.0, 0.029},
    {MaterialModel::kVolumetric, 0.0, 1.0, -0.261},   {MaterialModel::kVolumetric, 0.0, 2.0, -0.0775},
    {MaterialModel::kVolumetric, 0.25, 1.0, 0.101}, {MaterialModel::kVolumetric, 0.25, 2.0, 0.029},
    {MaterialModel::kVolumetric, 0.4, 1.0, -0.008}, {MaterialModel::kVolumetric, 0.4, 2.0, 0.002},
    {MaterialModel::kVolumetric, 0.45, 1.0, -0.044}, {MaterialModel::kVolumetric, 0.45, 2.0, -0.0002},
    {MaterialModel::kVolumetric, 0.49, 1.0, -0.068}, {MaterialModel::kVolumetric, 0.49, 2.0, 0.002},
    {MaterialModel::kNeoHookean, 0.0, 1.0, -0.375},   {MaterialModel::kNeoHookean, 0.0, 2.0, -0.075},
    {MaterialModel::kNeoHookean, 0.25, 1.0, -0.459},  {MaterialModel::kNeoHookean, 0.25, 2.0, -0.069},
    {MaterialModel::kNeoHookean, 0.45, 1.0, -0.541},  {MaterialModel::kNeoHookean, 0.45, 2.0, -0.065},
    {MaterialModel::kNeoHookean, 0.49, 1.0, -0.557},  {MaterialModel::kNeoHookean, 0.49, 2.0, -0.059},
};

// The same block with the contact solved under the sphere (device.contact "solved", `--contact solved`): the push
// goes where the surface, deformed by it, meets the sphere, and Hertz is only the check.
constexpr HertzPoint kHertzSolvedCalibration[] = {
    {MaterialModel::kSprings, 0.25, 0.25, 3.25},    {MaterialModel::kSprings, 0.25, 0.5, 0.899},
    {MaterialModel::kSprings, 0.25, 1.0, 0.0251},   {MaterialModel::kSprings, 0.25, 2.0, 0.093},
    {MaterialModel::kVolumetric, 0.0, 1.0, -0.151},  {MaterialModel::kVolumetric, 0.0, 2.0, 0.0608},
    {MaterialModel::kVolumetric, 0.25, 1.0, 0.0251}, {MaterialModel::kVolumetric, 0.25, 2.0, 0.0931},
    {MaterialModel::kVolumetric, 0.4, 1.0, 0.0144},  {MaterialModel::kVolumetric, 0.4, 2.0, 0.0831},
    {MaterialModel::kVolumetric, 0.45, 1.0, 0.141},  {MaterialModel::kVolumetric, 0.45, 2.0, 0.0858},
    {MaterialModel::kVolumetric, 0.49, 1.0, 0.125},  {MaterialModel::kVolumetric, 0.49, 2.0, 0.0906},
    {MaterialModel::kNeoHookean, 0.0, 1.0, -0.206},  {MaterialModel::kNeoHookean, 0.0, 2.0, 0.0813},
    {MaterialModel::kNeoHookean, 0.25, 1.0, -0.249}, {MaterialModel::kNeoHookean, 0.25, 2.0, 0.0937},
    {MaterialModel::kNeoHookean, 0.45, 1.0, -0.222}, {MaterialModel::kNeoHookean, 0.45, 2.0, 0.0501},
    {MaterialModel::kNeoHookean, 0.49, 1.0, -0.219}, {MaterialModel::kNeoHookean, 0.49, 2.0, 0.0548},
};

template <std::size_t N>
using Table = HertzPoint[N];

// The error of one (model, nu) row of `table` at `cells`: piecewise linear in log2(cells), the nearest end outside
template <std::size_t N>
double row_error(const Table<N>& table, MaterialModel model, double nu, double cells, bool* inside) {
  std::vector<HertzPoint> row;
  for (const HertzPoint& p : table)
    if (p.model == model && p.nu == nu) row.push_back(p);
  if (cells < row.front().cells || cells > row.back().cells) *inside = false;
  if (cells <= row.front().cells) return row.front().error;
  for (std::size_t k = 1; k < row.size(); ++k)
    if (cells <= row[k].cells) {
      const double t = std::log2(cells / row[k - 1].cells) / std::log2(row[k].cells / row[k - 1].cells);
      return row[k - 1].error + t * (row[k].error - row[k - 1].error);
    }
  return row.back().error;
}

template <std::size_t N>
ContactModelError read_table(const Table<N>& table, const MaterialSpec& material, bool sphere_tool,
                             double tool_radius_m, double cell_m, bool solved) {
  ContactModelError out;
  if (!sphere_tool && !solved) {
    out.basis = "point tool: its push goes to one surface point, a point load, whose force at a given depth has no "
                "continuum limit (it falls as the cells shrink); no Hertz figure applies";
    return out;
  }
  out.defined = true;
  out.contact_radius_cells = tool_radius_m / cell_m;
  // the rows of the scene's model, and the two nu rows either side of the scene's nu (springs: nu 1/4 only)
  const MaterialModel model = material.model;
  const double nu = model == MaterialModel::kSprings ? 0.25 : material.poisson_ratio;
  double below = -1.0, above = 2.0;
  for (const HertzPoint& p : table) {
    if (p.model != model) continue;
    if (p.nu <= nu) below = std::max(below, p.nu);
    if (p.nu >= nu) above = std::min(above, p.nu);
  }
  out.within_calibration = below >= 0.0 && above <= 1.0;
  if (below < 0.0) below = above;
  if (above > 1.0) above = below;
  const double e_below = row_error(table, model, below, out.contact_radius_cells, &out.within_calibration);
  const double e_above = row_error(table, model, above, out.contact_radius_cells, &out.within_calibration);
  const double t = above > below ? (nu - below) / (above - below) : 0.0;
  out.hertz_force_error = e_below + t * (e_above - e_below);
  char text[512];
  std::snprintf(text, sizeof text,
                "from the Hertz calibration of palpate bench model (material.model %s, nu %.2f, the contact %s), not "
                "measured in this run: force error at a contact radius of %.2f cells (the %s radius over the cell "
                "edge: its widest patch; shallower presses have a narrower patch and a larger error)%s",
                name_of(model), nu, solved ? "solved under the sphere" : "prescribed by Hertz's pressure",
                out.contact_radius_cells, sphere_tool ? "sphere tool's" : "point tool's tip, loaded as a sphere of its",
                out.within_calibration ? "" : "; outside the calibrated range (0.25-2 cells): the nearest figure");
  out.basis = text;
  return out;
}

}  // namespace

ContactModelError contact_model_error(const MaterialSpec& material, bool sphere_tool, double tool_radius_m,
                                      double cell_m, bool solved) {
  return solved ? read_table(kHertzSolvedCalibration, material, sphere_tool, tool_radius_m, cell_m, true)
                : read_table(kHertzCalibration, material, sphere_tool, tool_radius_m, cell_m, false);
}

}  // namespace palpate
