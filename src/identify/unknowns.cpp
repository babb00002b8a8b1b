#include "gyrocal/identify/unknowns.hpp"

#include "gyrocal/core/error.hpp"

namespace gyrocal {

Unknowns least_squares_unknowns(GyroModel gyro_model) {
  Unknowns u;
  u.gyro_model = gyro_model;
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) {
    u.names.emplace_back(kCoefficientNames[k]);
    u.units.emplace_back(kCoefficientUnits[k]);
  }
  if (gyro_model == GyroModel::kDriftRate) {
    for (std::size_t k = 0; k < kNumRateTerms; ++k) {
      u.names.emplace_back(kRateTermNames[k]);
      u.units.emplace_back(kRateTermUnits[k]);
    }
  }
  return u;
}

std::vector<double> design_row(const PositionModelTerms& ch, Compensation compensation,
                               const Unknowns& unknowns) {
  const auto& x = ch.regressors(compensation);
  std::vector<double> row(x.begin(), x.end());
  if (unknowns.gyro_model == GyroModel::kDriftRate) {
    // docs/physics.md section 15: W - omega_I = e omega_I + (1 + e) (dO omega_O + dS omega_S) + drift.
    row.push_back(ch.omega_deg_h(compensation) * 1e-6);
    row.push_back(ch.omega_O_exact_deg_h * kArcsecToRad);
    row.push_back(ch.omega_S_exact_deg_h * kArcsecToRad);
  }
  return row;
}

std::string to_string(GyroModel m) {
  return m == GyroModel::kDrift ? "drift" : "drift+rate";
}

GyroModel parse_gyro_model(const std::string& text) {
  if (text == "drift") return GyroModel::kDrift;
  if (text == "drift+rate") return GyroModel::kDriftRate;
  throw Error("unknown gyro model '" + text + "': use drift or drift+rate.");
}

}  // namespace gyrocal
