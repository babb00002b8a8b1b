// gyrocal demo [--sensor accelerometer|imu]: the main job on the default scenario — simulate the 16-position
// test, calibrate it with and without compensation, print the truth beside the estimates, run the error study
// and a Monte Carlo budget, write DIR/record.csv, DIR/result.json and DIR/report.html.
#include <algorithm>
#include <filesystem>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cli.hpp"
#include "gyrocal/analysis/montecarlo.hpp"
#include "gyrocal/analysis/sensitivity.hpp"
#include "gyrocal/core/atomic_file.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/imu_calibration.hpp"
#include "gyrocal/identify/scenario_options.hpp"
#include "gyrocal/model/nominal.hpp"
#include "gyrocal/report/html_report.hpp"
#include "gyrocal/result/calibration_json.hpp"
#include "gyrocal/result/coefficient_order.hpp"
#include "gyrocal/result/imu_calibration_json.hpp"
#include "gyrocal/result/montecarlo_json.hpp"
#include "gyrocal/result/sensitivity_json.hpp"
#include "gyrocal/result/test_statement_json.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "tables.hpp"

namespace gyrocal::cli {

namespace {

/// The demo's three files in `folder`, staged (the first three elements) and final: each checked now, before
/// any work, by the rule of every output (docs/interface.md, "Files"): an existing DIR/record.csv is replaced
/// only when gyrocal simulated it, DIR/result.json only when it is an earlier gyrocal result, DIR/report.html
/// only when it is an earlier gyrocal report; any regular file with --force. commit() checks again.
struct DemoFiles {
  std::string record_staged, result_staged, report_staged;
  std::string record, result, report;
};

DemoFiles stage_demo_files(AtomicOutputFolder& folder, bool force) {
  const auto rule = [force](OutputKind kind) {
    return [force, kind](const std::filesystem::path& existing) {
      may_replace(existing.string(), kind, force, "--out");
    };
  };
  DemoFiles f;
  f.record_staged = folder.path("record.csv", rule(OutputKind::kDemoRecord)).string();
  f.result_staged = folder.path("result.json", rule(OutputKind::kResult)).string();
  f.report_staged = folder.path("report.html", rule(OutputKind::kReport)).string();
  f.record = folder.final_path("record.csv").string();
  f.result = folder.final_path("result.json").string();
  f.report = folder.final_path("report.html").string();
  return f;
}

/// `gyrocal demo --sensor accelerometer`: the default accelerometer scenario (docs/accelerometer.md) on an
/// arm longer than nominal, simulated, calibrated by least squares with full compensation and again with the
/// radius error and stretch estimated from the sensor's own data, the truth beside the estimates, the error
/// study and a Monte Carlo budget; the same three files as the gyro's demo.
void accelerometer_demo(const std::string& out, bool force) {
  const Scenario s = demo_accelerometer_scenario();
  AtomicOutputFolder folder(out, "the demo's outputs");
  const DemoFiles files = stage_demo_files(folder, force);
  const std::string& record_staged = files.record_staged;
  const std::string& record = files.record;
  const double top_rate = *std::max_element(s.test.rates_rad_s.begin(), s.test.rates_rad_s.end());
  print_out(
      "gyrocal demo --sensor accelerometer: the default accelerometer scenario (R0 {} m + {:g} um, rates {} "
      "rad/s: up to {:.2f} g; static set, four beta, {} gamma).\n",
      s.centrifuge.radius_m, s.errors.radius_error_m * 1e6, fmt::join(s.test.rates_rad_s, ", "),
      radial_level_g(s.site, s.centrifuge.radius_m, top_rate), s.test.gamma_rad.size());
  AtomicOutputFile file(record_staged, /*overwrite=*/false);
  const SimulationSummary sim = simulate_record(s, SimulationOptions{}, file.stream());
  file.commit();
  print_out("simulated {} samples ({:.0f} s of test) for {}\n\n", sim.samples, sim.duration_s, record);

  std::vector<std::string> labels = {"least squares, full", "radius from the sensor"};
  std::vector<CalibrationResult> results;
  CalibrationChoices choices;
  results.push_back(calibrate_record(record_staged, s.model(), s.test, calibration_options(s, choices)));
  choices.estimate = std::vector<std::string>{"radius_error", "radius_stretch"};
  results.push_back(calibrate_record(record_staged, s.model(), s.test, calibration_options(s, choices)));
  print_out("{}\n", sensor_comparison_table(labels, results, kAccelerometerParameters,
                                            s.accelerometer.coefficients.values));
  const CalibrationResult& main = results.front();
  print_out("{}\n", main.BriefReport());
  for (const std::string& w : main.warnings) print_out("- {}\n", w);
  print_out("\nthe radius from the sensor (true values beside):\n");
  for (const MachineErrorEstimate& e : results.back().machine_errors) {
    // In microns (per (rad/s)^2) where the error is a length: the arm is measured to a few microns.
    const double to_um = e.unit.rfind("m", 0) == 0 ? 1e6 : 1.0;
    const std::string unit = to_um == 1e6 ? "u" + e.unit : e.unit;
    print_out(
        "  {:<16} {:>24} {}   (true {:g})\n", e.parameter.label(),
        e.identifiable ? format_value_std(e.value * to_um, e.std * to_um) : std::string("not identifiable"),
        unit, e.configured * to_um);
  }

  nlohmann::ordered_json j = calibration_to_json(main);
  j["record"] = record;
  nlohmann::ordered_json truth = nlohmann::ordered_json::object();
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k)
    truth[std::string(kAccelerometerParameters[k].name)] = s.accelerometer.coefficients.values[k];
  j["truth"] = truth;
  j["plan"] = plan_to_json(s.test);
  // The g-levels, sequence and the inputs of the linearity plot (docs/report.md); no unit under test.
  add_test_statement(j, s, nullptr, main.positions, record);
  j["comparison"] = nlohmann::json::array();
  for (std::size_t i = 0; i < results.size(); ++i) {
    const nlohmann::ordered_json r = calibration_to_json(results[i]);
    j["comparison"].push_back({{"label", labels[i]}, {"coefficients", r["coefficients"]}});
  }
  j["radius_from_the_sensor"] = calibration_to_json(results.back())["machine_errors"];
  print_out("\nsensitivity study (each machine error alone, exact shifts) and a fast Monte Carlo...\n");
  const SensitivityResult sensitivity = sensitivity_study(s);
  j["sensitivity"] = in_coefficient_order(sensitivity_to_json(sensitivity), s.sensor_kind);
  MonteCarloOptions mc;
  mc.trials = 20000;
  const MonteCarloResult budget = monte_carlo(s, mc);
  j["montecarlo"] = in_coefficient_order(montecarlo_to_json(budget), s.sensor_kind);
  print_out("{} machine-error rows studied; {} Monte Carlo trials ({} mode)\n", sensitivity.rows.size(),
            budget.trials, to_string(budget.mode));

  const std::string& result_path = files.result;
  j["config"] = nullptr;  // the built-in accelerometer demo scenario
  mark_result(j, "calibration");
  write_file_atomically(files.result_staged, j.dump(2) + "\n", false);
  HtmlReportOptions report;
  report.title = "gyrocal demo: the default accelerometer scenario";
  report.source = result_path;
  const std::string& report_path = files.report;
  write_file_atomically(files.report_staged, render_html_report(j, report), false);
  folder.commit();
  print_out("\nwrote {}, {} and {}\n", record, result_path, report_path);
}

/// `gyrocal demo --sensor imu`: the default IMU (docs/imu.md: six channels written as increments) on the
/// accelerometer demo's arm, simulated, calibrated jointly with the radius error and stretch estimated from
/// the unit's own data, every channel's truth beside its estimates; DIR/record.csv, DIR/result.json and
/// DIR/report.html (imu_report.hpp).
void imu_demo(const std::string& out, bool force) {
  const Scenario s = demo_imu_scenario();
  AtomicOutputFolder folder(out, "the demo's outputs");
  const DemoFiles files = stage_demo_files(folder, force);
  const std::string& record_staged = files.record_staged;
  const std::string& record = files.record;
  const std::string& result_path = files.result;
  print_out(
      "gyrocal demo --sensor imu: the default IMU ({} channels as increments) on R0 {} m + {:g} um, rates {} "
      "rad/s, static set, four beta, {} gamma.\n",
      s.imu_channels.size(), s.centrifuge.radius_m, s.errors.radius_error_m * 1e6,
      fmt::join(s.test.rates_rad_s, ", "), s.test.gamma_rad.size());
  AtomicOutputFile file(record_staged, /*overwrite=*/false);
  const SimulationSummary sim = simulate_record(s, SimulationOptions{}, file.stream());
  file.commit();
  print_out("simulated {} samples ({:.0f} s of test) for {}\n\n", sim.samples, sim.duration_s, record);
  // The machine as configured but for the arm, whose error and stretch the unit's data measure.
  Scenario configured = s;
  configured.errors.radius_error_m = 0.0;
  configured.errors.radius_stretch_m_per_rad2_s2 = 0.0;
  CalibrationChoices choices;
  choices.estimate = std::vector<std::string>{"radius_error", "radius_stretch"};
  const CalibrationOptions options = calibration_options(s, choices);
  RecordReader reader(record_staged, s.reading_layout());
  const ImuCalibrationResult r =
      calibrate_imu_record(reader, s.channels(), configured.model(), s.test, options);
  print_out("{}\n", imu_result_table(r));
  print_out("the truth: radius error {:g} um, stretch {:g} um/(rad/s)^2\n", s.errors.radius_error_m * 1e6,
            s.errors.radius_stretch_m_per_rad2_s2 * 1e6);
  nlohmann::ordered_json j = imu_calibration_to_json(r);
  j["record"] = record;
  j["config"] = nullptr;  // the built-in IMU demo scenario
  j["plan"] = plan_to_json(s.test);
  nlohmann::ordered_json truth = nlohmann::ordered_json::object();
  for (const SensorChannel& c : s.imu_channels) {
    nlohmann::ordered_json t = nlohmann::ordered_json::object();
    if (const auto* g = std::get_if<Gyro>(&c.sensor))
      for (std::size_t k = 0; k < kNumGyroCoefficients; ++k)
        t[std::string(kCoefficientNames[k])] = g->drift.values[k];
    else
      for (std::size_t k = 0; k < kNumAccelCoefficients; ++k)
        t[std::string(kAccelerometerParameters[k].name)] =
            std::get<Accelerometer>(c.sensor).coefficients.values[k] *
            (kAccelerometerParameters[k].name == "K1" ? c.output.scale : 1.0);
    truth[c.name] = t;
  }
  j["truth"] = truth;
  j["truth_machine"] = {{"radius_error_m", s.errors.radius_error_m},
                        {"radius_stretch_m_per_rad2_s2", s.errors.radius_stretch_m_per_rad2_s2}};
  mark_result(j, "calibration");
  write_file_atomically(files.result_staged, j.dump(2) + "\n", false);
  // The page is drawn from the result as `gyrocal report` reads it back (imu_report.hpp).
  HtmlReportOptions report;
  report.title = "gyrocal demo: the default IMU";
  report.source = result_path;
  write_file_atomically(files.report_staged, render_html_report(nlohmann::json::parse(j.dump()), report),
                        false);
  folder.commit();
  print_out("\nwrote {}, {} and {}\n", record, result_path, files.report);
}

}  // namespace

void register_demo(CLI::App& app) {
  struct Options {
    std::string out = "gyrocal-demo";
    std::string sensor = "gyro";
    bool force = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("demo", "The main job on the built-in default scenario");
  sub->add_option("--out", opt->out,
                  "Folder for record.csv, result.json and report.html: created, or those three files in it "
                  "replaced, all together at the end, when they are an earlier demo's (else give --force)");
  sub->add_flag("--force", opt->force,
                "Replace an existing record.csv, result.json or report.html in the --out folder that is not "
                "an earlier output of gyrocal");
  sub->add_option(
         "--sensor", opt->sensor,
         "gyro (default), accelerometer or imu: the default scenario of that sensor (gyrocal init --sensor)")
      ->check(CLI::IsMember({"gyro", "accelerometer", "imu"}));
  sub->callback([opt] {
    if (opt->sensor == "imu") {
      imu_demo(opt->out, opt->force);
      return;
    }
    if (opt->sensor == "accelerometer") {
      accelerometer_demo(opt->out, opt->force);
      return;
    }
    const Scenario s = demo_scenario();
    // The three files are built in a staging folder and moved into place together at the end: an error or
    // an interruption leaves the folder as it was (docs/interface.md, "Files").
    AtomicOutputFolder folder(opt->out, "the demo's outputs");
    const DemoFiles files = stage_demo_files(folder, opt->force);
    const std::string& record_staged = files.record_staged;
    const std::string& result_staged = files.result_staged;
    const std::string& report_staged = files.report_staged;
    const std::string& record = files.record;

    print_out(
        "gyrocal demo: the default scenario of docs/physics.md section 11 (R0 {} m, {} rad/s, Ar {:.3f} "
        "g).\n",
        s.centrifuge.radius_m, s.centrifuge.rate_rad_s,
        radial_level_g(s.site, s.centrifuge.radius_m, s.centrifuge.rate_rad_s));
    AtomicOutputFile file(record_staged, /*overwrite=*/false);
    const SimulationSummary sim = simulate_record(s, SimulationOptions{}, file.stream());
    file.commit();
    print_out("simulated {} samples ({:.0f} s of test) for {}\n\n", sim.samples, sim.duration_s, record);

    struct Run {
      std::string label;
      Method method;
      Compensation compensation;
    };
    const std::vector<Run> runs = {{"closed form, none", Method::kClosedForm, Compensation::kNone},
                                   {"closed form, seed", Method::kClosedForm, Compensation::kSeed},
                                   {"closed form, full", Method::kClosedForm, Compensation::kFull},
                                   {"least squares, full", Method::kLeastSquares, Compensation::kFull}};
    std::vector<std::string> labels;
    std::vector<CalibrationResult> results;
    for (const Run& run : runs) {
      CalibrationOptions options;
      options.method = run.method;
      options.compensation = run.compensation;
      options.reduce = s.reduce;
      labels.push_back(run.label);
      results.push_back(calibrate_record(record_staged, s.model(), s.test, options));
    }
    print_out("{}\n", comparison_table(labels, results, &s.gyro));
    const CalibrationResult& main = results.back();
    print_out("{}\n", main.BriefReport());
    for (const std::string& w : main.warnings) print_out("- {}\n", w);

    nlohmann::ordered_json j = calibration_to_json(main);
    j["record"] = record;
    j["truth"] = coefficients_to_json(s.gyro);
    j["plan"] = plan_to_json(s.test);
    j["comparison"] = nlohmann::json::array();
    for (std::size_t i = 0; i < results.size(); ++i)
      j["comparison"].push_back(
          {{"label", labels[i]}, {"coefficients", calibration_to_json(results[i])["coefficients"]}});
    // The seed's error study and the uncertainty budget (10% uncertainty on each configured error).
    print_out("\nsensitivity study (each machine error alone, exact shifts) and a fast Monte Carlo...\n");
    const SensitivityResult sensitivity = sensitivity_study(s);
    j["sensitivity"] = sensitivity_to_json(sensitivity);
    MonteCarloOptions mc;
    mc.trials = 100000;
    const MonteCarloResult budget = monte_carlo(s, mc);
    j["montecarlo"] = montecarlo_to_json(budget);
    print_out("{} machine-error rows studied; {} Monte Carlo trials ({} mode)\n", sensitivity.rows.size(),
              budget.trials, to_string(budget.mode));

    const std::string& result_path = files.result;
    j["config"] = nullptr;  // the built-in demo scenario
    mark_result(j, "calibration");
    write_file_atomically(result_staged, j.dump(2) + "\n", false);
    HtmlReportOptions report;
    report.title = "gyrocal demo: the default scenario";
    report.source = result_path;
    const std::string& report_path = files.report;
    write_file_atomically(report_staged, render_html_report(j, report), false);
    folder.commit();
    print_out("\nwrote {}, {} and {}\n", record, result_path, report_path);
  });
}

}  // namespace gyrocal::cli
