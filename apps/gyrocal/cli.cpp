#include "cli.hpp"

#include <cstdio>
#include <filesystem>
#include <iostream>

#include <fmt/format.h>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/core/atomic_file.hpp"
#include "gyrocal/core/error.hpp"

namespace gyrocal::cli {

Scenario load_configuration(const std::string& path) {
  return path.empty() ? default_scenario() : load_scenario(path);
}

std::unique_ptr<AtomicOutputFile> open_output(const std::string& path, bool overwrite) {
  if (path == "-") return std::make_unique<AtomicOutputFile>(AtomicOutputFile::StandardOutput{});
  return std::make_unique<AtomicOutputFile>(path, overwrite);
}

void write_output(const std::string& path, std::string_view content, bool overwrite) {
  const std::unique_ptr<AtomicOutputFile> file = open_output(path, overwrite);
  file->write(content);
  file->commit();
}

void refuse_to_overwrite_input(const std::string& output, const std::string& input) {
  if (output.empty() || output == "-" || input.empty()) return;
  std::error_code ec;
  if (std::filesystem::equivalent(output, input, ec))
    throw Error("refusing to write " + output + ": it is the input " + input + ".");
}

void ProgressBar::operator()(double fraction) {
  const int percent = static_cast<int>(fraction * 100.0);
  if (percent == percent_) return;
  percent_ = percent;
  constexpr int kWidth = 40;
  const int filled = percent * kWidth / 100;
  fmt::print(stderr, "\r{} [{:#<{}}{:<{}}] {:3}%", label_, "", filled, "", kWidth - filled, percent);
  if (percent == 100) fmt::print(stderr, "\n");
  std::fflush(stderr);
}

}  // namespace gyrocal::cli
