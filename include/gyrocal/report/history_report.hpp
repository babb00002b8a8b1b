#pragma once
// The self-contained HTML page of a unit's calibration history (`gyrocal report --history FILE --unit SERIAL
// --html OUT`, docs/history.md): who and when (the unit, its sensor, its runs and their dates, the gyrocal
// versions that calibrated), the repeatability table (per channel and coefficient: the weighted mean, the
// run-to-run standard deviation with its interval, the stated sigma, their ratio and F-test, the trend, the
// Shewhart limits and the runs outside them), a control chart per coefficient (each run's value with its
// sigma against its date, the mean, the limits, the EWMA with its limits, the flagged runs marked), the same
// for the rig's machine errors, and the runs. Same page as the other reports: nothing loaded from outside,
// Chart.js inlined.
#include <string>

#include "gyrocal/history/summary.hpp"
#include "gyrocal/report/html_report.hpp"

namespace gyrocal {

/// Renders the history page of `summary` (history::summarize's). options.source names the database (shown in
/// the header), options.title replaces the page's title ("gyrocal calibration history of UNIT"),
/// options.created its date; a section that cannot be drawn (a table or the charts beyond
/// limits::kReportTableCells cells or points: runs x quantities) shows a sentence saying why instead, also
/// put in options.problems. Every string from the summary (serials, notes, names, units) is escaped.
std::string history_report_html(const history::HistorySummary& summary,
                                const HtmlReportOptions& options = {});

}  // namespace gyrocal
