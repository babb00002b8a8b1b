#include "gyrocal/result/inputs_json.hpp"

namespace gyrocal {

nlohmann::json inputs_to_json(const InstantInputs& in) {
  const auto vec = [](const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
  return {
      {"time_s", in.time_s},
      {"main_angle_deg", in.joints.main_angle_rad * kRadToDeg},
      {"counter_angle_deg", in.joints.counter_angle_rad * kRadToDeg},
      {"beta_deg", in.joints.position_angle_rad * kRadToDeg},
      {"gamma_deg", in.joints.gamma_rad() * kRadToDeg},
      {"main_rate_rad_s", in.joints.main_rate_rad_s},
      {"counter_rate_rad_s", in.joints.counter_rate_rad_s},
      {"omega_rad_s", vec(in.exact.rate_rad_s)},
      {"specific_force_g", vec(in.exact.specific_force_g)},
      {"nominal",
       {{"omega_I_rad_s", in.nominal.omega_I_rad_s},
        {"a_I_g", in.nominal.a_I_g},
        {"a_O_g", in.nominal.a_O_g},
        {"a_S_g", in.nominal.a_S_g}}},
  };
}

}  // namespace gyrocal
