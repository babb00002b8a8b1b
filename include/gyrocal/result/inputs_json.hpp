#pragma once
// JSON of `gyrocal inputs` (docs/contract.md): one instant's joint angles, exact and nominal inputs.
#include <nlohmann/json.hpp>

#include "gyrocal/model/instant.hpp"

namespace gyrocal {

/// time_s, main_angle_deg, counter_angle_deg, beta_deg, gamma_deg, omega_rad_s [I,O,S], specific_force_g
/// [I,O,S], nominal {omega_I_rad_s, a_I_g, a_O_g, a_S_g}; angles as the joints hold them (not wrapped).
nlohmann::json inputs_to_json(const InstantInputs& instant);

}  // namespace gyrocal
