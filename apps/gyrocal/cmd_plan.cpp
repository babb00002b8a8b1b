// gyrocal plan: identifiability and predicted uncertainty of the configured test, before running it.
#include <fmt/format.h>

#include "cli.hpp"
#include "gyrocal/analysis/predict.hpp"
#include "gyrocal/analysis/predict_imu.hpp"
#include "gyrocal/identify/scenario_options.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/identify/unknowns.hpp"
#include "gyrocal/plan/positions.hpp"
#include "gyrocal/result/calibration_json.hpp"
#include "gyrocal/result/imu_calibration_json.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "tables.hpp"

namespace gyrocal::cli {
namespace {

/// "4 rates x 4 beta x 8 gamma": how the configured positions multiply (a static set's gamma are its holds).
std::string position_factors(const TestSpec& t) {
  std::string out = fmt::format("{} rate{}", t.rates_rad_s.size(), t.rates_rad_s.size() == 1 ? "" : "s");
  if (t.counter_rate_offsets_rad_s.size() > 1)
    out += fmt::format(" x {} counter rate offsets", t.counter_rate_offsets_rad_s.size());
  return out + fmt::format(" x {} beta x {} gamma", t.beta_rad.size(), t.gamma_rad.size());
}

/// The gammas, deg, as a list ("0, 51.43, 102.86").
std::string degrees_list(const std::vector<double>& radians) {
  std::string out;
  for (const double g : radians) out += fmt::format("{}{:.2f}", out.empty() ? "" : ", ", g * kRadToDeg);
  return out;
}

bool has_spinning_dwell(const TestSpec& t) {
  for (const double r : t.rates_rad_s)
    if (r != 0.0) return true;
  for (const double o : t.counter_rate_offsets_rad_s)
    if (o != 0.0) return true;
  return false;
}

/// The reduction the prediction assumes, as calibrate will reduce the record, and how the configured
/// positions become the reduced ones (`reduced`): an accelerometer's harmonic reduction keeps a spinning
/// dwell's whole harmonic content as values at 2 n + 1 evenly spaced gamma whatever [test] gamma_deg lists
/// (only the static holds follow it); the window reduction and the gyro's read each dwell at gamma_deg.
std::string reduction_text(const Scenario& s, const ReduceOptions& reduce, std::size_t reduced) {
  const bool harmonic = reduce.method == ReduceOptions::Method::kHarmonicFit;
  const TestSpec plan = reduction_plan(s.test, reduction_kind(s.channels()), reduce);
  std::string text = fmt::format(
      "Reduced by the {} reduction, as calibrate reduces the record (--reduction, [calibration] reduction): ",
      harmonic ? "harmonic" : "window");
  if (!plan.spinning_gamma_rad.empty() && has_spinning_dwell(s.test))
    text += fmt::format(
        "each spinning dwell to the {} values of its harmonic content at gamma {} deg whatever [test] "
        "gamma_deg lists (gamma_deg sets the static holds only), each static hold at its gamma",
        plan.spinning_gamma_rad.size(), degrees_list(plan.spinning_gamma_rad));
  else
    text += fmt::format("each dwell {} at [test] gamma_deg",
                        harmonic ? "fitted with its harmonics and read" : "averaged around each gamma");
  return text + fmt::format("; {} reduced positions.", reduced);
}

/// Every rate of the test with its centripetal level Ar = omega^2 R0 / g (g-levels, the static set's 0 g).
std::string g_levels_text(const Scenario& s) {
  std::string levels;
  for (const double rate : s.test.rates_rad_s) {
    const double ar = rate * rate * s.centrifuge.radius_m / s.site.gravity_m_s2;
    levels += fmt::format("{}{} rad/s: {}", levels.empty() ? "" : "; ", rate,
                          rate == 0.0 ? std::string("static") : fmt::format("Ar = {:.4g} g", ar));
  }
  return fmt::format("The rates and their g-levels (Ar = omega^2 R0 / g at R0 = {} m): {}.",
                     s.centrifuge.radius_m, levels);
}

/// The reduction of reduction_text as JSON: method, reduced positions, a spinning dwell's gamma (deg).
nlohmann::ordered_json reduction_to_json(const Scenario& s, const ReduceOptions& reduce,
                                         std::size_t reduced) {
  const TestSpec plan = reduction_plan(s.test, reduction_kind(s.channels()), reduce);
  nlohmann::ordered_json j;
  j["method"] = reduce.method == ReduceOptions::Method::kHarmonicFit ? "harmonic" : "window";
  j["positions"] = reduced;
  nlohmann::json gammas = nlohmann::json::array();
  for (const double g : spinning_gammas(plan)) gammas.push_back(g * kRadToDeg);
  j["spinning_gamma_deg"] = gammas;
  return j;
}

/// The test's duration and the record simulate writes of it, one line.
std::string record_size_text(const Scenario& s) {
  const RecordSize size = estimate_record_size(s);
  return fmt::format("The test lasts {:.1f} s ({:.2f} h); simulate writes {} rows, about {}.\n",
                     size.duration_s, size.duration_s / 3600.0, size.rows, size_text(size.bytes));
}

/// `plan` of an IMU (docs/imu.md, "Planning an IMU"): every channel's predicted uncertainties from the joint
/// solve, as JSON (the calibration result's shape) and as calibrate's table.
void plan_imu(const Scenario& s, const CalibrationOptions& options, const std::string& config,
              const std::string& json, bool force) {
  const ImuCalibrationResult r = predict_imu_calibration(s, options);
  const std::size_t reduced = r.channels.empty() ? 0 : r.channels.front().positions.size();
  if (!json.empty()) {
    nlohmann::ordered_json j = imu_calibration_to_json(r);
    j["config"] = config.empty() ? nlohmann::json(nullptr) : nlohmann::json(config);
    j["plan"] = plan_to_json(s.test);
    j["reduction"] = reduction_to_json(s, options.reduce, reduced);
    write_result(json, std::move(j), "plan", force);
  }
  if (json == "-") return;
  print_out(
      "The configured test: {} positions ({}), {} revolutions per dwell at {} Hz; an IMU of {} channels.\n",
      test_positions(s.test).size(), position_factors(s.test), s.test.revolutions, s.test.sample_rate_hz,
      s.channels().size());
  print_out("{}\n", reduction_text(s, options.reduce, reduced));
  print_out("{}\n", g_levels_text(s));
  print_out("{}", record_size_text(s));
  print_out(
      "Predicted from each channel's configured noise ([channel.noise]); estimates are the configured "
      "truth.\n\n");
  print_out("{}", imu_result_table(r));
}

}  // namespace

void register_plan(CLI::App& app) {
  struct Options {
    std::string config, json, method = "least-squares", compensation = "full", estimate;
    std::string gyro_model;  // empty: [calibration] gyro_model
    std::string reduction;   // empty: [calibration] reduction
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
  sub->add_option(
         "--reduction", opt->reduction,
         "harmonic (harmonic fit in gamma with a linear trend in time) or window (mean around each gamma), "
         "as calibrate reduces the record; default: [calibration] reduction, else harmonic")
      ->check(CLI::IsMember({"harmonic", "window"}));
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
    choices.reduction = opt->reduction;
    const CalibrationOptions options = calibration_options(s, choices);
    check_feasible(s, opt->config, options.reduce);
    if (s.is_imu()) {
      plan_imu(s, options, opt->config, opt->json, opt->force);
      return;
    }
    const CalibrationResult r = predict_calibration(s, options);
    if (!opt->json.empty()) {
      nlohmann::ordered_json j = calibration_to_json(r);
      j["config"] = opt->config.empty() ? nlohmann::json(nullptr) : nlohmann::json(opt->config);
      j["plan"] = plan_to_json(s.test);
      j["reduction"] = reduction_to_json(s, options.reduce, r.positions.size());
      write_result(opt->json, std::move(j), "plan", opt->force);
    }
    if (opt->json == "-") return;
    print_out("The configured test: {} positions ({}), {} revolutions per dwell at {} Hz.\n",
              test_positions(s.test).size(), position_factors(s.test), s.test.revolutions,
              s.test.sample_rate_hz);
    print_out("{}\n", reduction_text(s, options.reduce, r.positions.size()));
    print_out("{}\n", g_levels_text(s));
    print_out("{}", record_size_text(s));
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
