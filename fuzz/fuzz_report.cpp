// libFuzzer target: the reader of `gyrocal report RESULT.json --html FILE` (apps/gyrocal/cmd_report.cpp):
// read_result_file, which reads the file bounded by limits::kResultBytes and stops at the first character
// when it cannot open a JSON object, and parse_result_json (valid JSON holding an object, at most
// limits::kResultDepth levels deep and limits::kResultNames distinct names); then the check that some section
// is present, and the HTML report itself (src/report/html_report.cpp), which reads every section and turns a
// section it cannot read into a problem sentence (an IMU's result is checked whole first and refused by the
// key's path). A clean refusal (gyrocal::Error) is fine; anything else
// escaping, a crash, a leak or undefined behaviour is a finding. So is a problem sentence that carries a
// library's internal message (nlohmann::json's "[json.exception...]") instead of one of ours, and a file
// read that answers otherwise than the same bytes parsed in memory. The same JSON is also read as `history
// add` reads it (history::run_from_result): a run with a channel and a coefficient, or a refusal of ours.
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gyrocal/core/error.hpp"
#include "gyrocal/history/run.hpp"
#include "gyrocal/report/html_report.hpp"

namespace {

/// The outcome of reading a result: the JSON, or the refusal's sentence.
struct Outcome {
  nlohmann::json result;
  std::optional<std::string> refusal;
};

template <class Read>
Outcome outcome_of(Read read) {
  Outcome o;
  try {
    o.result = read();
  } catch (const gyrocal::Error& e) {
    o.refusal = e.what();
  }
  return o;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);

  // The file: written whole into an anonymous in-memory file, read back through its /proc path.
  const int fd = ::memfd_create("fuzz.json", MFD_CLOEXEC);
  if (fd < 0) std::abort();
  for (std::size_t written = 0; written < size;) {
    const ssize_t n = ::write(fd, data + written, size - written);
    if (n <= 0) std::abort();
    written += static_cast<std::size_t>(n);
  }
  const std::string path = "/proc/self/fd/" + std::to_string(fd);
  const Outcome from_file = outcome_of([&] { return gyrocal::read_result_file(path); });
  ::close(fd);
  // The same bytes in memory, named by the same path: the same JSON or the same sentence.
  const Outcome in_memory = outcome_of([&] { return gyrocal::parse_result_json(text, path); });
  if (from_file.refusal != in_memory.refusal ||
      (!in_memory.refusal && from_file.result != in_memory.result)) {
    std::fprintf(stderr, "the file read says \"%s\", the text parsed in memory \"%s\"\n",
                 from_file.refusal.value_or("(accepted)").c_str(),
                 in_memory.refusal.value_or("(accepted)").c_str());
    std::abort();
  }
  if (in_memory.refusal) return 0;  // a clean refusal
  const nlohmann::json& result = in_memory.result;

  // `history add` reads the same file into a run (src/history/run.cpp): a run, or a refusal of ours.
  try {
    const gyrocal::history::Run run = gyrocal::history::run_from_result(result, "fuzz.json");
    if (run.channels.empty() || run.coefficients.empty()) std::abort();
  } catch (const gyrocal::Error& e) {
    if (std::string_view(e.what()).find("[json.exception.") != std::string_view::npos) {
      std::fprintf(stderr, "internal message in a history refusal: %s\n", e.what());
      std::abort();
    }
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
  } catch (const gyrocal::Error& e) {
    // An IMU's result is checked whole and refused by the key's path (src/report/imu_check.cpp): a sentence
    // of ours, never the library's.
    if (std::string_view(e.what()).find("[json.exception.") != std::string_view::npos) {
      std::fprintf(stderr, "internal message in a report refusal: %s\n", e.what());
      std::abort();
    }
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
