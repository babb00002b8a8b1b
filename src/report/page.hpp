#pragma once
// The report's page (docs/report.md), private to src/report: the sections drawn, their navigation, the plot
// descriptions, and the self-contained HTML document around them (styles and scripts from the files
// src/report/report.css, report_errors.js and report.js and the Chart.js bundle, all compiled in by
// src/report/embed_file.cmake). A report of any kind (a calibration result, a noise characterisation) is a
// table of Section entries drawn by render_sections().
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace gyrocal::report {

/// What the header of a page says.
struct PageHeader {
  std::string title;
  std::string source;                   ///< where the data came from (a file name); empty = not shown
  std::string source_label = "result";  ///< what `source` is, shown before it
  std::string created;                  ///< date and time; empty = now, UTC
  /// Shown in place of the sections when none was drawn.
  std::string nothing_to_show = "The result contains none of the sections this report shows.";
};

class Page {
 public:
  /// `problems`, when not null, receives one sentence per section that could not be read.
  explicit Page(std::vector<std::string>* problems = nullptr) : problems_(problems) {}

  /// A canvas for one plot; `spec` is a plot description (charts.hpp) that report.js hands to Chart.js.
  /// Returns the canvas's HTML, to be placed in a section.
  std::string plot(nlohmann::json spec, int height_px, std::string_view description,
                   std::string_view cls = "plot");

  /// Draws one section: a heading `title` with anchor `id`, filled by `fill`. When `fill` throws, the
  /// section shows the sentence "The section "<name>" of the result could not be read: ..." instead (and
  /// loses the plots it had added); the sentence also goes to `problems`. Every section drawn is listed in
  /// the navigation.
  void section(std::string_view name, std::string_view id, std::string_view title,
               const std::function<void(std::string&)>& fill);

  /// The sections drawn, in order: (anchor id, title). The navigation lists exactly these.
  const std::vector<std::pair<std::string, std::string>>& navigation() const { return toc_; }

  /// The whole HTML document.
  std::string html(const PageHeader& header) const;

 private:
  std::vector<std::string>* problems_;
  std::string body_;
  std::vector<std::pair<std::string, std::string>> toc_;
  nlohmann::json plots_ = nlohmann::json::array();
  int next_plot_ = 1;
};

/// One section of a report: drawn when `applies(data)`, by `render(data, page, out)` appending its HTML to
/// `out` (and its plots through page.plot). `name` is the section's name in messages and in
/// report_sections_present(), `id` its anchor, `title` its heading and its entry in the navigation.
struct Section {
  std::string_view name;
  std::string_view id;
  std::string_view title;
  void (*render)(const nlohmann::json& data, Page& page, std::string& out);
  bool (*applies)(const nlohmann::json& data);
};

/// Draws every section of `table` that applies to `data`, in the table's order.
void render_sections(std::span<const Section> table, const nlohmann::json& data, Page& page);

/// The names of the sections of `table` that apply to `data`, in the table's order.
std::vector<std::string> sections_applying(std::span<const Section> table, const nlohmann::json& data);

}  // namespace gyrocal::report
