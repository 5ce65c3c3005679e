#pragma once
/// Richardson extrapolation over lattice levels: a quantity computed at cell sizes h, h/2, h/4 whose error falls as
/// C h^p (p unknown) is extrapolated to h -> 0. Used where no closed form exists (the large-strain pull of
/// sim/reference/pull_reference.h). Pure functions; any thread.

#include "core/result.h"

namespace palpate {

/// Relative difference below which three levels count as agreeing (the rest tolerance of sim/reference/settle.h).
inline constexpr double kRichardsonAgreement = 1e-5;

/// The extrapolated value and the observed order. Plain data.
struct Richardson {
  double value = 0.0;   ///< estimate at h -> 0
  double order = 0.0;   ///< p, observed from the three values; NaN when the three agree already
};

/// Extrapolates f_coarse, f_mid, f_fine (cell sizes h, h/2, h/4); values agreeing within kRichardsonAgreement give
/// f_fine. Errors when the differences do not shrink with one sign (the levels are not in the asymptotic range),
/// naming the three values.
Result<Richardson> richardson_extrapolate(double f_coarse, double f_mid, double f_fine);

}  // namespace palpate
