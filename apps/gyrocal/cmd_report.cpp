// gyrocal report RESULT.json --html FILE: the self-contained HTML report of a result (docs/report.md);
// gyrocal report --history DB --unit SERIAL --html FILE: the page of a unit's calibration history
// (docs/history.md).
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/history/read.hpp"
#include "gyrocal/report/history_report.hpp"
#include "gyrocal/report/html_report.hpp"
#include "gyrocal/report/imu_report.hpp"

namespace gyrocal::cli {

namespace {

/// What `report` wrote, on standard error when the report itself went to standard output.
void say_written(const std::string& html, const std::string& line) {
  if (html == "-")
    fmt::print(stderr, "{}", line);
  else
    print_out("{}", line);
}

void write_history_page(const std::string& database, const std::string& unit, const std::string& html,
                        bool force) {
  refuse_to_overwrite_input(html, database);
  check_output(html, OutputKind::kReport, force, "--html");
  const history::HistorySummary summary = history::read_unit_history(database, unit);
  std::vector<std::string> problems;
  HtmlReportOptions options;
  options.source = database;
  options.problems = &problems;
  const std::string page = history_report_html(summary, options);
  for (const auto& p : problems) fmt::print(stderr, "gyrocal: warning: {}: {}\n", database, p);
  write_output(html, page, OutputKind::kReport, force, "--html");
  std::size_t charted = 0;
  for (const auto* list : {&summary.coefficients, &summary.machine_errors})
    for (const history::QuantityHistory& q : *list) charted += q.stats ? 1 : 0;
  say_written(html, fmt::format("wrote {}: the calibration history of unit {} in {} ({} run{}, {} control "
                                "chart{})\n",
                                html == "-" ? "standard output" : html, unit, database, summary.runs.size(),
                                summary.runs.size() == 1 ? "" : "s", charted, charted == 1 ? "" : "s"));
}

}  // namespace

void register_report(CLI::App& app) {
  struct Options {
    std::string result, html, history, unit;
    bool force = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "report",
      "Write a self-contained HTML report with plots of a result file, or of a unit's calibration history");
  CLI::Option* result = sub->add_option("RESULT", opt->result,
                                        "Result file (JSON) written by gyrocal (or give --history instead)");
  CLI::Option* history = sub->add_option(
      "--history", opt->history,
      "Draw the calibration history of --unit from this history database (SQLite) instead of a "
      "result: control charts and the repeatability table (docs/history.md)");
  CLI::Option* unit =
      sub->add_option("--unit", opt->unit, "The unit (its serial) whose history --history draws");
  sub->add_option("--html", opt->html, "Write the report to FILE ('-' = standard output)")->required();
  sub->add_flag("--force", opt->force, "Replace an existing file that is not an earlier gyrocal report");
  sub->callback([opt, result, history, unit] {
    // Exactly one of the two inputs.
    if (result->count() > 0 && history->count() > 0)
      throw Error(fmt::format(
          "report draws either a result file ({}) or a unit's history (--history {}), not both: give one.",
          opt->result, opt->history));
    if (result->count() == 0 && history->count() == 0)
      throw Error(
          "report needs what to draw: a result file (gyrocal report RESULT.json --html FILE) or a unit's "
          "calibration history (gyrocal report --history DATABASE --unit SERIAL --html FILE).");
    if (history->count() > 0) {
      if (unit->count() == 0)
        throw Error(
            fmt::format("--history {} needs --unit SERIAL: the unit whose history to draw.", opt->history));
      write_history_page(opt->history, opt->unit, opt->html, opt->force);
      return;
    }
    if (unit->count() > 0)
      throw Error(
          "--unit goes with --history DATABASE (a unit's calibration history), not with a result file.");
    refuse_to_overwrite_input(opt->html, opt->result);
    check_output(opt->html, OutputKind::kReport, opt->force, "--html");
    const nlohmann::json result_json = read_result_file(opt->result);
    const std::string kind = result_kind(result_json);
    if (kind == "inputs")
      throw Error(
          fmt::format("{} is the output of `gyrocal inputs` (one instant's inputs to the gyro), which has no "
                      "report page; "
                      "report draws the results of calibrate, plan, sensitivity, montecarlo, noise and demo.",
                      opt->result));
    if (kind == "history")
      throw Error(
          fmt::format("{} is the output of `gyrocal history show`; the page of a unit's history is drawn "
                      "from its database: "
                      "gyrocal report --history DATABASE --unit SERIAL --html FILE.",
                      opt->result));
    // An IMU's result (its estimates keyed by channel, docs/imu.md) is checked whole first: a missing or
    // malformed key is refused, named, before anything is drawn or written.
    if (is_imu_result(result_json)) check_imu_result(result_json, opt->result);
    const std::vector<std::string> sections = report_sections_present(result_json);
    if (sections.empty())
      throw Error(fmt::format(
          "{} contains none of the sections of a gyrocal result (coefficients, positions, sensitivity, "
          "montecarlo, plan, ...).",
          opt->result));
    std::vector<std::string> problems;
    HtmlReportOptions options;
    options.source = opt->result;
    options.problems = &problems;
    const std::string html = render_html_report(result_json, options);
    for (const auto& p : problems) fmt::print(stderr, "gyrocal: warning: {}: {}\n", opt->result, p);
    // A report is derived from its result and cheap to write again: an earlier report is replaced,
    // any other existing file only with --force (docs/report.md).
    write_output(opt->html, html, OutputKind::kReport, opt->force, "--html");
    say_written(opt->html, fmt::format("wrote {}: the {} report of {} ({} sections)\n",
                                       opt->html == "-" ? "standard output" : opt->html,
                                       is_imu_result(result_json) ? "IMU " + kind
                                       : kind == "montecarlo"     ? std::string("Monte Carlo")
                                                                  : kind,
                                       opt->result, sections.size()));
  });
}

}  // namespace gyrocal::cli
