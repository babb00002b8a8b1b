// gyrocal simulate: simulate a whole test into a record (docs/contract.md).
#include <sys/statvfs.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>

#include <fmt/format.h>

#include "cli.hpp"
#include "gyrocal/core/atomic_file.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/plan/timeline.hpp"
#include "gyrocal/simulate/simulator.hpp"

namespace gyrocal::cli {
namespace {

/// A floor on a simulated row's length: five numbers, four commas and a newline, the noisy gyro output
/// alone taking 15 or more characters (a typical row is about 65 bytes).
constexpr std::uint64_t kMinRowBytes = 24;

/// Refuses a record that cannot fit in the free space of the file system that will hold it (a regular
/// file only; a device, a FIFO or standard output has no such limit). The estimate is a floor, so that a
/// record that would fit is never refused; one that fits the floor but not the space fails when the disk
/// is full, with its temporary removed.
void refuse_what_cannot_fit(const AtomicOutputFile& file, std::uint64_t samples) {
  const std::filesystem::path folder =
      file.destination().has_parent_path() ? file.destination().parent_path() : std::filesystem::path(".");
  struct statvfs fs {};
  if (::statvfs(folder.c_str(), &fs) != 0) return;
  const auto free_bytes = static_cast<double>(fs.f_bavail) * static_cast<double>(fs.f_frsize);
  const double needed = static_cast<double>(samples) * static_cast<double>(kMinRowBytes);
  if (needed <= free_bytes) return;
  throw Error(fmt::format(
      "Cannot write the record '{}': its {} samples need at least {} ({} bytes a row; a typical row is "
      "about 65), but the file system that holds '{}' has {} free. Shorten the test (fewer revolutions, "
      "rates, positions or a lower sample_rate_hz) or write elsewhere.",
      file.target().string(), samples, size_text(static_cast<std::uintmax_t>(needed)), kMinRowBytes,
      folder.string(), size_text(static_cast<std::uintmax_t>(free_bytes))));
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
  sub->add_option("--out", opt->out, "The record to write (CSV; '-' = standard output)")->required();
  CLI::Option* seed = sub->add_option("--seed", opt->seed,
                                      "Random seed of the noise, 0 to 2^64-1; default: [test] seed (not "
                                      "--compensation seed, the seed paper's correction)")
                          ->transform(kSeed);
  sub->add_flag("--force", opt->force, "Overwrite RECORD if it exists");
  sub->callback([opt, seed] {
    refuse_to_overwrite_input(opt->out, opt->config);
    check_output(opt->out, OutputKind::kRecord, opt->force, "--out");
    const Scenario scenario = load_configuration(opt->config);
    // A record that calibrate would refuse is not written (the same check as plan's and calibrate's).
    check_feasible(scenario, opt->config, scenario.reduce);
    SimulationOptions options;
    if (seed->count()) options.seed = opt->seed;
    options.progress = ProgressBar("simulating");

    const std::uint64_t samples =
        sample_count(make_timeline(scenario.test, scenario.model()), scenario.test.sample_rate_hz);

    const std::unique_ptr<AtomicOutputFile> file =
        open_output(opt->out, OutputKind::kRecord, opt->force, "--out");
    if (!file->writes_through()) refuse_what_cannot_fit(*file, samples);
    const SimulationSummary summary = simulate_record(scenario, options, file->stream());
    const std::uint64_t bytes = file->bytes();
    file->commit();
    // With the record on standard output, the summary goes to standard error.
    const std::string line =
        fmt::format("wrote {}: {} samples, test duration {:.1f} s ({:.2f} h), {}, seed {}\n",
                    opt->out == "-" ? "standard output" : opt->out, summary.samples, summary.duration_s,
                    summary.duration_s / 3600.0, size_text(bytes), summary.seed);
    if (opt->out == "-")
      fmt::print(stderr, "{}", line);
    else
      print_out("{}", line);
  });
}

}  // namespace gyrocal::cli
