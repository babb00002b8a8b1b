// gyrocal simulate: simulate a whole test into a record (INTERFACE.md).
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>

#include <fmt/format.h>

#include "cli.hpp"
#include "gyrocal/core/atomic_file.hpp"
#include "gyrocal/simulate/simulator.hpp"

namespace gyrocal::cli {
namespace {

std::string size_text(std::uintmax_t bytes) {
  if (bytes >= 1000000) return fmt::format("{:.1f} MB", static_cast<double>(bytes) / 1e6);
  if (bytes >= 1000) return fmt::format("{:.1f} kB", static_cast<double>(bytes) / 1e3);
  return fmt::format("{} bytes", bytes);
}

}  // namespace

void register_simulate(CLI::App& app) {
  struct Options {
    std::string config, out;
    std::uint64_t seed = 0;
    bool force = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("simulate", "Simulate a whole test into a record");
  sub->add_option("--config", opt->config, "Configuration file (TOML); default: the built-in scenario");
  sub->add_option("--out", opt->out, "The record to write (CSV)")->required();
  CLI::Option* seed = sub->add_option("--seed", opt->seed, "Random seed of the noise; default: [test] seed");
  sub->add_flag("--force", opt->force, "Overwrite RECORD if it exists");
  sub->callback([opt, seed] {
    refuse_to_overwrite_input(opt->out, opt->config);
    const Scenario scenario = load_configuration(opt->config);
    // A record that calibrate would refuse is not written (the same check as plan's and calibrate's).
    check_feasible(scenario, opt->config);
    SimulationOptions options;
    if (seed->count()) options.seed = opt->seed;
    if (::isatty(STDERR_FILENO)) options.progress = ProgressBar("simulating");

    AtomicOutputFile file(opt->out, opt->force);
    const SimulationSummary summary = simulate_record(scenario, options, file.stream());
    file.commit();
    fmt::print("wrote {}: {} samples, test duration {:.1f} s ({:.2f} h), {}, seed {}\n", opt->out,
               summary.samples, summary.duration_s, summary.duration_s / 3600.0,
               size_text(std::filesystem::file_size(opt->out)), summary.seed);
  });
}

}  // namespace gyrocal::cli
