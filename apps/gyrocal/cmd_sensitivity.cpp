// gyrocal sensitivity (INTERFACE.md). Placeholder until its issue lands.
#include "cli.hpp"
#include "gyrocal/core/error.hpp"

namespace gyrocal::cli {

void register_sensitivity(CLI::App& app) {
  CLI::App* sub = app.add_subcommand("sensitivity", "(not yet available)");
  sub->allow_extras();
  sub->callback([] { throw Error("'gyrocal sensitivity' is not available yet in this version."); });
}

}  // namespace gyrocal::cli
