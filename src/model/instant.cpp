#include "gyrocal/model/instant.hpp"

namespace gyrocal {
namespace {

InstantInputs evaluate(const CentrifugeModel& model, const JointState& joints, double time_s) {
  InstantInputs out;
  out.time_s = time_s;
  out.joints = joints;
  out.exact = exact_inputs(model, joints);
  out.nominal = nominal_inputs(model, joints, /*with_seed_terms=*/true);
  return out;
}

}  // namespace

InstantInputs inputs_at_time(const CentrifugeModel& model, double rate_rad_s, double beta_rad,
                             double time_s) {
  return evaluate(model, spinning_joint_state(model, rate_rad_s, beta_rad, time_s), time_s);
}

InstantInputs inputs_at_gamma(const CentrifugeModel& model, double rate_rad_s, double beta_rad,
                              double gamma_rad, int revolution) {
  if (rate_rad_s == 0.0) return evaluate(model, static_joint_state(model, beta_rad, gamma_rad), 0.0);
  return inputs_at_time(model, rate_rad_s, beta_rad, time_at_gamma(model, rate_rad_s, gamma_rad, revolution));
}

}  // namespace gyrocal
