#include "gyrocal/sensor/sensor_model.hpp"

#include <cmath>
#include <limits>
#include <utility>

namespace gyrocal {

ParameterEstimates propagate(Eigen::VectorXd values, const Eigen::MatrixXd& jacobian,
                             const Eigen::MatrixXd& product_covariance, std::vector<bool> identifiable) {
  ParameterEstimates e;
  e.values = std::move(values);
  e.covariance = jacobian * product_covariance * jacobian.transpose();
  e.jacobian = jacobian;
  e.identifiable = std::move(identifiable);
  e.std.resize(e.values.size());
  for (Eigen::Index k = 0; k < e.values.size(); ++k) {
    e.std(k) = e.identifiable[k] ? std::sqrt(std::max(e.covariance(k, k), 0.0))
                                 : std::numeric_limits<double>::infinity();
  }
  return e;
}

}  // namespace gyrocal
