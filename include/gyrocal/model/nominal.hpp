#pragma once
// The nominal inputs to the gyro (docs/physics.md section 5; the seed's eq. 2-5), written once. The seed's
// first-order machine-error terms k1, k2 and delta omega enter omega_I; the specific force is nominal.
#include "gyrocal/model/centrifuge.hpp"

namespace gyrocal {

/// The seed's first-order error terms of the counter-rotating platform (docs/physics.md section 5).
struct SeedErrorTerms {
  double k1 = 0.0;                 ///< -(count_perp_y + count_wobble_y(psi_r)), rad
  double k2 = 0.0;                 ///< count_perp_x + count_wobble_x(psi_r), rad
  double delta_omega_rad_s = 0.0;  ///< counter_rate_mismatch, rad/s
};

/// k1, k2, delta omega from configured errors at the platform angle psi_r (rad).
SeedErrorTerms seed_error_terms(const CentrifugeErrors& errors, double counter_angle_rad);

/// Nominal inputs at one position: omega_I (rad/s) and the specific force (g) in gyro axes.
struct NominalInputs {
  double omega_I_rad_s = 0.0;
  double a_I_g = 0.0;
  double a_O_g = 0.0;
  double a_S_g = 0.0;
};

/// Ar = omega*R0*(omega + 2*we*sin(lat))/g: the radial level including the radial Coriolis term, g.
double radial_level_g(const Site& site, double radius_m, double rate_rad_s);

/// docs/physics.md section 5 at position beta, gamma (rad) for main rate omega (rad/s, signed), nominal
/// radius R0 (m) and heading psi0 (rad), with the seed's error terms (zero for a perfect machine).
NominalInputs nominal_inputs(const Site& site, double radius_m, double rate_rad_s, double heading_rad,
                             double beta_rad, double gamma_rad, const SeedErrorTerms& terms);

/// Convenience: nominal inputs of `model` at joint state `joints` (beta, gamma and rate from the joints;
/// R0, psi0 from the geometry), with the seed's terms from the configured errors when with_seed_terms.
/// counter_rate_offset_rad_s: the commanded offset of a rate-platform dwell (docs/physics.md section 15),
/// which turns the platform about Up as delta omega does: it adds to Omega_U.
NominalInputs nominal_inputs(const CentrifugeModel& model, const JointState& joints, bool with_seed_terms,
                             double counter_rate_offset_rad_s = 0.0);

}  // namespace gyrocal
