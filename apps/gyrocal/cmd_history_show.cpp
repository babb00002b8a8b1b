// gyrocal history show --unit SERIAL: a unit's calibration history read from the database, its repeatability
// printed as a table and written as JSON (docs/history.md, docs/interface.md "Calibration history (SQLite)").
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cli.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/history/read.hpp"
#include "gyrocal/result/history_json.hpp"
#include "history_show.hpp"
#include "tables.hpp"

namespace gyrocal::cli {

namespace {

/// p-values below this are marked with '*' (the F-test's, the trend's).
constexpr double kSignificant = 0.01;

std::string opt_g(const std::optional<double>& v, int significant) {
  return v ? fmt::format("{:.{}g}", *v, significant) : std::string("-");
}

std::string p_text(const std::optional<double>& p) {
  if (!p) return "-";
  return fmt::format("{:.2g}{}", *p, *p < kSignificant ? " *" : "");
}

std::string ids_text(const std::vector<std::int64_t>& ids) {
  std::string out;
  for (const std::int64_t id : ids) out += (out.empty() ? "" : ",") + std::to_string(id);
  return out;
}

/// Columns padded to their widest cell; the first `left` columns left-aligned, the others right-aligned, the
/// last left-aligned (the flagged runs).
std::string aligned(const std::vector<std::vector<std::string>>& rows, std::size_t left) {
  std::vector<std::size_t> width;
  const auto columns_of = [](const std::string& s) {
    // Display width: UTF-8 continuation bytes take no column.
    return static_cast<std::size_t>(std::count_if(
        s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
  };
  for (const auto& row : rows)
    for (std::size_t c = 0; c < row.size(); ++c) {
      if (width.size() <= c) width.push_back(0);
      width[c] = std::max(width[c], columns_of(row[c]));
    }
  std::string out;
  for (const auto& row : rows) {
    std::string line;
    for (std::size_t c = 0; c < row.size(); ++c) {
      const std::string pad(width[c] - columns_of(row[c]), ' ');
      const bool last = c + 1 == row.size();
      line += (c == 0 ? "" : "  ") + (c < left || last ? row[c] + (last ? "" : pad) : pad + row[c]);
    }
    line.erase(line.find_last_not_of(' ') + 1);
    out += line + "\n";
  }
  return out;
}

std::vector<std::string> quantity_row(const history::QuantityHistory& q) {
  std::vector<std::string> row = {q.name, q.unit,
                                  q.unidentified.empty()
                                      ? std::to_string(q.values.size())
                                      : fmt::format("{}+{}", q.values.size(), q.unidentified.size())};
  if (!q.stats) {
    row.push_back("not identified by any run");
    for (int k = 0; k < 7; ++k) row.push_back("");
    return row;
  }
  const Repeatability& r = *q.stats;
  row.push_back(format_value_std(r.mean, r.mean_std));
  row.push_back(r.run_to_run_std
                    ? fmt::format("{:.3g} [{:.3g}, {:.3g}]", *r.run_to_run_std,
                                  r.run_to_run_std_low.value_or(NAN), r.run_to_run_std_high.value_or(NAN))
                    : std::string("-"));
  row.push_back(opt_g(r.mean_stated_std, 3));
  row.push_back(opt_g(r.std_ratio, 3));
  row.push_back(p_text(r.f_test_p));
  row.push_back(r.trend_per_day ? format_value_std(*r.trend_per_day, r.trend_std.value_or(NAN)) : "-");
  row.push_back(p_text(r.trend_p));
  std::string flagged = ids_text(r.flagged);
  if (!r.ewma_flagged.empty()) flagged += (flagged.empty() ? "" : " ") + ("ewma " + ids_text(r.ewma_flagged));
  row.push_back(flagged.empty() ? "-" : flagged);
  return row;
}

const std::vector<std::string> kHeader = {
    "coefficient", "unit",  "runs", "mean ± σ (weighted)", "run-to-run std [68.3 %]",
    "stated σ",    "ratio", "F p",  "trend/day ± σ",       "trend p",
    "flagged runs"};

std::string quantities_table(const std::vector<const history::QuantityHistory*>& list,
                             const std::string& first) {
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> header = kHeader;
  header[0] = first;
  rows.push_back(header);
  for (const auto* q : list) rows.push_back(quantity_row(*q));
  return aligned(rows, 2);
}

}  // namespace

std::string history_table(const history::HistorySummary& s, const std::string& database) {
  std::string out =
      fmt::format("unit {} ({}): {} run{}", s.unit, s.sensor, s.runs.size(), s.runs.size() == 1 ? "" : "s");
  if (!s.runs.empty())
    out += s.runs.front().date == s.runs.back().date
               ? fmt::format(" on {}", s.runs.front().date)
               : fmt::format(" from {} to {}", s.runs.front().date, s.runs.back().date);
  out += fmt::format(", in {}\n", database);
  std::vector<std::string> channels;
  for (const auto& q : s.coefficients)
    if (std::find(channels.begin(), channels.end(), q.channel) == channels.end())
      channels.push_back(q.channel);
  for (const std::string& channel : channels) {
    std::vector<const history::QuantityHistory*> list;
    for (const auto& q : s.coefficients)
      if (q.channel == channel) list.push_back(&q);
    out += fmt::format("\nchannel {}\n", channel);
    out += quantities_table(list, "coefficient");
  }
  if (!s.machine_errors.empty()) {
    std::vector<const history::QuantityHistory*> list;
    for (const auto& q : s.machine_errors) list.push_back(&q);
    out += "\nthe rig's machine errors (the rig's history, not the unit's)\n";
    out += quantities_table(list, "error");
  }
  out +=
      "\nruns: stated (+ not identified); mean weighted by 1/σ² (σ scaled by the Birge ratio when above 1);\n"
      "run-to-run std with its 68.3 % interval; ratio = run-to-run std / stated σ; F p: the probability of\n"
      "this scatter if the stated σ explained it; * p < 0.01; flagged: runs outside the Shewhart limits\n"
      "(ewma: where the EWMA left its own).\n";
  // The runs, with what each left.
  out += "\nrun  date                 record        note\n";
  for (const auto& r : s.runs) {
    std::string note = r.note;
    if (note.size() > 60) note = note.substr(0, 57) + "...";
    std::replace(note.begin(), note.end(), '\n', ' ');
    out += fmt::format("{:<4} {:<20} {:<12}  {}\n", r.id, r.date, r.record_sha256.substr(0, 12), note);
  }
  return out;
}

void register_history_show(CLI::App& history) {
  struct Options {
    std::string unit, db, json, config;
    bool force = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = history.add_subcommand(
      "show",
      "A unit's repeatability over its runs: per coefficient the weighted mean, the run-to-run std, the "
      "F-test against the stated sigma, the trend, the control limits and the flagged runs");
  sub->add_option("--unit", opt->unit, "The unit's serial")->required();
  sub->add_option("--db", opt->db,
                  "The history database (SQLite); default: [history] database of --config, else "
                  "gyrocal-history.sqlite in the current folder. Never created by show");
  sub->add_option("--config", opt->config,
                  "Configuration file (TOML) whose [history] database names the database");
  sub->add_option("--json", opt->json, "Write the history as JSON to FILE ('-' = standard output)");
  add_force_flag(sub, opt->force);
  sub->callback([opt] {
    // The database as `history add` finds it; the configuration is read only for its [history] database.
    std::optional<Scenario> scenario;
    if (opt->db.empty() && !opt->config.empty()) scenario = load_configuration(opt->config);
    const std::string database =
        history_database_path(opt->db, scenario ? &*scenario : nullptr, opt->config).string();
    refuse_to_overwrite_input(opt->json, database);
    refuse_to_overwrite_input(opt->json, opt->config);
    check_output(opt->json, OutputKind::kResult, opt->force, "--json");
    const history::HistorySummary summary = history::read_unit_history(database, opt->unit);
    if (!opt->json.empty()) write_result(opt->json, history_to_json(summary), "history", opt->force);
    if (opt->json != "-") print_out("{}", history_table(summary, database));
  });
}

}  // namespace gyrocal::cli
