#pragma once
// What a least-squares fit refuses before it weights anything, each refusal naming the position or dwell at
// fault: a value or model term that is not finite, an observation that leaves a double's range once whitened,
// a measurement repeated, a covariance that cannot weight a fit. Internal to src/identify.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "gyrocal/identify/calibration.hpp"

namespace gyrocal::identify_detail {

/// "position 8 (rate 9.9 rad/s, beta 180 deg, gamma 270 deg; record time 812.3 s to 1013.4 s)".
std::string describe_position(const Reduction& reduction, std::size_t i);

/// Refuses, naming the position, a reduced value or model term that is not finite.
void check_finite(const Reduction& reduction, const Eigen::MatrixXd& design,
                  const Eigen::VectorXd& observations, const std::vector<PositionModelTerms>& model_terms,
                  Compensation compensation);

/// Refuses, naming the position, an observation that leaves a double's range once whitened. `unit` is the
/// output's (deg/h or g); `limit` the configuration's bound on what predicts it.
void refuse_overflowing_weighting(const Reduction& reduction, const Eigen::VectorXd& observations,
                                  const Eigen::VectorXd& whitened, std::string_view unit,
                                  std::string_view limit);

/// Refuses two positions of the plan that are one measurement (a repeated rate, beta or gamma), naming them.
void refuse_repeated_positions(const Reduction& reduction);

/// Refuses a covariance of the reduced positions that cannot weight a fit, naming the dwell at fault (it
/// always throws: it is called once the covariance's factorisation has failed).
void refuse_covariance(const Reduction& reduction, const ReduceOptions& reduce);

}  // namespace gyrocal::identify_detail
