// `gyrocal report`'s input is bounded (issue 29, D2 and D18; docs/report.md): at most
// limits::kResultBytes + 1 bytes are read from any file (a regular file, a pipe, /dev/zero), reading stops at
// the first character when it cannot open a JSON object (a record, binary bytes), and a result holds at most
// limits::kResultNames distinct names; reading is linear in the file's size (it was quadratic in the members
// of an object).
// Every refusal names the file and the limit, exits 1 and leaves no report behind.
// The tables the report draws are bounded too (limits::kReportTableCells): a table whose rows x columns (an
// array's length x the union of its entries' keys) exceed the limit is refused as a problem of its section,
// before any of its cells is built; the rest of the page is drawn.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "gyrocal/core/bounded_read.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/report/html_report.hpp"
#include "support/cli_run.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::CliOutcome;
using test::fresh_test_folder;
using test::run_cli;

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

void write_file(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

/// `text` followed by zero bytes up to `size` bytes in all: a sparse file, which takes no room on the disk.
void write_sparse(const fs::path& path, const std::string& text, std::uintmax_t size) {
  write_file(path, text);
  fs::resize_file(path, size);
}

/// The number of distinct keys of the objects in `j`, at any depth: what limits::kResultNames counts.
std::size_t distinct_names(const json& j) {
  std::set<std::string> names;
  const std::function<void(const json&)> walk = [&](const json& v) {
    if (v.is_object())
      for (const auto& [key, value] : v.items()) {
        names.insert(key);
        walk(value);
      }
    else if (v.is_array())
      for (const auto& value : v) walk(value);
  };
  walk(j);
  return names.size();
}

/// A calibration result with `n` coefficients k0 .. k(n-1), each with a truth: the report's coefficient table
/// and error plot draw all of them.
json result_with_coefficients(std::size_t n) {
  json result = {{"coefficients", json::object()}, {"truth", json::object()}};
  for (std::size_t i = 0; i < n; ++i) {
    const std::string name = "k" + std::to_string(i);
    result["coefficients"][name] = {{"value", 1.0 + 1e-3 * static_cast<double>(i % 7)},
                                    {"std", 0.01},
                                    {"unit", "deg/h"},
                                    {"identifiable", true}};
    result["truth"][name] = 1.0;
  }
  return result;
}

/// Refused with exit 1 and a sentence holding each of `words`, no report file left in `dir`.
void expect_refused(const CliOutcome& o, const fs::path& dir, std::initializer_list<std::string_view> words) {
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_EQ(o.err.find("internal error"), std::string::npos) << o.err;
  for (const std::string_view w : words) EXPECT_NE(o.err.find(w), std::string::npos) << w << " in: " << o.err;
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find(".html"), std::string::npos)
        << "a report was left: " << entry.path();
}

// ---- D2: the size of the input -------------------------------------------------------------------

// An endless device: a zero byte cannot open a JSON object, so reading stops at the first read (before the
// fix, memory grew by 0.4 GB a second until the process was killed or ended in "internal error:
// std::bad_alloc").
TEST(ReportBounds, DevZeroIsRefusedAtItsFirstByte) {
  const fs::path dir = fresh_test_folder("report-bounds");
  const CliOutcome o = run_cli("report /dev/zero --html " + (dir / "z.html").string(), dir);
  expect_refused(o, dir, {"/dev/zero", "is not a gyrocal result", "line 1, column 1", "the byte 0x00"});
  fs::remove_all(dir);
}

TEST(ReportBounds, DevUrandomIsRefused) {
  const fs::path dir = fresh_test_folder("report-bounds");
  const CliOutcome o = run_cli("report /dev/urandom --html " + (dir / "u.html").string(), dir);
  // Its first byte is almost always refused at once; a '{' (or white space, then '{') is refused when the
  // limit is reached, or as invalid JSON: either way by name, with exit 1.
  expect_refused(o, dir, {"/dev/urandom"});
  fs::remove_all(dir);
}

// A record (1 GiB, sparse) given as the result: refused by its first character, not read whole (before the
// fix: 2 GB of memory, then "not valid JSON: line 1, column 1").
TEST(ReportBounds, ARecordGivenAsTheResultIsRefusedByItsFirstCharacter) {
  const fs::path dir = fresh_test_folder("report-bounds");
  const fs::path record = dir / "r30k.csv";
  write_sparse(record, "# gyrocal-record 1\ntime_s,main_angle_deg\n", std::uintmax_t{1} << 30);
  const CliOutcome o = run_cli("report " + record.string() + " --html " + (dir / "x.html").string(), dir);
  expect_refused(o, dir, {record.string(), "is not a gyrocal result", "line 1, column 1", "'#'"});
  fs::remove_all(dir);
}

// Leading white space is skipped: the character is named at its own line and column.
TEST(ReportBounds, TheFirstCharacterIsNamedAtItsLineAndColumn) {
  try {
    (void)parse_result_json("\n\n   time_s,gyro_deg_h\n", "t.csv");
    ADD_FAILURE() << "a CSV header was parsed as a result";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("t.csv"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("(line 3, column 4) is 't'"), std::string::npos) << e.what();
  }
  // A byte order mark before the '{' is accepted, as the JSON library skips it.
  EXPECT_NO_THROW((void)parse_result_json("\xEF\xBB\xBF {\"coefficients\": {}}", "bom.json"));
}

// A file larger than the limit, whose first character opens an object, is refused naming the limit after
// reading limits::kResultBytes + 1 bytes (before the fix it was read whole).
TEST(ReportBounds, AFileLargerThanTheLimitIsRefusedNamingTheLimit) {
  const fs::path dir = fresh_test_folder("report-bounds");
  const fs::path big = dir / "big.json";
  write_sparse(big, "{\"coefficients\": {}, \"pad\": \"", limits::kResultBytes + 1);
  const CliOutcome o = run_cli("report " + big.string() + " --html " + (dir / "big.html").string(), dir);
  expect_refused(o, dir, {big.string(), "larger than 16 MiB", "the limit for a result file"});
  fs::remove_all(dir);
}

// A pipe that never ends but opens with '{': reading stops after the limit (before the fix it was read until
// memory ran out).
TEST(ReportBounds, AnEndlessPipeIsReadOnlyUpToTheLimit) {
  const fs::path dir = fresh_test_folder("report-bounds");
  const std::string command = "{ printf '{'; tr '\\0' ' ' </dev/zero; } 2>/dev/null | " +
                              std::string(GYROCAL_CLI) + " report /dev/stdin --html " +
                              (dir / "p.html").string() + " 2>" + (dir / "err.txt").string();
  const int raw = std::system(command.c_str());
  CliOutcome o;
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  o.err = test::slurp(dir / "err.txt");
  fs::remove(dir / "err.txt");
  expect_refused(o, dir, {"/dev/stdin", "larger than 16 MiB"});
  fs::remove_all(dir);
}

// A file at the limit exactly is read and parsed.
TEST(ReportBounds, AResultOfTheLimitsSizeIsRead) {
  const fs::path dir = fresh_test_folder("report-bounds");
  const fs::path at_limit = dir / "limit.json";
  const std::string head = "{\"coefficients\": {}, \"pad\": \"";
  const std::string tail = "\"}";
  write_file(at_limit, head + std::string(limits::kResultBytes - head.size() - tail.size(), ' ') + tail);
  ASSERT_EQ(fs::file_size(at_limit), limits::kResultBytes);
  json result;
  ASSERT_NO_THROW(result = read_result_file(at_limit));
  EXPECT_EQ(result["pad"].get_ref<const std::string&>().size(),
            limits::kResultBytes - head.size() - tail.size());
  fs::remove_all(dir);
}

// The shared reader (configuration and result files): at most max_bytes + one read, whatever the file.
TEST(ReportBounds, TheBoundedReaderStopsAtTheLimitOrWhenTold) {
  const BoundedRead zero = read_bounded("/dev/zero", 100000, "test file");
  EXPECT_TRUE(zero.too_large);
  EXPECT_FALSE(zero.stopped);
  EXPECT_GT(zero.text.size(), 100000u);
  EXPECT_LE(zero.text.size(), 100000u + (64u << 10));

  std::size_t calls = 0;
  const BoundedRead stopped =
      read_bounded("/dev/zero", std::size_t{1} << 30, "test file", [&](std::string_view) {
        ++calls;
        return true;
      });
  EXPECT_TRUE(stopped.stopped);
  EXPECT_EQ(calls, 1u);
  EXPECT_LE(stopped.text.size(), 64u << 10);

  const fs::path dir = fresh_test_folder("report-bounds");
  write_file(dir / "small.txt", "abc");
  const BoundedRead small = read_bounded(dir / "small.txt", 3, "test file");
  EXPECT_EQ(small.text, "abc");
  EXPECT_FALSE(small.too_large);
  const BoundedRead over = read_bounded(dir / "small.txt", 2, "test file");
  EXPECT_TRUE(over.too_large);

  for (const auto& [path, why] : {std::pair<fs::path, std::string>{dir / "absent.txt", "it does not exist"},
                                  std::pair<fs::path, std::string>{dir, "it is a directory"}}) {
    try {
      (void)read_bounded(path, 10, "test file");
      ADD_FAILURE() << path;
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()), "Cannot read test file " + path.string() + ": " + why + ".");
    }
  }
  fs::remove_all(dir);
}

// Nesting: a million '[' is refused at its first character; inside an object, while it is parsed, at
// limits::kResultDepth levels (nothing deeper is built, so nothing recurses a million times).
TEST(ReportBounds, AMillionLevelsOfNestingAreRefused) {
  const std::size_t levels = 1'000'000;
  const std::string bare = std::string(levels, '[') + std::string(levels, ']');
  const std::string nested = "{\"method\": " + bare + "}";
  ASSERT_LT(nested.size(), limits::kResultBytes);
  try {
    (void)parse_result_json(bare, "bare.json");
    ADD_FAILURE() << "a million '[' were accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bare.json holds a JSON array, not an object"), std::string::npos)
        << e.what();
  }
  try {
    (void)parse_result_json(nested, "deep.json");
    ADD_FAILURE() << "a million levels were accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("deep.json nests arrays and objects more than 64 levels deep"),
              std::string::npos)
        << e.what();
  }
}

// ---- D18: the names --------------------------------------------------------------------------------------

// One name beyond limits::kResultNames is refused by name and limit, before the report is drawn (before the
// fix, 200,000 names took more than a minute).
TEST(ReportBounds, MoreDistinctNamesThanTheLimitAreRefused) {
  const fs::path dir = fresh_test_folder("report-bounds");
  json result = result_with_coefficients(limits::kResultNames);
  ASSERT_GT(distinct_names(result), limits::kResultNames);
  const fs::path input = dir / "names.json";
  write_file(input, result.dump());
  const CliOutcome o = run_cli("report " + input.string() + " --html " + (dir / "n.html").string(), dir);
  expect_refused(o, dir, {input.string(), "more than 4096 distinct names", "the limit for a result"});

  // A name repeated in many objects counts once: 8,000 positions of four fields are fine.
  json many = {{"positions", json::array()}};
  for (int i = 0; i < 8000; ++i)
    many["positions"].push_back({{"beta_deg", 0}, {"gamma_deg", i}, {"rate_rad_s", 1}});
  EXPECT_NO_THROW((void)parse_result_json(many.dump(), "many.json"));
  fs::remove_all(dir);
}

// A result with exactly limits::kResultNames distinct names is drawn whole: every coefficient has its row
// and its point on the error plot.
TEST(ReportBounds, AResultAtTheNamesLimitIsDrawnWhole) {
  const fs::path dir = fresh_test_folder("report-bounds");
  // The coefficients' fields and the top-level keys are names too.
  const std::size_t others = distinct_names(result_with_coefficients(1)) - 1;
  const std::size_t n = limits::kResultNames - others;
  const json result = result_with_coefficients(n);
  ASSERT_EQ(distinct_names(result), limits::kResultNames);
  const fs::path input = dir / "names.json", html = dir / "names.html";
  write_file(input, result.dump());
  const CliOutcome o = run_cli("report " + input.string() + " --html " + html.string(), dir);
  ASSERT_EQ(o.status, 0) << o.err;
  const std::string page = test::slurp(html);
  for (const std::size_t i : {std::size_t{0}, n / 2, n - 1})
    EXPECT_NE(page.find("<td>k" + std::to_string(i) + "</td>"), std::string::npos) << i;
  // One table row per coefficient (and the header's).
  EXPECT_EQ(count(page, "<td>deg/h</td>"), n);
  fs::remove_all(dir);
}

// The parsed result is held whole: its values are bounded (limits::kResultValues), so that 64 MiB of tiny
// values
// (`{},` 22 million times: 2.3 GB before the fix) are refused while they are read. At the limit exactly, the
// result is read.
TEST(ReportBounds, MoreValuesThanTheLimitAreRefused) {
  // The root object, the array and its numbers.
  const auto with_numbers = [](std::size_t n) {
    std::string text = "{\"x\": [";
    text.reserve(2 * n + 16);
    for (std::size_t i = 0; i < n; ++i) text += i == 0 ? "0" : ",0";
    return text + "]}";
  };
  EXPECT_NO_THROW((void)parse_result_json(with_numbers(limits::kResultValues - 2), "at.json"));
  try {
    (void)parse_result_json(with_numbers(limits::kResultValues - 1), "over.json");
    ADD_FAILURE() << "more values than the limit were accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("over.json holds more than 4194304 JSON values"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("the limit for a result"), std::string::npos) << e.what();
  }
}

// ---- The cells of a table ---------------------------------------------------------------------------------

/// The number of table cells on a page.
std::size_t cells_on(const std::string& page) {
  return count(page, "<td");
}

/// `n` entries of an array, entry i holding {"<prefix><i % keys>": i} and `common` (so a table of them has
/// `keys` columns of their own).
json cycling_entries(std::size_t n, std::size_t keys, const std::string& prefix, const json& common = {}) {
  json entries = json::array();
  for (std::size_t i = 0; i < n; ++i) {
    json e = common.is_object() ? common : json::object();
    e[prefix + std::to_string(i % keys)] = i;
    entries.push_back(std::move(e));
  }
  return entries;
}

// Issue 29: `data_quality.rejected` of 2,000 entries cycling through 1,000 keys is a table of 2,000 x 1,003
// cells (start_s, end_s, reason and the keys): beyond the limit, it is refused naming the file, the section,
// its rows x columns and the limit, and the page is written with the other sections (before the fix the
// table was drawn whole: 2 million cells; 50,000 entries of 4,000 keys ran out of 2 GB).
TEST(ReportBounds, AnExplodingTableIsRefusedAsAProblemOfItsSection) {
  const fs::path dir = fresh_test_folder("report-bounds");
  json result = result_with_coefficients(3);
  result["data_quality"] = {{"rows_read", 10}, {"rows_used", 5}, {"outliers", 0}, {"gaps", 0}};
  result["data_quality"]["rejected"] =
      cycling_entries(2000, 1000, "k", {{"start_s", 1.0}, {"end_s", 2.0}, {"reason", "not planned"}});
  ASSERT_GT(2000u * 1003u, limits::kReportTableCells);
  ASSERT_LE(distinct_names(result), limits::kResultNames);
  const fs::path input = dir / "rejected.json", html = dir / "rejected.html";
  const std::string input_name = input.string();
  const std::string limit_words = std::to_string(limits::kReportTableCells) + ", the limit of a table";
  write_file(input, result.dump());
  const CliOutcome o = run_cli("report " + input_name + " --html " + html.string(), dir);
  ASSERT_EQ(o.status, 0) << o.err;
  for (const std::string_view w :
       {std::string_view("warning"), std::string_view(input_name), std::string_view("data_quality"),
        std::string_view("data_quality.rejected"), std::string_view("2000 rows"),
        std::string_view("1003 columns"), std::string_view(limit_words)})
    EXPECT_NE(o.err.find(w), std::string::npos) << w << " in: " << o.err;
  const std::string page = test::slurp(html);
  EXPECT_NE(page.find("1003 columns"), std::string::npos);
  // The other sections are drawn: the coefficients' table.
  EXPECT_NE(page.find("<td>k2</td>"), std::string::npos);
  EXPECT_LT(cells_on(page), 1000u);
  fs::remove_all(dir);
}

/// Renders `result` and expects one problem naming `where` and the limit, and a page without the table.
void expect_table_refused(const json& result, const std::string& where) {
  std::vector<std::string> problems;
  HtmlReportOptions options;
  options.problems = &problems;
  const std::string page = render_html_report(result, options);
  ASSERT_EQ(problems.size(), 1u) << where;
  EXPECT_NE(problems[0].find(where), std::string::npos) << problems[0];
  EXPECT_NE(problems[0].find(std::to_string(limits::kReportTableCells) + ", the limit of a table"),
            std::string::npos)
      << problems[0];
  EXPECT_LE(cells_on(page), limits::kReportTableCells / 100) << where;
}

// Every table drawn from an array or object of the result is bounded before its cells are built: the union
// of keys (coefficients' and machine errors' fields, dwells' fields, comparison's labels, the budget's
// sources, the sensitivity heat maps' estimates) or the rows alone (positions) or the bins (histograms).
TEST(ReportBounds, EveryTableOfTheReportIsBounded) {
  {
    json r = {{"data_quality", {{"dwells", cycling_entries(1000, 1000, "d")}}}};
    expect_table_refused(r, "data_quality.dwells would be a table of 1000 rows \xC3\x97 1001 columns");
  }
  {
    json r = result_with_coefficients(1000);
    std::size_t i = 0;
    for (auto& [name, e] : r["coefficients"].items()) e["f" + std::to_string(i++)] = 1;
    // 1000 extra keys beside the table's nine columns (the expanded uncertainty U, k = 2, among them).
    expect_table_refused(r, "coefficients would be a table of 1000 rows \xC3\x97 1009 columns");
  }
  {
    json r = {{"machine_errors", cycling_entries(1000, 1000, "f", {{"error", "x"}, {"value", 1}})}};
    expect_table_refused(r, "machine_errors would be a table of 1000 rows \xC3\x97 1008 columns");
  }
  {
    json r = {{"comparison", json::array()}};
    for (int k = 0; k < 1000; ++k)
      r["comparison"].push_back(
          {{"label", std::to_string(k)}, {"coefficients", {{"c" + std::to_string(k), 1}}}});
    expect_table_refused(r, "comparison would be a table of 1000 rows \xC3\x97 1002 columns");
  }
  {
    json r = {{"positions", json::array()}};
    for (std::size_t k = 0; k <= limits::kReportTableCells / 8; ++k) r["positions"].push_back(json::object());
    expect_table_refused(r, "positions would be a table of " +
                                std::to_string(limits::kReportTableCells / 8 + 1) +
                                " rows \xC3\x97 8 columns");
  }
  {
    json budget = json::object();
    for (int k = 0; k < 1000; ++k) budget["c" + std::to_string(k)] = {{"s" + std::to_string(k), 0.5}};
    json r = {{"montecarlo", {{"budget", budget}}}};
    expect_table_refused(r, "montecarlo.budget would be a table of 1000 rows \xC3\x97 1002 columns");
  }
  {
    json counts = json::array(), edges = json::array({0});
    for (std::size_t k = 0; k <= limits::kReportTableCells; ++k) {
      counts.push_back(0);
      edges.push_back(k + 1);
    }
    json r = {
        {"montecarlo",
         {{"coefficients",
           {{"dF", {{"mean", 0}, {"std", 1}, {"histogram", {{"edges", edges}, {"counts", counts}}}}}}}}}};
    expect_table_refused(r, "montecarlo.coefficients' histograms would be a table of 1 rows \xC3\x97 " +
                                std::to_string(limits::kReportTableCells + 1));
  }
  {
    json rows = json::array();
    for (int k = 0; k < 2001; ++k)
      rows.push_back(
          {{"error", "e"}, {"value", 1}, {"shift", {{"none", {{"n" + std::to_string(k % 500), 1.0}}}}}});
    json r = {{"sensitivity", {{"rows", rows}}}};
    expect_table_refused(
        r, "sensitivity.rows (the heat maps) would be a table of 2001 rows \xC3\x97 500 columns");
  }
}

// The limit leaves a real result's tables whole: the sample (every section) draws with no problem, and a
// table of exactly the limit's cells is drawn.
TEST(ReportBounds, ATableAtTheLimitIsDrawn) {
  json r = {
      {"data_quality",
       {{"rejected", cycling_entries(500, 497, "k", {{"start_s", 1.0}, {"end_s", 2.0}, {"reason", "x"}})}}}};
  ASSERT_EQ(500u * 500u, limits::kReportTableCells);
  std::vector<std::string> problems;
  HtmlReportOptions options;
  options.problems = &problems;
  const std::string page = render_html_report(r, options);
  EXPECT_TRUE(problems.empty()) << problems.front();
  // The rejected table's cells, and the eight of the counts' table (four rows of label and count).
  EXPECT_EQ(cells_on(page), limits::kReportTableCells + 8);
}

}  // namespace
}  // namespace gyrocal
