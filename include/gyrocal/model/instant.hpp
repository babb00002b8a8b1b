#pragma once
// Everything the model says about one instant: joint angles, exact and nominal inputs (`gyrocal inputs`).
#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/model/nominal.hpp"

namespace gyrocal {

struct InstantInputs {
  double time_s = 0.0;  ///< time since the start of the dwell, s
  JointState joints;    ///< theta, psi_r, beta and their rates
  SensorInputs exact;   ///< docs/physics.md section 4
  NominalInputs
      nominal;  ///< docs/physics.md section 5, with the seed's k1, k2, delta omega of the configured errors
};

/// The instant t (s) of a dwell at main rate omega (rad/s; 0 = stopped) and position beta (rad).
InstantInputs inputs_at_time(const CentrifugeModel& model, double rate_rad_s, double beta_rad, double time_s);

/// The instant at which gamma = gamma_rad during revolution `revolution` (>= 0) of the main axis, counted
/// from t = 0. With the main axis stopped (omega = 0) the platform is indexed to gamma and t = 0.
InstantInputs inputs_at_gamma(const CentrifugeModel& model, double rate_rad_s, double beta_rad,
                              double gamma_rad, int revolution);

}  // namespace gyrocal
