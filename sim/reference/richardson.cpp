#include "sim/reference/richardson.h"

#include <cmath>
#include <string>

namespace palpate {

Result<Richardson> richardson_extrapolate(double f_coarse, double f_mid, double f_fine) {
  const double d1 = f_coarse - f_mid, d2 = f_mid - f_fine;
  // levels that agree to within kRichardsonAgreement: converged already (a homogeneous deformation, exact at any level)
  if (std::abs(d1) <= kRichardsonAgreement * std::abs(f_fine) && std::abs(d2) <= kRichardsonAgreement * std::abs(f_fine))
    return Richardson{f_fine, NAN};
  // the differences shrink by 2^p: same sign and smaller
  if (!(d1 * d2 > 0.0) || !(std::abs(d2) < std::abs(d1)))
    return make_error("Richardson extrapolation: ", std::to_string(f_coarse), ", ", std::to_string(f_mid), ", ",
                      std::to_string(f_fine), " do not converge monotonically (not in the asymptotic range)");
  Richardson r;
  r.order = std::log2(d1 / d2);
  r.value = f_fine - d2 / (std::pow(2.0, r.order) - 1.0);
  return r;
}

}  // namespace palpate
