// gyrocal demo: the main job on the default scenario.
#include <fmt/format.h>

#include "cli.hpp"
#include "gyrocal/model/instant.hpp"
#include "gyrocal/plan/positions.hpp"

namespace gyrocal::cli {

void register_demo(CLI::App& app) {
  struct Options {
    std::string out = "gyrocal-demo";
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("demo", "The main job on the built-in default scenario");
  sub->add_option("--out", opt->out, "Directory for the demo's files");
  sub->callback([] {
    const Scenario s = default_scenario();
    const CentrifugeModel model = s.model();
    fmt::print("gyrocal demo: the 16 positions of the default scenario (MODEL.md sections 7 and 11),\n");
    fmt::print(
        "exact inputs (MODEL.md section 4) beside the seed's nominal ones (section 5), revolution 0.\n\n");
    fmt::print("{:>3} {:>6} {:>6}  {:>16} {:>16}  {:>12} {:>12}  {:>12} {:>12}  {:>12} {:>12}\n", "k", "beta",
               "gamma", "omega_I exact", "nominal", "a_I exact", "nominal", "a_O exact", "nominal",
               "a_S exact", "nominal");
    fmt::print("{:>3} {:>6} {:>6}  {:>16} {:>16}  {:>12} {:>12}  {:>12} {:>12}  {:>12} {:>12}\n", "", "deg",
               "deg", "deg/h", "deg/h", "g", "g", "g", "g", "g", "g");
    for (const Position& p : test_positions(s.test)) {
      const InstantInputs in = inputs_at_gamma(model, p.rate_rad_s, p.beta_rad, p.gamma_rad, 0);
      fmt::print(
          "{:>3} {:>6.0f} {:>6.0f}  {:>16.9f} {:>16.9f}  {:>12.7f} {:>12.7f}  {:>12.7f} {:>12.7f}  {:>12.7f} "
          "{:>12.7f}\n",
          p.index, p.beta_rad * kRadToDeg, p.gamma_rad * kRadToDeg,
          in.exact.rate_rad_s.x() * kRadPerSecToDegPerHour, in.nominal.omega_I_rad_s * kRadPerSecToDegPerHour,
          in.exact.specific_force_g.x(), in.nominal.a_I_g, in.exact.specific_force_g.y(), in.nominal.a_O_g,
          in.exact.specific_force_g.z(), in.nominal.a_S_g);
    }
  });
}

}  // namespace gyrocal::cli
