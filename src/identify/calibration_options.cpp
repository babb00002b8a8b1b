#include "gyrocal/identify/calibration.hpp"

#include <cmath>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"

namespace gyrocal {

bool CalibrationOptions::IsValid(std::string* error) const {
  std::string e;
  if (!reduce.IsValid(&e)) {
    if (error) *error = "reduce: " + e;
    return false;
  }
  if (!least_squares.IsValid(&e)) {
    if (error) *error = "least squares: " + e;
    return false;
  }
  if (!(min_std_err > 0.0)) {
    if (error) *error = "min_std_err_deg_h must be positive";
    return false;
  }
  if (!(min_regressor_level >= 0.0 && min_regressor_level < 1.0)) {
    if (error) *error = "min_regressor_level must be in [0, 1)";
    return false;
  }
  if (!(misfit.p_min > 0.0 && misfit.p_min < 1.0)) {
    if (error) *error = "misfit.p_min must be in (0, 1)";
    return false;
  }
  if (!(misfit.max_scale > 1.0) || !(misfit.max_scale_factor_error_ppm > 0.0)) {
    if (error) *error = "misfit.max_scale must exceed 1 and misfit.max_scale_factor_error_ppm be positive";
    return false;
  }
  if (!(output.scale != 0.0 && std::isfinite(output.scale))) {
    if (error) *error = "output.scale must be finite and non-zero";
    return false;
  }
  if (sensor != SensorKind::kGyro) {
    const std::string_view kind = to_string(sensor);
    const auto refuse = [&](const std::string& what) {
      if (error)
        *error = fmt::format(
            "{} is the gyro's; sensor.kind is \"{}\", whose calibration is least squares "
            "with full compensation (docs/accelerometer.md)",
            what, kind);
      return false;
    };
    if (method == Method::kClosedForm) return refuse("--method closed-form (the 16-position closed forms)");
    if (compensation != Compensation::kFull)
      return refuse(fmt::format("--compensation {}", to_string(compensation)));
    if (gyro_model != GyroModel::kDrift) return refuse("--gyro-model drift+rate (the gyro's rate terms)");
  }
  if (!(max_uncertainty_ratio > 1.0)) {
    if (error) *error = "max_uncertainty_ratio must exceed 1";
    return false;
  }
  return true;
}

std::string to_string(Method m) {
  return m == Method::kClosedForm ? "closed-form" : "least-squares";
}
std::string to_string(Compensation c) {
  return c == Compensation::kNone ? "none" : c == Compensation::kSeed ? "seed" : "full";
}
Method parse_method(const std::string& t) {
  if (t == "closed-form") return Method::kClosedForm;
  if (t == "least-squares") return Method::kLeastSquares;
  throw Error("unknown method '" + t + "': use closed-form or least-squares.");
}
Compensation parse_compensation(const std::string& t) {
  if (t == "none") return Compensation::kNone;
  if (t == "seed") return Compensation::kSeed;
  if (t == "full") return Compensation::kFull;
  throw Error("unknown compensation '" + t + "': use none, seed or full.");
}

}  // namespace gyrocal
