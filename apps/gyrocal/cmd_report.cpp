// gyrocal report RESULT.json --html FILE: the self-contained HTML report of a result (docs/report.md).
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/report/html_report.hpp"

namespace gyrocal::cli {

void register_report(CLI::App& app) {
  struct Options {
    std::string result, html;
    bool force = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub =
      app.add_subcommand("report", "Write a self-contained HTML report with plots of a result file");
  sub->add_option("RESULT", opt->result, "Result file (JSON) written by gyrocal")->required();
  sub->add_option("--html", opt->html, "Write the report to FILE ('-' = standard output)")->required();
  sub->add_flag("--force", opt->force, "Replace an existing file that is not an earlier gyrocal report");
  sub->callback([opt] {
    refuse_to_overwrite_input(opt->html, opt->result);
    check_output(opt->html, OutputKind::kReport, opt->force, "--html");
    const nlohmann::json result = read_result_file(opt->result);
    const std::string kind = result_kind(result);
    if (kind == "inputs")
      throw Error(
          fmt::format("{} is the output of `gyrocal inputs` (one instant's inputs to the gyro), which has no "
                      "report page; "
                      "report draws the results of calibrate, plan, sensitivity, montecarlo, noise and demo.",
                      opt->result));
    const std::vector<std::string> sections = report_sections_present(result);
    if (sections.empty())
      throw Error(fmt::format(
          "{} contains none of the sections of a gyrocal result (coefficients, positions, sensitivity, "
          "montecarlo, plan, ...).",
          opt->result));
    std::vector<std::string> problems;
    HtmlReportOptions options;
    options.source = opt->result;
    options.problems = &problems;
    const std::string html = render_html_report(result, options);
    for (const auto& p : problems) fmt::print(stderr, "gyrocal: warning: {}: {}\n", opt->result, p);
    // A report is derived from its result and cheap to write again: an earlier report is replaced,
    // any other existing file only with --force (docs/report.md).
    write_output(opt->html, html, OutputKind::kReport, opt->force, "--html");
    // What was written, on standard error when the report itself went to standard output.
    const std::string line = fmt::format(
        "wrote {}: the {} report of {} ({} sections)\n", opt->html == "-" ? "standard output" : opt->html,
        kind == "montecarlo" ? "Monte Carlo" : kind, opt->result, sections.size());
    if (opt->html == "-")
      fmt::print(stderr, "{}", line);
    else
      print_out("{}", line);
  });
}

}  // namespace gyrocal::cli
