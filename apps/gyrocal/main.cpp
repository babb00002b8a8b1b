// gyrocal: the command line (docs/contract.md). Parsing arguments and printing only; no physics here.
#include <exception>
#include <iostream>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "cli.hpp"
#include "gyrocal/core/atomic_file.hpp"
#include "gyrocal/core/error.hpp"

namespace {

/// The final check of standard output after a command (or CLI11's --help and --version) wrote to it: a write
/// error that went unseen fails the run (docs/interface.md, "Errors and exit status").
int checked_exit(int status) {
  try {
    gyrocal::check_standard_output();
  } catch (const gyrocal::Error& e) {
    fmt::print(stderr, "gyrocal: {}\n", e.what());
    return status == 0 ? 1 : status;
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "gyrocal: calibrate a gyroscope or an accelerometer on a centrifuge with a counter-rotating platform"};
  // At most one subcommand; none at all lists them (below).
  app.require_subcommand(0, 1);
  app.set_version_flag("--version", std::string("gyrocal ") + GYROCAL_VERSION);
  gyrocal::cli::register_demo(app);
  gyrocal::cli::register_init(app);
  gyrocal::cli::register_inputs(app);
  gyrocal::cli::register_simulate(app);
  gyrocal::cli::register_calibrate(app);
  gyrocal::cli::register_plan(app);
  gyrocal::cli::register_sensitivity(app);
  gyrocal::cli::register_montecarlo(app);
  gyrocal::cli::register_report(app);
  gyrocal::cli::register_noise(app);
  gyrocal::cli::register_history(app);
  try {
    app.parse(argc, argv);
    if (app.get_subcommands().empty()) {
      // `gyrocal` alone: the help, which lists the subcommands, and a usage error's status
      // (docs/interface.md): nothing was done.
      fmt::print(stderr, "{}\ngyrocal: give one of the subcommands above.\n", app.help());
      return static_cast<int>(CLI::ExitCodes::RequiredError);
    }
  } catch (const CLI::ParseError& e) {
    // --help and --version print to `out`; it goes to standard output through the one checked writer.
    std::ostringstream out;
    const int status = app.exit(e, out, std::cerr);
    try {
      gyrocal::write_standard_output(out.str());
    } catch (const gyrocal::Error& write_error) {
      fmt::print(stderr, "gyrocal: {}\n", write_error.what());
      return status == 0 ? 1 : status;
    }
    return checked_exit(status);
  } catch (const gyrocal::Error& e) {
    fmt::print(stderr, "gyrocal: {}\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    fmt::print(stderr, "gyrocal: internal error: {}\n", e.what());
    return 2;
  }
  return checked_exit(0);
}
