// gyrocal init [FILE] [--sensor accelerometer|imu]: the default scenario (of the gyro, of an accelerometer or
// of a whole IMU) as a commented configuration.
#include "cli.hpp"
#include "gyrocal/config/config_io.hpp"

namespace gyrocal::cli {

void register_init(CLI::App& app) {
  struct Options {
    std::string file = "-";
    std::string sensor = "gyro";
    bool force = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("init", "Write the default scenario as a commented configuration file");
  sub->add_option("FILE", opt->file, "Configuration file to write ('-' or none: standard output)");
  sub->add_flag("--force", opt->force, "Overwrite an existing file");
  sub->add_option("--sensor", opt->sensor,
                  "gyro (default), accelerometer or imu: the default scenario of that sensor "
                  "(docs/accelerometer.md), or of a six-channel IMU (docs/imu.md)")
      ->check(CLI::IsMember({"gyro", "accelerometer", "imu"}));
  sub->callback([opt] {
    const Scenario s = opt->sensor == "accelerometer" ? default_accelerometer_scenario()
                       : opt->sensor == "imu"         ? default_imu_scenario()
                                                      : default_scenario();
    write_output(opt->file, scenario_to_toml(s), OutputKind::kConfiguration, opt->force, "FILE");
  });
}

}  // namespace gyrocal::cli
