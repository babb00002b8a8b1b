// gyrocal plan: identifiability and predicted uncertainty of the configured test, before running it.
#include <fmt/format.h>

#include "cli.hpp"
#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/identify/scenario_options.hpp"
#include "gyrocal/identify/unknowns.hpp"
#include "gyrocal/result/calibration_json.hpp"
#include "tables.hpp"

namespace gyrocal::cli {

void register_plan(CLI::App& app) {
  struct Options {
    std::string config, json, method = "least-squares", compensation = "full", estimate;
    std::string gyro_model;  // empty: [calibration] gyro_model
    bool force = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "plan", "Identifiability and predicted uncertainty of the configured test, before running it");
  sub->add_option("--config", opt->config, "Configuration file (TOML); default: the built-in scenario");
  sub->add_option(
         "--method", opt->method,
         "closed-form (a gyro's 16-position test) or least-squares (default; an accelerometer's only)")
      ->check(CLI::IsMember({"closed-form", "least-squares"}));
  sub->add_option("--compensation", opt->compensation, kCompensationHelp)
      ->check(CLI::IsMember({"none", "seed", "full"}));
  sub->add_option(
      "--estimate", opt->estimate,
      "Machine errors estimated from the data with the coefficients, NAME[,NAME...] (NAME, NAME_I/_O/_S, "
      "NAME:N for a harmonic; docs/self_calibration.md); overrides [calibration] estimate");
  add_gyro_model_option(sub, opt->gyro_model);
  sub->add_option("--json", opt->json, "Write the prediction as JSON to FILE ('-' = standard output)");
  add_force_flag(sub, opt->force);
  sub->callback([opt] {
    refuse_to_overwrite_input(opt->json, opt->config);
    check_output(opt->json, OutputKind::kResult, opt->force, "--json");
    const Scenario s = load_configuration(opt->config);
    // The options as the library builds them for every caller (identify/scenario_options.hpp); the
    // prediction models [reduce] and [calibration] reduction.
    CalibrationChoices choices;
    choices.method = opt->method;
    choices.compensation = opt->compensation;
    if (!opt->estimate.empty()) choices.estimate = split_names(opt->estimate);
    choices.gyro_model = opt->gyro_model;
    const CalibrationOptions options = calibration_options(s, choices);
    check_feasible(s, opt->config, options.reduce);
    const CalibrationResult r = predict_calibration(s, options);
    if (!opt->json.empty()) {
      nlohmann::ordered_json j = calibration_to_json(r);
      j["config"] = opt->config.empty() ? nlohmann::json(nullptr) : nlohmann::json(opt->config);
      j["plan"] = plan_to_json(s.test);
      write_result(opt->json, std::move(j), "plan", opt->force);
    }
    if (opt->json == "-") return;
    print_out("The configured test: {} positions, {} revolutions per dwell at {} Hz.\n", r.positions.size(),
              s.test.revolutions, s.test.sample_rate_hz);
    if (s.sensor_kind == SensorKind::kAccelerometer)
      print_out(
          "Predicted from the configured noise (white {} ug/sqrt(Hz)); estimates are the configured "
          "truth.\n\n",
          s.accelerometer.noise.velocity_random_walk_ug_rt_hz);
    else
      print_out(
          "Predicted from the configured noise (angle random walk {} deg/sqrt(h), bias instability {} deg/h, "
          "rate random walk {} deg/h/sqrt(h)); estimates are the configured truth.\n\n",
          s.noise.angle_random_walk_deg_rt_h, s.noise.bias_instability_deg_h,
          s.noise.rate_random_walk_deg_h_rt_h);
    print_out("{}", result_table(r));
  });
}

}  // namespace gyrocal::cli
