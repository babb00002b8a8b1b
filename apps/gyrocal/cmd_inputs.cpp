// gyrocal inputs: exact and nominal inputs to the gyro at one instant.
#include <climits>
#include <cmath>

#include <fmt/format.h>

#include "cli.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/model/instant.hpp"
#include "gyrocal/reduce/feasibility.hpp"
#include "gyrocal/result/inputs_json.hpp"

namespace gyrocal::cli {
namespace {

/// An angle in degrees as printed: a negative zero (gamma at the start of a dwell, -0.0 in radians) shows as
/// 0, never "-0".
double shown_deg(double rad) {
  return rad * kRadToDeg + 0.0;
}

std::string inputs_table(const InstantInputs& in) {
  const auto& j = in.joints;
  std::string s;
  s += fmt::format("time                 {:.12g} s\n", in.time_s);
  s += fmt::format("main angle theta     {:.12g} deg   rate {:.9g} rad/s\n", shown_deg(j.main_angle_rad),
                   j.main_rate_rad_s);
  s += fmt::format("counter angle psi_r  {:.12g} deg   rate {:.9g} rad/s\n", shown_deg(j.counter_angle_rad),
                   j.counter_rate_rad_s);
  s += fmt::format("beta                 {:.9g} deg\ngamma                {:.12g} deg\n\n",
                   shown_deg(j.position_angle_rad), shown_deg(j.gamma_rad()));
  s += fmt::format("{:<10}{:>22}{:>22}{:>22}\n", "", "exact", "nominal", "exact - nominal");
  s += fmt::format("{:<10}{:>22.12e}{:>22.12e}{:>22.3e}  rad/s\n", "omega_I", in.exact.rate_rad_s.x(),
                   in.nominal.omega_I_rad_s, in.exact.rate_rad_s.x() - in.nominal.omega_I_rad_s);
  s += fmt::format("{:<10}{:>22.12e}{:>22}{:>22}  rad/s\n", "omega_O", in.exact.rate_rad_s.y(), "", "");
  s += fmt::format("{:<10}{:>22.12e}{:>22}{:>22}  rad/s\n", "omega_S", in.exact.rate_rad_s.z(), "", "");
  const double nominal_f[3] = {in.nominal.a_I_g, in.nominal.a_O_g, in.nominal.a_S_g};
  const char* names[3] = {"a_I", "a_O", "a_S"};
  for (int k = 0; k < 3; ++k)
    s += fmt::format("{:<10}{:>22.12f}{:>22.12f}{:>22.3e}  g\n", names[k], in.exact.specific_force_g[k],
                     nominal_f[k], in.exact.specific_force_g[k] - nominal_f[k]);
  return s;
}

/// True when every number `inputs` shows of `in` is finite.
bool all_finite(const InstantInputs& in) {
  const auto& j = in.joints;
  const double values[] = {in.time_s,
                           j.main_angle_rad,
                           j.main_rate_rad_s,
                           j.counter_angle_rad,
                           j.counter_rate_rad_s,
                           j.position_angle_rad,
                           in.nominal.omega_I_rad_s,
                           in.nominal.a_I_g,
                           in.nominal.a_O_g,
                           in.nominal.a_S_g};
  for (const double v : values)
    if (!std::isfinite(v)) return false;
  return in.exact.rate_rad_s.allFinite() && in.exact.specific_force_g.allFinite();
}

}  // namespace

void register_inputs(CLI::App& app) {
  struct Options {
    std::string config, json;
    double beta_deg = 0.0, time_s = 0.0, gamma_deg = 0.0;
    int revolution = 0;
    bool force = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "inputs", "Exact and nominal inputs to the sensor (inertial rate and specific force) at one instant");
  sub->add_option("--config", opt->config, "Configuration file (TOML); default: the built-in scenario");
  sub->add_option("--beta-deg", opt->beta_deg, "Position-platform angle beta, deg")
      ->required()
      ->check(kFinite);
  CLI::Option* time =
      sub->add_option("--time-s", opt->time_s, "Time since the start of the dwell, s")->check(kFinite);
  CLI::Option* gamma =
      sub->add_option("--gamma-deg", opt->gamma_deg, "Arm angle gamma seen from the platform, deg")
          ->check(kFinite);
  CLI::Option* rev = sub->add_option("--revolution", opt->revolution,
                                     "Main-axis revolution (from 0) in which gamma is taken")
                         ->transform(integer_between(0, INT_MAX))
                         ->needs(gamma);
  time->excludes(gamma)->excludes(rev);
  sub->add_option("--json", opt->json, "Write the result as JSON to FILE ('-' = standard output)");
  add_force_flag(sub, opt->force);
  sub->callback([opt, time, gamma] {
    if (time->count() == 0 && gamma->count() == 0)
      throw CLI::ValidationError("inputs", "give the instant with --time-s T or --gamma-deg G");
    refuse_to_overwrite_input(opt->json, opt->config);
    check_output(opt->json, OutputKind::kResult, opt->force, "--json");
    const Scenario s = load_configuration(opt->config);
    refuse_imu(s, "inputs");
    // An instant lies within a test (a larger time would also overflow theta = omega t into inf and every
    // input into NaN).
    if (time->count()) check_time_within_test(opt->time_s, s.test, "--time-s");
    const CentrifugeModel model = s.model();
    const double rate = s.centrifuge.rate_rad_s, beta = opt->beta_deg * kDegToRad;
    const InstantInputs in =
        time->count() ? inputs_at_time(model, rate, beta, opt->time_s)
                      : inputs_at_gamma(model, rate, beta, opt->gamma_deg * kDegToRad, opt->revolution);
    if (!time->count())
      check_time_within_test(
          in.time_s, s.test,
          fmt::format("The instant of --gamma-deg {:g} in --revolution {}", opt->gamma_deg, opt->revolution));
    if (!all_finite(in))
      throw Error(
          fmt::format("the inputs at --beta-deg {:g} and {} are not finite numbers (they overflow with the "
                      "configuration's "
                      "rates and lengths); nothing was written.",
                      opt->beta_deg,
                      time->count() ? fmt::format("--time-s {:g}", opt->time_s)
                                    : fmt::format("--gamma-deg {:g}", opt->gamma_deg)));
    if (!opt->json.empty()) write_result(opt->json, inputs_to_json(in), "inputs", opt->force);
    if (opt->json != "-") print_out("{}", inputs_table(in));
  });
}

}  // namespace gyrocal::cli
