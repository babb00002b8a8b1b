// gyrocal simulate (INTERFACE.md). Placeholder until its issue lands.
#include "cli.hpp"
#include "gyrocal/core/error.hpp"

namespace gyrocal::cli {

void register_simulate(CLI::App& app) {
  CLI::App* sub = app.add_subcommand("simulate", "(not yet available)");
  sub->allow_extras();
  sub->callback([] { throw Error("'gyrocal simulate' is not available yet in this version."); });
}

}  // namespace gyrocal::cli
