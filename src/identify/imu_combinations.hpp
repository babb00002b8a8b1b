#pragma once
// The estimable combinations of one IMU channel's coefficients that its plan does not identify on their own
// (docs/imu.md, "When a plan leaves a coefficient unidentifiable"): from the joint solve's null space, in
// reduced row echelon form in the channel's own order, each with its pivot coefficient's weight 1.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gyrocal/solve/least_squares.hpp"

namespace gyrocal::identify_detail {

/// One combination of a channel's products: weights on its products (its block of the joint unknowns, in the
/// sensor's design-row order), the pivot's weight 1 (parameter units: a weight carries the ratio of the
/// pivot's unit to its product's, e.g. g^2 for dII against dF).
struct ChannelCombination {
  Eigen::VectorXd weights;  ///< one per product of the channel
  Eigen::Index pivot = 0;   ///< the product whose weight is 1
};

/// The combinations of the channel's unidentifiable products (the joint unknowns offset .. offset + nc - 1
/// that `solution` does not identify) that the data do identify: weights z on those products alone with
/// z' N = 0 for the joint null space N (equilibrated coordinates), as many as the products less the rank of
/// their rows of N; none when every product is identified or none of them can be combined.
std::vector<ChannelCombination> channel_combinations(const LeastSquaresSolution& solution,
                                                     Eigen::Index offset, Eigen::Index nc);

/// "dF + 14.4765 dSS", "dII - dSS": the weights written with the coefficients' names, terms below 1e-4 of
/// the largest weight left out and a weight within 1e-4 of 1 written as 1 (the exact chain tilts the null
/// direction by ~1e-8: the exact weights are the combination's coefficients).
std::string combination_text(const ChannelCombination& c, const std::vector<std::string>& names);

}  // namespace gyrocal::identify_detail
