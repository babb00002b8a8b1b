#include "gyrocal/model/nominal.hpp"

#include <cmath>

namespace gyrocal {

SeedErrorTerms seed_error_terms(const CentrifugeErrors& e, double counter_angle_rad) {
  SeedErrorTerms t;
  t.k1 = -(e.counter_perpendicularity_y_rad + e.counter_wobble_y_rad.value(counter_angle_rad));
  t.k2 = e.counter_perpendicularity_x_rad + e.counter_wobble_x_rad.value(counter_angle_rad);
  t.delta_omega_rad_s = e.counter_rate_mismatch_rad_s;
  return t;
}

double radial_level_g(const Site& site, double radius_m, double rate_rad_s) {
  return rate_rad_s * radius_m * (rate_rad_s + 2.0 * site.earth_rate_rad_s * std::sin(site.latitude_rad)) /
         site.gravity_m_s2;
}

NominalInputs nominal_inputs(const Site& site, double radius_m, double rate_rad_s, double heading_rad,
                             double beta_rad, double gamma_rad, const SeedErrorTerms& t) {
  const double ar = radial_level_g(site, radius_m, rate_rad_s);
  const double cb = std::cos(beta_rad), sb = std::sin(beta_rad);
  const double cg = std::cos(gamma_rad), sg = std::sin(gamma_rad);
  const double omega_n = site.earth_rate_rad_s * std::cos(site.latitude_rad) * std::cos(heading_rad);
  const double omega_u = t.delta_omega_rad_s + site.earth_rate_rad_s * std::sin(site.latitude_rad);
  NominalInputs n;
  n.a_I_g = -ar * cg * cb + sb;
  n.a_O_g = -ar * sg;
  n.a_S_g = ar * cg * sb + cb;
  n.omega_I_rad_s = ((t.k1 * cg - t.k2 * sg) * rate_rad_s + omega_n) * cb + omega_u * sb;
  return n;
}

NominalInputs nominal_inputs(const CentrifugeModel& model, const JointState& j, bool with_seed_terms,
                             double counter_rate_offset_rad_s) {
  // The platform's heading from the encoders: psi0 + delta_omega*t while spinning, theta0 - gamma when
  // the main axis is stopped and the platform indexed.
  const double heading = j.main_angle_rad + j.counter_angle_rad;
  SeedErrorTerms terms =
      with_seed_terms ? seed_error_terms(model.errors(), j.counter_angle_rad) : SeedErrorTerms{};
  if (counter_rate_offset_rad_s != 0.0) terms.delta_omega_rad_s += counter_rate_offset_rad_s;
  return nominal_inputs(model.site(), model.geometry().radius_m, j.main_rate_rad_s, heading,
                        j.position_angle_rad, j.gamma_rad(), terms);
}

}  // namespace gyrocal
