// gyrocal noise RECORD: the noise of a static record's output (overlapping Allan deviation, IEEE 952 terms).
#include <fmt/format.h>

#include "cli.hpp"
#include "gyrocal/analysis/record_noise.hpp"
#include "gyrocal/result/noise_json.hpp"
#include "tables.hpp"

namespace gyrocal::cli {

void register_noise(CLI::App& app) {
  struct Options {
    std::string record, config, json;
    bool toml = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "noise",
      "Noise of a record's output: overlapping Allan deviation with 68.3 % bounds and the IEEE 952 terms");
  sub->add_option("RECORD", opt->record, "Record of a static test (CSV, docs/contract.md)")->required();
  sub->add_option("--config", opt->config,
                  "Configuration file (TOML); only its [record] section (the record's layout) is used");
  sub->add_option("--json", opt->json, "Write the result as JSON to FILE ('-' = standard output)");
  sub->add_flag("--toml", opt->toml, "Print the fitted terms as a [gyro.noise] configuration section");
  sub->callback([opt] {
    refuse_to_overwrite_input(opt->json, opt->record);
    refuse_to_overwrite_input(opt->json, opt->config);
    const Scenario s = load_configuration(opt->config);
    const RecordNoise r = characterise_record_noise(opt->record, {}, s.record);
    if (!opt->json.empty()) write_output(opt->json, noise_to_json(r).dump(2) + "\n", true);
    if (opt->toml) {
      fmt::print("{}", noise_to_toml(r));
    } else if (opt->json != "-") {
      fmt::print("{}", noise_table(r));
    }
  });
}

}  // namespace gyrocal::cli
