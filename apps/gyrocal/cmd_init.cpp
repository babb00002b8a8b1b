// gyrocal init [FILE]: the default scenario as a commented configuration.
#include "cli.hpp"
#include "gyrocal/config/config_io.hpp"

namespace gyrocal::cli {

void register_init(CLI::App& app) {
  struct Options {
    std::string file = "-";
    bool force = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("init", "Write the default scenario as a commented configuration file");
  sub->add_option("FILE", opt->file, "Configuration file to write ('-' or none: standard output)");
  sub->add_flag("--force", opt->force, "Overwrite an existing file");
  sub->callback([opt] {
    write_output(opt->file, scenario_to_toml(default_scenario()), OutputKind::kConfiguration, opt->force,
                 "FILE");
  });
}

}  // namespace gyrocal::cli
