// gyrocal montecarlo: uncertainty budget over random machine errors and noise (docs/contract.md).

#include <algorithm>
#include <chrono>
#include <cstdio>

#include <fmt/format.h>

#include "cli.hpp"
#include "gyrocal/analysis/montecarlo.hpp"
#include "gyrocal/analysis/montecarlo_imu.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/identify/scenario_options.hpp"
#include "gyrocal/identify/unknowns.hpp"
#include "gyrocal/result/coefficient_order.hpp"
#include "gyrocal/result/montecarlo_imu_json.hpp"
#include "gyrocal/result/montecarlo_json.hpp"

namespace gyrocal::cli {
namespace {

std::string montecarlo_table(const MonteCarloResult& r, double seconds) {
  std::string s = fmt::format(
      "{} trials ({} mode, seed {}) in {:.2f} s: {} with compensation {}, {}, which knows the "
      "configured errors only.\nError = estimate - truth. Predicted: the linearised model (mean = noise-free "
      "error at the configured errors). z std: the std over the trials of error / the std the calibration "
      "states ({}).\n\n",
      r.trials, to_string(r.mode), r.seed, seconds, to_string(r.method),
      r.self ? std::string("self") : to_string(r.compensation),
      r.sensor == SensorKind::kGyro ? fmt::format("gyro model {}", to_string(r.gyro_model))
                                    : fmt::format("sensor {}", to_string(r.sensor)),
      r.mode == MonteCarloMode::kSamples ? "each trial's own" : "the configured machine's calibration's");
  std::size_t width = 16;  // the rate errors' names are longer than the coefficients'
  for (const EstimateDistribution& e : r.estimates) width = std::max(width, e.name.size() + 2);
  for (const auto& entry : r.not_identifiable) width = std::max(width, entry.first.size() + 2);
  s += fmt::format("{:<{}}{:>13}{:>13}{:>13}{:>13}{:>8}  {:<10} {}\n", "estimate", width, "mean error", "std",
                   "pred. mean", "pred. std", "z std", "unit", "largest shares of the variance");
  for (const EstimateDistribution& e : r.estimates) {
    std::vector<std::size_t> order(r.sources.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return e.budget[a] > e.budget[b]; });
    std::string shares;
    for (std::size_t k = 0; k < std::min<std::size_t>(3, order.size()); ++k)
      if (e.budget[order[k]] >= 0.005)
        shares += fmt::format("{}{} {:.0f}%", shares.empty() ? "" : ", ", r.sources[order[k]],
                              100.0 * e.budget[order[k]]);
    s += fmt::format("{:<{}}{:>13.4g}{:>13.4g}{:>13.4g}{:>13.4g}{:>8.3g}  {:<10} {}\n", e.name, width, e.mean,
                     e.std, e.predicted_mean, e.predicted_std, e.z_std, e.unit, shares);
  }
  // docs/physics.md section 15: what the plan cannot identify has no distribution, and is said why.
  for (const auto& [name, reason] : r.not_identifiable)
    s += fmt::format("{:<{}}not identifiable: {}\n", name, width, reason);
  s += "\nsources:";
  for (std::size_t k = 0; k < r.sources.size(); ++k)
    s += fmt::format("  {} {:g} {}", r.sources[k], r.source_std[k], r.source_units[k]);
  return s + "\n";
}

/// An IMU's table: per channel each coefficient's mean error, its std, the mean stated std, the plan's std
/// and the z-score's mean and std; then the estimated machine errors alike.
std::string montecarlo_imu_table(const ImuMonteCarloResult& r, double seconds) {
  std::string s = fmt::format(
      "{} trials (samples mode, seed {}) in {:.2f} s ({:.3g} s a trial): an IMU of {} "
      "channels, least squares with compensation full, which knows the configured errors only, gyro model "
      "{}.\nError = estimate - truth (a machine error's truth: its value drawn in the trial). Stated: the "
      "mean "
      "over the trials of the std each calibration states; planned: the plan's. z = error / the trial's "
      "stated std.\n",
      r.trials, r.seed, seconds, seconds / static_cast<double>(r.trials), r.channels.size(),
      to_string(r.gyro_model));
  std::size_t width = 16;  // the rate errors' names are longer than the coefficients'
  for (const ImuChannelDistribution& c : r.channels)
    for (const ImuEstimateDistribution& e : c.coefficients) width = std::max(width, e.name.size() + 2);
  for (const ImuEstimateDistribution& e : r.machine_errors) width = std::max(width, e.name.size() + 2);
  const auto header = [width](const std::string& what) {
    return fmt::format("{:<{}}{:>13}{:>13}{:>13}{:>13}{:>9}{:>8}  {}\n", what, width, "mean error", "std",
                       "stated std", "planned std", "z mean", "z std", "unit");
  };
  const auto row = [&r, width](const ImuEstimateDistribution& e) {
    return fmt::format("{:<{}}{:>13.4g}{:>13.4g}{:>13.4g}{:>13.4g}{:>9.3g}{:>8.3g}  {}{}\n", e.name, width,
                       e.mean, e.std, e.stated_std, e.planned_std, e.z_mean, e.z_std, e.unit,
                       e.trials < r.trials ? fmt::format(" ({} trials identified it)", e.trials) : "");
  };
  for (const ImuChannelDistribution& c : r.channels) {
    s += fmt::format("\nchannel {} ({})\n", c.name, to_string(c.sensor));
    s += header("coefficient");
    for (const ImuEstimateDistribution& e : c.coefficients) s += row(e);
    for (const auto& [name, reason] : c.not_identifiable)
      s += fmt::format("{:<{}}not identifiable: {}\n", name, width, reason);
  }
  if (!r.machine_errors.empty() || !r.not_identifiable.empty()) {
    s += "\nmachine errors estimated\n" + header("error");
    for (const ImuEstimateDistribution& e : r.machine_errors) s += row(e);
    for (const auto& [name, reason] : r.not_identifiable)
      s += fmt::format("{:<{}}not identifiable: {}\n", name, width, reason);
  }
  s += "\nsources: each channel's [channel.noise]";
  for (std::size_t k = 0; k < r.sources.size(); ++k)
    s += fmt::format("  {} {:g} {}", r.sources[k], r.source_std[k], r.source_units[k]);
  return s + "\n";
}

/// `montecarlo` of an IMU (docs/montecarlo.md, "An IMU"): the samples mode, the joint calibration with the
/// configuration's [calibration] estimate.
void run_imu_montecarlo(const Scenario& scenario, MonteCarloOptions options, const std::string& compensation,
                        const std::string& method, const std::string& gyro_model, const std::string& config,
                        const std::string& json, bool force) {
  CalibrationChoices choices;
  choices.method = method;
  choices.compensation = compensation == "self" ? "full" : compensation;
  choices.gyro_model = gyro_model;
  options.calibration = calibration_options(scenario, choices);
  options.self = compensation == "self";
  options.progress = ProgressBar("Monte Carlo");
  const auto start = std::chrono::steady_clock::now();
  const ImuMonteCarloResult result = monte_carlo_imu(scenario, options);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!json.empty()) {
    nlohmann::ordered_json j = montecarlo_imu_to_json(result);
    j["config"] = config.empty() ? nlohmann::json(nullptr) : nlohmann::json(config);
    write_result(json, j, "montecarlo", force);
  }
  if (json != "-") print_out("{}", montecarlo_imu_table(result, seconds));
}

/// The most trials gyrocal runs. Fast mode: about 2 us a trial and core on the default scenario (two
/// passes), so 1e9 trials take about half an hour a core; memory does not grow with trials. Samples mode:
/// each trial simulates and reduces the whole test (about 0.1 s on the default scenario), so 1e5 trials
/// take hours, and every trial's errors are kept for the histograms.
constexpr long long kMaxFastTrials = limits::kTrials;
constexpr long long kMaxSampleTrials = limits::kTrialsWithSamples;

}  // namespace

void register_montecarlo(CLI::App& app) {
  struct Options {
    std::string config, json, method = "least-squares", compensation = "full";
    std::string gyro_model;  // empty: [calibration] gyro_model
    long long trials = 0;
    std::uint64_t seed = 0;
    bool samples = false;
    int threads = 0;
    bool force = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "montecarlo", "Uncertainty budget over random machine errors ([uncertainty]) and noise");
  sub->add_option("--config", opt->config, "Configuration file (TOML); default: the built-in scenario");
  sub->add_option("--trials", opt->trials,
                  "Number of trials: 2 to 1000000000 (1e9), or to 100000 (1e5) with --samples")
      ->required()
      ->transform(
          integer_between(2, kMaxFastTrials, /*check_range=*/false));  // the range below, with reasons
  CLI::Option* seed = sub->add_option("--seed", opt->seed,
                                      "Random seed of the trials' draws, 0 to 2^64-1; default: [test] seed "
                                      "(not --compensation seed, the seed paper's correction)")
                          ->transform(kSeed);
  sub->add_flag("--samples", opt->samples,
                "Run the whole time-series pipeline per trial (slow; checks the fast linearised mode)");
  sub->add_option("--threads", opt->threads,
                  fmt::format("Worker threads, 0 to {}; default (0): all cores", limits::kThreads))
      ->transform(integer_between(0, limits::kThreads));
  sub->add_option(
         "--method", opt->method,
         "closed-form (a gyro's 16-position test) or least-squares (default; an accelerometer's only)")
      ->check(CLI::IsMember({"closed-form", "least-squares"}));
  sub->add_option("--compensation", opt->compensation,
                  std::string(kCompensationHelp) +
                      "; or self (the counter platform's errors estimated from the data; two speeds)")
      ->check(CLI::IsMember({"none", "seed", "full", "self"}));
  add_gyro_model_option(sub, opt->gyro_model);
  sub->add_option("--json", opt->json, "Write the result as JSON to FILE ('-' = standard output)");
  add_force_flag(sub, opt->force);
  sub->callback([opt, seed] {
    const long long most = opt->samples ? kMaxSampleTrials : kMaxFastTrials;
    if (opt->trials < 2 || opt->trials > most) {
      throw Error(fmt::format(
          "--trials {} is {}: {}", opt->trials,
          opt->trials < 2 ? "fewer than 2" : "more than the most gyrocal runs",
          opt->trials < 2 ? "a standard deviation needs at least 2 trials."
          : opt->samples
              ? "with --samples each trial simulates the whole test (about 0.1 s on the default scenario), "
                "so 100000 trials already take hours; use the fast mode (no --samples) for more."
              : "at about 2 us a trial and core, 1000000000 trials take about half an hour a core and give a "
                "standard deviation to 0.002%; more would take days for no visible gain."));
    }
    refuse_to_overwrite_input(opt->json, opt->config);
    check_output(opt->json, OutputKind::kResult, opt->force, "--json");
    const Scenario scenario = load_configuration(opt->config);
    MonteCarloOptions options;
    options.trials = opt->trials;
    options.seed = seed->count() ? opt->seed : scenario.test.seed;
    options.mode = opt->samples ? MonteCarloMode::kSamples : MonteCarloMode::kFast;
    options.threads = opt->threads;
    if (scenario.is_imu()) {
      run_imu_montecarlo(scenario, options, opt->compensation, opt->method, opt->gyro_model, opt->config,
                         opt->json, opt->force);
      return;
    }
    options.calibration.method = parse_method(opt->method);
    options.self = opt->compensation == "self";
    options.calibration.compensation = parse_compensation(options.self ? "full" : opt->compensation);
    options.calibration.gyro_model = chosen_gyro_model(opt->gyro_model, scenario);
    options.calibration.reduce = scenario.reduce;  // [reduce]: --samples reduces each trial's record with it
    options.progress = ProgressBar("Monte Carlo");
    const auto start = std::chrono::steady_clock::now();
    const MonteCarloResult result = monte_carlo(scenario, options);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!opt->json.empty()) {
      nlohmann::json j = montecarlo_to_json(result);
      j["config"] = opt->config.empty() ? nlohmann::json(nullptr) : nlohmann::json(opt->config);
      write_result(opt->json, in_coefficient_order(j, result.sensor), "montecarlo", opt->force);
    }
    if (opt->json != "-") print_out("{}", montecarlo_table(result, seconds));
  });
}

}  // namespace gyrocal::cli
