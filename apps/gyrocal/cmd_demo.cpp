// gyrocal demo: the main job on the default scenario — simulate the 16-position test, calibrate it with and
// without compensation, print the truth beside the estimates, run the error study and a Monte Carlo budget,
// write DIR/record.csv, DIR/result.json and DIR/report.html.
#include <filesystem>

#include <fmt/format.h>

#include "cli.hpp"
#include "gyrocal/analysis/montecarlo.hpp"
#include "gyrocal/analysis/sensitivity.hpp"
#include "gyrocal/core/atomic_file.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/model/nominal.hpp"
#include "gyrocal/report/html_report.hpp"
#include "gyrocal/result/calibration_json.hpp"
#include "gyrocal/result/montecarlo_json.hpp"
#include "gyrocal/result/sensitivity_json.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "tables.hpp"

namespace gyrocal::cli {

void register_demo(CLI::App& app) {
  struct Options {
    std::string out = "gyrocal-demo";
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("demo", "The main job on the built-in default scenario");
  sub->add_option("--out", opt->out,
                  "Folder for record.csv, result.json and report.html: created, or those three files in it "
                  "replaced, all together at the end");
  sub->callback([opt] {
    const Scenario s = demo_scenario();
    // The three files are built in a staging folder and moved into place together at the end: an error or
    // an interruption leaves the folder as it was (docs/interface.md, "Files").
    AtomicOutputFolder folder(opt->out, "the demo's outputs");
    const std::string record_staged = folder.path("record.csv").string();
    const std::string result_staged = folder.path("result.json").string();
    const std::string report_staged = folder.path("report.html").string();
    const std::string record = folder.final_path("record.csv").string();

    fmt::print(
        "gyrocal demo: the default scenario of docs/physics.md section 11 (R0 {} m, {} rad/s, Ar {:.3f} "
        "g).\n",
        s.centrifuge.radius_m, s.centrifuge.rate_rad_s,
        radial_level_g(s.site, s.centrifuge.radius_m, s.centrifuge.rate_rad_s));
    AtomicOutputFile file(record_staged, /*overwrite=*/false);
    const SimulationSummary sim = simulate_record(s, SimulationOptions{}, file.stream());
    file.commit();
    fmt::print("simulated {} samples ({:.0f} s of test) for {}\n\n", sim.samples, sim.duration_s, record);

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
    fmt::print("{}\n", comparison_table(labels, results, &s.gyro));
    const CalibrationResult& main = results.back();
    fmt::print("{}\n", main.BriefReport());
    for (const std::string& w : main.warnings) fmt::print("- {}\n", w);

    nlohmann::ordered_json j = calibration_to_json(main);
    j["record"] = record;
    j["truth"] = coefficients_to_json(s.gyro);
    j["plan"] = plan_to_json(s.test);
    j["comparison"] = nlohmann::json::array();
    for (std::size_t i = 0; i < results.size(); ++i)
      j["comparison"].push_back(
          {{"label", labels[i]}, {"coefficients", calibration_to_json(results[i])["coefficients"]}});
    // The seed's error study and the uncertainty budget (10% uncertainty on each configured error).
    fmt::print("\nsensitivity study (each machine error alone, exact shifts) and a fast Monte Carlo...\n");
    const SensitivityResult sensitivity = sensitivity_study(s);
    j["sensitivity"] = sensitivity_to_json(sensitivity);
    MonteCarloOptions mc;
    mc.trials = 100000;
    const MonteCarloResult budget = monte_carlo(s, mc);
    j["montecarlo"] = montecarlo_to_json(budget);
    fmt::print("{} machine-error rows studied; {} Monte Carlo trials ({} mode)\n", sensitivity.rows.size(),
               budget.trials, to_string(budget.mode));

    const std::string result_path = folder.final_path("result.json").string();
    j["config"] = nullptr;  // the built-in demo scenario
    mark_result(j, "calibration");
    write_file_atomically(result_staged, j.dump(2) + "\n", false);
    HtmlReportOptions report;
    report.title = "gyrocal demo: the default scenario";
    report.source = result_path;
    const std::string report_path = folder.final_path("report.html").string();
    write_file_atomically(report_staged, render_html_report(j, report), false);
    folder.commit();
    fmt::print("\nwrote {}, {} and {}\n", record, result_path, report_path);
  });
}

}  // namespace gyrocal::cli
