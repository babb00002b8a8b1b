#include "fit_refusals.hpp"

#include <cmath>

#include <fmt/format.h>
#include <Eigen/Cholesky>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/reduce/feasibility.hpp"

namespace gyrocal::identify_detail {
/// "position 8 (rate 9.9 rad/s, beta 180 deg, gamma 270 deg; record time 812.3 s to 1013.4 s)".
std::string describe_position(const Reduction& reduction, std::size_t i) {
  const ReducedPosition& p = reduction.positions[i];
  std::string where = fmt::format("position {} (rate {:g} rad/s, beta {:g} deg, gamma {:g} deg", p.index,
                                  p.rate_rad_s, p.beta_rad * kRadToDeg, p.gamma_rad * kRadToDeg);
  if (p.dwell >= 0 && static_cast<std::size_t>(p.dwell) < reduction.dwells.size()) {
    const Dwell& d = reduction.dwells[static_cast<std::size_t>(p.dwell)];
    where += fmt::format("; record time {:g} s to {:g} s", d.first_time_s, d.last_time_s);
  }
  return where + ")";
}

/// Refuses, naming the position, a reduced value or model term that is not finite (a record whose outputs
/// overflow, a configuration whose levels do).
void check_finite(const Reduction& reduction, const Eigen::MatrixXd& design,
                  const Eigen::VectorXd& observations, const std::vector<PositionModelTerms>& model_terms,
                  Compensation compensation) {
  for (Eigen::Index i = 0; i < design.rows(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    const ReducedPosition& p = reduction.positions[k];
    if (!std::isfinite(p.mean))
      throw Error(
          fmt::format("the reduced gyro output of {} is not a finite number: the record's gyro "
                      "outputs there are too large to average; check the record's gyro column.",
                      describe_position(reduction, k)));
    if (!std::isfinite(model_terms[k].omega_deg_h(compensation)) || !design.row(i).allFinite())
      throw Error(
          fmt::format("the model's input rate or specific force at {} is not finite: the configured "
                      "radius, rate or machine errors are too large to evaluate.",
                      describe_position(reduction, k)));
    if (!std::isfinite(observations[i]))
      throw Error(
          fmt::format("the output minus the model's input rate at {} is not finite ({:g} - {:g}): "
                      "the record's gyro output and the configuration disagree beyond a double's range.",
                      describe_position(reduction, k), p.mean, model_terms[k].omega_deg_h(compensation)));
  }
}

/// Refuses, naming the position, an observation that leaves a double's range once whitened (divided by its
/// standard error) to weight the fit: the solver's own check would only say "Observation 0 is not finite".
/// `unit` is the output's (deg/h or g); `limit` the configuration's bound on what predicts it.
void refuse_overflowing_weighting(const Reduction& reduction, const Eigen::VectorXd& observations,
                                  const Eigen::VectorXd& whitened, std::string_view unit,
                                  std::string_view limit) {
  for (Eigen::Index i = 0; i < whitened.size(); ++i) {
    if (std::isfinite(whitened[i])) continue;
    const auto k = static_cast<std::size_t>(i);
    throw Error(fmt::format(
        "the output minus the model's at {}, {:g} {}, leaves a double's range once divided by its standard "
        "error ({:g} {}) to weight the fit: the outputs, or the configured coefficients that predict them, "
        "are "
        "too large ({}).",
        describe_position(reduction, k), observations[i], unit, reduction.positions[k].std_err, unit, limit));
  }
}

/// Refuses two positions of the plan that are one measurement (a repeated rate, beta or gamma), naming them.
/// Checked before any weighting: their covariance is singular, but rounding may let a factorisation pass it.
void refuse_repeated_positions(const Reduction& reduction) {
  const auto& ps = reduction.positions;
  for (std::size_t i = 0; i < ps.size(); ++i)
    for (std::size_t j = i + 1; j < ps.size(); ++j)
      if (ps[i].dwell == ps[j].dwell && ps[i].gamma_slot == ps[j].gamma_slot)
        throw Error(
            fmt::format("{} and {} are one and the same measurement (the plan repeats a rate, beta or "
                        "gamma): they cannot be weighted as two; remove the repeated value from [test].",
                        describe_position(reduction, i), describe_position(reduction, j)));
}

/// Refuses a covariance of the reduced positions that cannot weight a fit, naming the dwell at fault, or
/// [test] gamma_deg and [reduce] harmonic_order when the dwell lists more gamma than the fit resolves.
void refuse_covariance(const Reduction& reduction, const ReduceOptions& reduce) {
  const auto& ps = reduction.positions;
  for (std::size_t d = 0; d < reduction.dwells.size(); ++d) {
    const Eigen::MatrixXd& c = reduction.dwells[d].output.covariance;
    if (c.size() == 0 || Eigen::LLT<Eigen::MatrixXd>(c).info() == Eigen::Success) continue;
    if (!reduction.dwells[d].is_static)
      refuse_gammas_beyond_fit(reduction.dwells[d].gammas_rad.size(), reduce);
    for (std::size_t i = 0; i < ps.size(); ++i)
      if (static_cast<std::size_t>(ps[i].dwell) == d)
        throw Error(
            fmt::format("the standard errors of the dwell holding {} do not form a covariance (not "
                        "positive definite): the record's scatter there cannot weight a fit.",
                        describe_position(reduction, i)));
  }
  throw Error(
      "the reduced positions' standard errors do not form a covariance (not positive definite): they cannot "
      "weight a least-squares fit.");
}

}  // namespace gyrocal::identify_detail
