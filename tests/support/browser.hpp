#pragma once
// Opening a report in a real browser from a test (headless Chromium, Debian's or $GYROCAL_CHROMIUM): the
// page's own checks (report_errors.js, report.js) leave their findings as attributes of <body>, which
// Chromium's
// --dump-dom shows. Header-only.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace gyrocal::test {

/// Debian's chromium, or the one named by $GYROCAL_CHROMIUM.
inline std::string chromium() {
  if (const char* env = std::getenv("GYROCAL_CHROMIUM"); env && *env) return env;
  return "/usr/bin/chromium";
}

/// Fails the running test when Chromium is missing, saying how to install it.
inline void expect_chromium() {
  ASSERT_EQ(access(chromium().c_str(), X_OK), 0)
      << "chromium is not installed (" << chromium()
      << "): this test opens the report in a real browser. scripts/test installs it; or run "
         "`apt-get install -y chromium` (or set GYROCAL_CHROMIUM to a Chromium binary).";
}

/// The browser's output of one run.
struct BrowserOutcome {
  int status = -1;
  std::string out, err;
};

/// Runs headless Chromium with `arguments` (as written on a command line; the paths hold no single quote),
/// its profile in `dir`, its outputs captured.
inline BrowserOutcome run_chromium(const std::string& arguments, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  const std::filesystem::path out = dir / "chromium.stdout", err = dir / "chromium.stderr";
  const std::string line = chromium() +
                           " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
                           "--disable-background-networking --disable-component-update --disable-sync "
                           "--disable-dev-shm-usage --hide-scrollbars --enable-logging=stderr "
                           "--virtual-time-budget=5000 --user-data-dir='" +
                           (dir / "profile").string() + "' " + arguments + " >'" + out.string() + "' 2>'" +
                           err.string() + "' </dev/null";
  const int raw = std::system(line.c_str());
  BrowserOutcome o;
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  const auto slurp = [](const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  o.out = slurp(out);
  o.err = slurp(err);
  return o;
}

/// The value of attribute `name` of the <body> tag in `dom` ("<absent>" when it has none).
inline std::string body_attribute(const std::string& dom, const std::string& name) {
  const std::regex body("<body[^>]*>");
  std::smatch m;
  if (!std::regex_search(dom, m, body)) return "<no body>";
  const std::string tag = m.str();
  const std::regex attr(name + "=\"([^\"]*)\"");
  if (!std::regex_search(tag, m, attr)) return "<absent>";
  return m[1].str();
}

}  // namespace gyrocal::test
