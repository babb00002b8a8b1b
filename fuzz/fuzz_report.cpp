// libFuzzer target: the JSON reader of `gyrocal report RESULT.json --html FILE`
// (apps/gyrocal/cmd_report.cpp): parse_result_json (valid JSON holding an object), the check that some
// section is present, and the HTML report itself (src/report/html_report.cpp), which reads every section and
// turns a section it cannot read into a problem sentence. A clean refusal (gyrocal::Error) is fine; anything
// else escaping, a crash, a leak or undefined behaviour is a finding. So is a problem sentence that carries a
// library's internal message (nlohmann::json's "[json.exception...]") instead of one of ours.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "gyrocal/core/error.hpp"
#include "gyrocal/report/html_report.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  nlohmann::json result;
  try {
    result = gyrocal::parse_result_json(text, "fuzz.json");
  } catch (const gyrocal::Error&) {
    return 0;  // a clean refusal
  }
  if (gyrocal::report_sections_present(result).empty()) return 0;  // `report` refuses it by name
  std::vector<std::string> problems;
  gyrocal::HtmlReportOptions options;
  options.source = "fuzz.json";
  options.created = "2026-01-01 00:00:00 UTC";  // not the clock: the same input gives the same page
  options.problems = &problems;
  std::string html;
  try {
    html = gyrocal::render_html_report(result, options);
  } catch (const gyrocal::Error&) {
    return 0;
  }
  if (html.rfind("<!DOCTYPE html>", 0) != 0) std::abort();
  for (const std::string& p : problems) {
    if (p.find("[json.exception.") != std::string::npos) {
      std::fprintf(stderr, "internal message in a problem sentence: %s\n", p.c_str());
      std::abort();
    }
  }
  return 0;
}
