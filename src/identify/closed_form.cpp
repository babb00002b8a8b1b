#include "gyrocal/identify/closed_form.hpp"

#include <algorithm>
#include <cmath>

namespace gyrocal {

double LinearForm::value(const std::array<double, 16>& w) const {
  double v = constant;
  for (std::size_t k = 0; k < 16; ++k) v += weights[k] * w[k];
  return v;
}

double LinearForm::std(const Eigen::Matrix<double, 16, 16>& covariance) const {
  const Eigen::Map<const Eigen::Matrix<double, 16, 1>> w(weights.data());
  return std::sqrt(std::max(w.dot(covariance * w), 0.0));
}

namespace {

/// A form from (position number 1..16, coefficient) pairs, all divided by `divisor`.
LinearForm form(std::string name, std::string unit, std::initializer_list<std::pair<int, double>> terms,
                double divisor, double constant = 0.0) {
  LinearForm f;
  f.name = std::move(name);
  f.unit = std::move(unit);
  for (const auto& [k, c] : terms) f.weights[static_cast<std::size_t>(k - 1)] += c / divisor;
  f.constant = constant / divisor;
  return f;
}

LinearForm combine(std::string name, std::string unit, const LinearForm& a, double ca, const LinearForm& b,
                   double cb) {
  LinearForm f;
  f.name = std::move(name);
  f.unit = std::move(unit);
  for (std::size_t k = 0; k < 16; ++k) f.weights[k] = ca * a.weights[k] + cb * b.weights[k];
  f.constant = ca * a.constant + cb * b.constant;
  return f;
}

}  // namespace

ClosedForms closed_forms(double ar, double omega_n, double omega_u) {
  const std::string g1 = "deg/h/g", g2 = "deg/h/g^2";
  ClosedForms cf;
  // docs/physics.md section 8 (seed eq. 7-9 and the cross terms), with k1 = k2 = 0 after compensation.
  cf.primary = {
      form("dI", g1, {{1, 1}, {2, -1}, {5, -1}, {6, 1}}, -4 * ar),
      form("dO", g1, {{3, -1}, {4, 1}, {7, -1}, {8, 1}}, 4 * ar),
      form("dS", g1, {{9, 1}, {10, -1}, {13, -1}, {14, 1}}, 4 * ar),
      form("dIS", g2, {{1, -1}, {2, 1}, {5, -1}, {6, 1}}, 4 * ar),
      form("dIO", g2, {{11, -1}, {12, 1}, {15, 1}, {16, -1}}, 4 * ar),
      form("dOS", g2, {{3, -1}, {4, 1}, {7, 1}, {8, -1}}, 4 * ar),
  };
  cf.alternatives = {
      form("dI_1g", g1, {{11, 1}, {12, 1}, {15, -1}, {16, -1}}, 4, -4 * omega_u),
      form("dO_1g", g1, {{11, -1}, {15, -1}, {12, 1}, {16, 1}}, 4 * ar),
      form("dS_1g", g1, {{1, 1}, {2, 1}, {5, -1}, {6, -1}}, 4, -4 * omega_n),
      form("dIS_b", g2, {{9, 1}, {10, -1}, {13, 1}, {14, -1}}, 4 * ar),
  };
  // What one speed gives of dF, dII, dOO, dSS (docs/physics.md section 8, "What one speed cannot give").
  const LinearForm s1 = form("S1", "deg/h", {{1, 1}, {2, 1}, {5, 1}, {6, 1}}, 4);
  const LinearForm s2 = form("S2", "deg/h", {{3, 1}, {4, 1}, {7, 1}, {8, 1}}, 4);
  const LinearForm s3 = form("S3", "deg/h", {{9, 1}, {10, 1}, {13, 1}, {14, 1}}, 4);
  const LinearForm s4 = form("S4", "deg/h", {{11, 1}, {12, 1}, {15, 1}, {16, 1}}, 4);
  const LinearForm s4_minus_s2 = combine("dII-dSS", g2, s4, 1, s2, -1);
  cf.combinations = {
      s4_minus_s2,
      combine("dOO-dSS", g2, combine("", "", s2, 1, s1, -1), 1 / (ar * ar), s4_minus_s2, 1),
      combine("dF+(1+Ar^2)dSS", "deg/h", s3, 1, s4_minus_s2, -1),
  };
  return cf;
}

}  // namespace gyrocal
