// gyrocal noise RECORD: the noise of a static record's output (overlapping Allan deviation, IEEE 952 terms);
// of an IMU's record, every channel's (docs/imu.md).
#include <fmt/format.h>

#include "cli.hpp"
#include "gyrocal/analysis/record_noise.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/report/noise_report.hpp"
#include "gyrocal/result/noise_json.hpp"
#include "tables.hpp"

namespace gyrocal::cli {

void register_noise(CLI::App& app) {
  struct Options {
    std::string record, config, json, html;
    bool toml = false, force = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "noise",
      "Noise of a record's output: overlapping Allan deviation with 68.3 % bounds and the IEEE 952 terms");
  sub->add_option("RECORD", opt->record, "Record of a static test (CSV, docs/contract.md)")->required();
  sub->add_option(
      "--config", opt->config,
      "Configuration file (TOML); only its [sensor] kind and [record] section (the record's "
      "layout), and an IMU's [[channel]] tables (each channel's column, scale and form), are used");
  sub->add_option("--json", opt->json, "Write the result as JSON to FILE ('-' = standard output)");
  sub->add_option(
      "--html", opt->html,
      "Write a self-contained HTML report (log-log Allan plot, fitted terms) to FILE ('-' = standard "
      "output)");
  add_force_flag(sub, opt->force);
  sub->add_flag("--toml", opt->toml,
                "Print the fitted terms as a [gyro.noise] (or [accelerometer.noise]) configuration section");
  sub->callback([opt] {
    refuse_to_overwrite_input(opt->json, opt->record);
    refuse_to_overwrite_input(opt->json, opt->config);
    refuse_to_overwrite_input(opt->html, opt->record);
    refuse_to_overwrite_input(opt->html, opt->config);
    if (!opt->json.empty() && opt->json == opt->html && opt->json != "-")
      throw Error(fmt::format("--json and --html both name {}: give each its own file.", opt->json));
    if (opt->json == "-" && opt->html == "-")
      throw Error("--json and --html cannot both write to standard output.");
    check_output(opt->html, OutputKind::kReport, opt->force, "--html");
    check_output(opt->json, OutputKind::kResult, opt->force, "--json");
    const Scenario s = load_configuration(opt->config);
    if (s.is_imu()) {
      // A whole IMU (docs/imu.md, "What serves an IMU"): every channel's terms, each in its own unit.
      if (opt->toml)
        throw Error(
            "noise --toml prints one sensor's [gyro.noise] or [accelerometer.noise] section; an IMU's terms "
            "belong in each [[channel]]'s [channel.noise]: take them from the table or --json "
            "(docs/imu.md).");
      if (!opt->html.empty())
        throw Error(
            "noise --html does not serve an IMU configuration yet ([sensor] kind = \"imu\"): its report "
            "draws one output's Allan deviation; use the table or --json, which hold every channel's "
            "(docs/imu.md).");
      const ImuRecordNoise r = characterise_imu_record_noise(opt->record, s.channels(), *s.reading_layout());
      if (!opt->json.empty()) write_result(opt->json, imu_noise_to_json(r), "noise", opt->force);
      if (opt->json != "-") print_out("{}", imu_noise_table(r));
      return;
    }
    // With a configuration, its sensor's output is characterised (a record of the other sensor is refused);
    // without one, the record's output column says which sensor (accel_g: an accelerometer).
    RecordNoiseOptions noise_options;
    if (!opt->config.empty()) {
      noise_options.sensor = s.sensor_kind;
      noise_options.config_name = opt->config;
    }
    const RecordNoise r = characterise_record_noise(opt->record, noise_options, s.record);
    const nlohmann::json j = noise_to_json(r);
    // Both outputs are opened (and a refused path refused) before either is written: a refused --html
    // leaves no --json, and a refused --json no report.
    nlohmann::json marked = j;
    mark_result(marked, "noise");
    std::string html;
    if (!opt->html.empty()) {
      HtmlReportOptions options;
      options.title = "gyrocal noise report";
      options.source = opt->record;
      std::vector<std::string> problems;
      options.problems = &problems;
      html = render_noise_html_report(j, options);
      if (!problems.empty())
        throw Error(fmt::format("the noise report of {} is incomplete: {}", opt->record, problems.front()));
    }
    const std::unique_ptr<AtomicOutputFile> html_file =
        opt->html.empty() ? nullptr : open_output(opt->html, OutputKind::kReport, opt->force, "--html");
    const std::unique_ptr<AtomicOutputFile> json_file =
        opt->json.empty() ? nullptr : open_output(opt->json, OutputKind::kResult, opt->force, "--json");
    if (html_file) html_file->write(html);
    if (json_file) json_file->write(marked.dump(2) + "\n");
    if (html_file) html_file->commit();
    if (json_file) json_file->commit();
    if (opt->toml) {
      print_out("{}", noise_to_toml(r));
    } else if (opt->json != "-" && opt->html != "-") {
      print_out("{}", noise_table(r));
    }
  });
}

}  // namespace gyrocal::cli
