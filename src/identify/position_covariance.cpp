#include "position_covariance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>

namespace gyrocal::identify_detail {
/// Covariance (deg/h)^2 of the reduced positions: within a dwell from its values' covariance (one fit
/// correlates its gammas), zero across dwells; standard errors alone where no covariance was computed.
/// floor^2 is added to every variance, so that a noise-free record (whose measured covariance is rounding)
/// still weights a fit.
Eigen::MatrixXd position_covariance(const Reduction& r, double floor) {
  const auto m = static_cast<Eigen::Index>(r.positions.size());
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(m, m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const ReducedPosition& a = r.positions[static_cast<std::size_t>(i)];
    for (Eigen::Index j = 0; j < m; ++j) {
      const ReducedPosition& b = r.positions[static_cast<std::size_t>(j)];
      if (a.dwell != b.dwell) continue;
      const Eigen::MatrixXd& dc = r.dwells[static_cast<std::size_t>(a.dwell)].output.covariance;
      const double v = dc.size() ? dc(a.gamma_slot, b.gamma_slot) : (i == j ? a.std_err * a.std_err : 0.0);
      c(i, j) = std::isfinite(v) ? v : 0.0;
    }
  }
  c.diagonal().array() += floor * floor;
  return c;
}

/// The factor that turns sqrt(g' C g) - the standard uncertainty of a linear function g'y of the reduced
/// positions - into the standard deviation of its error when C's levels are themselves measured: each dwell's
/// from a scatter with DwellValues::dof degrees of freedom. The Welch-Satterthwaite degrees of freedom of
/// g'Cg, nu = (sum_d v_d)^2 / sum_d (v_d^2 / nu_d) with v_d dwell d's share of it, make the error over its
/// standard uncertainty a Student t, whose standard deviation is sqrt(nu / (nu - 2)) (docs/calibration.md,
/// "Degrees of freedom"). nu below 3 is taken as 3 (a factor of 1.73) and warned about by the caller. 1 for a
/// known covariance (a prediction).
double student_factor(const Reduction& r, const Eigen::MatrixXd& c, const Eigen::VectorXd& g, double* nu) {
  std::vector<double> share(r.dwells.size(), 0.0);
  for (std::size_t i = 0; i < r.positions.size(); ++i)
    for (std::size_t j = 0; j < r.positions.size(); ++j)
      if (r.positions[i].dwell == r.positions[j].dwell)
        share[static_cast<std::size_t>(r.positions[i].dwell)] +=
            g[static_cast<Eigen::Index>(i)] * c(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) *
            g[static_cast<Eigen::Index>(j)];
  double total = 0.0, spread = 0.0;
  for (std::size_t d = 0; d < share.size(); ++d) {
    total += share[d];
    const double dof = r.dwells[d].output.dof;
    if (std::isfinite(dof) && dof > 0.0) spread += share[d] * share[d] / dof;
  }
  *nu = std::numeric_limits<double>::infinity();
  if (!(spread > 0.0) || !(total > 0.0)) return 1.0;
  *nu = total * total / spread;
  const double n = std::max(*nu, 3.0);
  return std::sqrt(n / (n - 2.0));
}

/// A warning when an uncertainty rests on fewer than 3 degrees of freedom (its widening is then capped).
void warn_few_dof(double nu, const std::string& name, CalibrationResult& r) {
  if (nu < 3.0)
    r.warnings.push_back(fmt::format(
        "the standard uncertainty of {} rests on only {:.1f} degrees of freedom of the scatter between "
        "revolutions; it is widened as for 3 and is itself uncertain: add revolutions.",
        name, nu));
}

/// position_covariance() with every measured dwell's level replaced by the record's: the dwells' levels
/// (DwellValues::level) averaged with their degrees of freedom as weights. Dwells whose covariance is not
/// measured (a prediction) keep theirs.
Eigen::MatrixXd pooled_position_covariance(const Reduction& r, double floor) {
  double sum = 0.0, dof = 0.0;
  for (const Dwell& d : r.dwells)
    if (std::isfinite(d.output.dof) && d.output.dof > 0.0 && std::isfinite(d.output.level)) {
      sum += d.output.dof * d.output.level;
      dof += d.output.dof;
    }
  Reduction pooled;
  pooled.positions = r.positions;
  pooled.dwells = r.dwells;
  if (dof > 0.0 && sum > 0.0) {
    for (Dwell& d : pooled.dwells)
      if (std::isfinite(d.output.dof) && d.output.dof > 0.0 && d.output.level > 0.0) {
        d.output.covariance *= (sum / dof) / d.output.level;
      }
  }
  return position_covariance(pooled, floor);
}

}  // namespace gyrocal::identify_detail
