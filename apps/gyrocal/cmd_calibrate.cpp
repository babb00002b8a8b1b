// gyrocal calibrate RECORD: reduce a record and identify the drift coefficients.
#include <fmt/format.h>

#include "cli.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/record_check.hpp"
#include "gyrocal/identify/scenario_options.hpp"
#include "gyrocal/identify/unknowns.hpp"
#include "gyrocal/result/calibration_json.hpp"
#include "tables.hpp"

namespace gyrocal::cli {

void register_calibrate(CLI::App& app) {
  struct Options {
    std::string record, config, json, method = "least-squares", compensation = "full", estimate;
    std::string gyro_model;  // empty: [calibration] gyro_model
    std::string reduction;   // empty: [calibration] reduction
    bool force = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("calibrate", "Reduce a record and identify the drift coefficients");
  sub->add_option("RECORD", opt->record, "Test record (CSV, docs/contract.md)")->required();
  sub->add_option(
      "--config", opt->config,
      "Configuration file (TOML): the machine, site and plan of the test, and the record's layout "
      "([record])");
  sub->add_option("--method", opt->method, "closed-form or least-squares (default)")
      ->check(CLI::IsMember({"closed-form", "least-squares"}));
  sub->add_option("--compensation", opt->compensation, kCompensationHelp)
      ->check(CLI::IsMember({"none", "seed", "full"}));
  sub->add_option("--reduction", opt->reduction,
                  "harmonic (harmonic fit in gamma with drift) or window (mean around each gamma); default: "
                  "[calibration] reduction, else harmonic")
      ->check(CLI::IsMember({"harmonic", "window"}));
  sub->add_option(
      "--estimate", opt->estimate,
      "Machine errors estimated from the data with the coefficients, NAME[,NAME...] (NAME, NAME_I/_O/_S, "
      "NAME:N for a harmonic; docs/self_calibration.md); overrides [calibration] estimate");
  add_gyro_model_option(sub, opt->gyro_model);
  sub->add_option("--json", opt->json, "Write the result as JSON to FILE ('-' = standard output)");
  add_force_flag(sub, opt->force);
  sub->callback([opt] {
    refuse_to_overwrite_input(opt->json, opt->record);
    refuse_to_overwrite_input(opt->json, opt->config);
    check_output(opt->json, OutputKind::kResult, opt->force, "--json");
    const Scenario s = load_configuration(opt->config);
    // The options as the library builds them for every caller (identify/scenario_options.hpp).
    CalibrationChoices choices;
    choices.method = opt->method;
    choices.compensation = opt->compensation;
    if (!opt->estimate.empty()) choices.estimate = split_names(opt->estimate);
    choices.gyro_model = opt->gyro_model;
    choices.reduction = opt->reduction;
    const CalibrationOptions options = calibration_options(s, choices);
    check_feasible(s, opt->config, options.reduce);
    require_angle_columns(s.record, opt->record);
    // The record's output column and metadata against the configuration, before its rows are read
    // (docs/interface.md). The record is opened once: the reader that read its head reads its rows (a pipe,
    // a FIFO or /dev/stdin can be read only once).
    const std::string config_name = opt->config.empty() ? "the built-in scenario" : opt->config;
    RecordReader reader(opt->record, s.record);
    require_output_for_sensor(reader, s.sensor_kind, config_name);
    const std::vector<std::string> metadata_warnings =
        check_record_metadata(reader.metadata(), opt->record, s, config_name);
    for (const std::string& w : metadata_warnings) fmt::print(stderr, "gyrocal: warning: {}\n", w);
    CalibrationResult r = calibrate_record(reader, s.model(), s.test, options);
    r.warnings.insert(r.warnings.begin(), metadata_warnings.begin(), metadata_warnings.end());
    if (!opt->json.empty()) {
      nlohmann::ordered_json j = calibration_to_json(r);
      // Provenance (docs/interface.md): the record, the configuration (null: the built-in scenario), the
      // plan.
      j["record"] = opt->record;
      j["config"] = opt->config.empty() ? nlohmann::json(nullptr) : nlohmann::json(opt->config);
      j["plan"] = plan_to_json(s.test);
      write_result(opt->json, std::move(j), "calibration", opt->force);
    }
    if (opt->json != "-") print_out("{}", result_table(r));
  });
}

}  // namespace gyrocal::cli
