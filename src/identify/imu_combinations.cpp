// One IMU channel's estimable combinations (imu_combinations.hpp).
#include "imu_combinations.hpp"

#include <cmath>

#include <fmt/format.h>
#include <Eigen/SVD>

#include "gyrocal/identify/identifiability.hpp"

namespace gyrocal::identify_detail {

std::vector<ChannelCombination> channel_combinations(const LeastSquaresSolution& sol, Eigen::Index offset,
                                                     Eigen::Index nc) {
  std::vector<ChannelCombination> out;
  const Eigen::MatrixXd& ns = sol.scaled_null_space;
  if (ns.cols() == 0) return out;
  std::vector<Eigen::Index> unidentified;  // channel-local indices
  for (Eigen::Index j = 0; j < nc; ++j)
    if (!sol.identifiable[static_cast<std::size_t>(offset + j)]) unidentified.push_back(j);
  const auto nj = static_cast<Eigen::Index>(unidentified.size());
  if (nj == 0) return out;
  // The null space's rows of those products: a combination z (on them alone) is estimable iff z' N = 0.
  Eigen::MatrixXd rows(nj, ns.cols());
  for (Eigen::Index a = 0; a < nj; ++a)
    rows.row(a) = ns.row(offset + unidentified[static_cast<std::size_t>(a)]);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(rows, Eigen::ComputeFullU);
  Eigen::Index rank = 0;
  for (Eigen::Index k = 0; k < svd.singularValues().size(); ++k)
    if (svd.singularValues()[k] > 1e-6) ++rank;
  const Eigen::Index dim = nj - rank;
  if (dim <= 0) return out;
  // The estimable space in the channel's coordinates (equilibrated), brought to reduced row echelon form in
  // the channel's own order: each combination starts at a coefficient of its own.
  Eigen::MatrixXd basis = Eigen::MatrixXd::Zero(dim, nc);
  for (Eigen::Index k = 0; k < dim; ++k)
    for (Eigen::Index a = 0; a < nj; ++a)
      basis(k, unidentified[static_cast<std::size_t>(a)]) = svd.matrixU()(a, rank + k);
  std::vector<Eigen::Index> order;
  for (Eigen::Index j = 0; j < nc; ++j) order.push_back(j);
  const Eigen::MatrixXd echelon = reduced_row_echelon(basis, order, 1e-6);
  const Eigen::VectorXd d = sol.column_scales.segment(offset, nc);
  for (Eigen::Index k = 0; k < echelon.rows(); ++k) {
    const Eigen::VectorXd z = echelon.row(k).transpose();
    Eigen::Index pivot = -1;
    for (Eigen::Index j = 0; j < nc && pivot < 0; ++j)
      if (std::abs(z[j]) >= 0.5) pivot = j;
    if (pivot < 0) continue;
    // In parameter units (x_j = d_j x~_j, so z' x~ = sum_j z_j / d_j x_j), the pivot's weight 1.
    Eigen::VectorXd c = z.cwiseQuotient(d);
    c /= c[pivot];
    out.push_back({c, pivot});
  }
  return out;
}

std::string combination_text(const ChannelCombination& c, const std::vector<std::string>& names) {
  const double largest = c.weights.cwiseAbs().maxCoeff();
  std::string text;
  for (Eigen::Index j = 0; j < c.weights.size(); ++j) {
    const double w = c.weights[j];
    if (!(std::abs(w) >= 1e-4 * largest)) continue;
    const std::string& name = names[static_cast<std::size_t>(j)];
    const double a = std::abs(w);
    const std::string weight = std::abs(a - 1.0) < 1e-4 ? std::string() : fmt::format("{:.6g} ", a);
    if (text.empty())
      text = fmt::format("{}{}{}", w < 0 ? "-" : "", weight, name);
    else
      text += fmt::format(" {} {}{}", w < 0 ? '-' : '+', weight, name);
  }
  return text;
}

}  // namespace gyrocal::identify_detail
