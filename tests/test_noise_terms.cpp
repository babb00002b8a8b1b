// Noise characterisation (physics.md section 13): chi-squared quantiles against closed forms and tables, the
// equivalent degrees of freedom against the scatter of simulated Allan variances, confidence bounds against
// their coverage, and the IEEE 952 terms recovered from simulated records.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <numeric>
#include <vector>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/cli_run.hpp"

#include "gyrocal/analysis/record_noise.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/noise_terms.hpp"
#include "gyrocal/core/random.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/report/html_report.hpp"
#include "gyrocal/simulate/noise.hpp"

namespace gyrocal {
namespace {

bool sanitized() {
  return std::getenv("GYROCAL_SANITIZED") != nullptr;
}

std::vector<double> generate(const GyroNoise& noise, double sample_rate_hz, std::uint64_t seed,
                             std::size_t count, double offset_deg_h = 0.0) {
  GyroNoiseGenerator generator(noise, sample_rate_hz, seed);
  std::vector<double> out(count);
  for (double& y : out) y = generator.next(offset_deg_h);
  return out;
}

TEST(ChiSquaredQuantile, MatchesClosedFormsAndTables) {
  // Two degrees of freedom: P(X <= x) = 1 - exp(-x/2).
  for (double p : {1e-6, 0.1586552539, 0.5, 0.8413447461, 0.999}) {
    EXPECT_NEAR(chi_squared_quantile(p, 2.0) / (-2.0 * std::log1p(-p)), 1.0, 1e-12) << p;
  }
  // One degree of freedom: X = Z^2, so P(X <= k^2) = P(|Z| <= k).
  EXPECT_NEAR(chi_squared_quantile(std::erf(1.0 / std::sqrt(2.0)), 1.0), 1.0, 1e-12);
  EXPECT_NEAR(chi_squared_quantile(std::erf(2.0 / std::sqrt(2.0)), 1.0), 4.0, 1e-11);
  // Published tables (Abramowitz & Stegun 26.4): 10 degrees of freedom at 5 % and 95 %; 100 at 50 %.
  EXPECT_NEAR(chi_squared_quantile(0.05, 10.0), 3.940299, 1e-6);
  EXPECT_NEAR(chi_squared_quantile(0.95, 10.0), 18.307038, 1e-6);
  EXPECT_NEAR(chi_squared_quantile(0.5, 100.0), 99.334129, 1e-6);
  EXPECT_THROW(chi_squared_quantile(0.0, 3.0), Error);
  EXPECT_THROW(chi_squared_quantile(0.5, -1.0), Error);
}

TEST(ConfidenceBounds, AreTheChiSquaredQuantilesOfTheVariance) {
  // With 2 degrees of freedom the bounds are closed forms of the 15.87 % and 84.13 % quantiles.
  const DeviationBounds b = deviation_confidence_bounds(1.0, 2.0);
  const double tail = (1.0 - std::erf(1.0 / std::sqrt(2.0))) / 2.0;
  EXPECT_NEAR(b.low, std::sqrt(2.0 / (-2.0 * std::log(tail))), 1e-10);
  EXPECT_NEAR(b.high, std::sqrt(2.0 / (-2.0 * std::log1p(-tail))), 1e-10);
  // Many degrees of freedom: the relative half-width tends to 1/sqrt(2 dof).
  const DeviationBounds wide = deviation_confidence_bounds(1.0, 20000.0);
  EXPECT_NEAR((wide.high - wide.low) / 2.0, 1.0 / std::sqrt(40000.0), 1e-4);
}

// The equivalent degrees of freedom say var(sigma^2 estimate) = 2 sigma^4 / dof: check that against the
// scatter of independent simulated runs, for white rate noise and for rate random walk.
void expect_dof_matches_scatter(const GyroNoise& noise, NoiseTerm term, std::size_t samples, int runs,
                                const std::vector<std::size_t>& sizes) {
  std::vector<double> sum(sizes.size(), 0.0), sum_squares(sizes.size(), 0.0);
  for (int run = 0; run < runs; ++run) {
    const std::vector<double> y =
        generate(noise, 10.0, derive_stream_seed(77, static_cast<std::uint64_t>(run)), samples);
    const AllanDeviation adev = overlapping_allan_deviation(y, 10.0, sizes);
    for (std::size_t j = 0; j < sizes.size(); ++j) {
      const double v = adev.deviation[j] * adev.deviation[j];
      sum[j] += v;
      sum_squares[j] += v * v;
    }
  }
  const auto r = static_cast<double>(runs);
  for (std::size_t j = 0; j < sizes.size(); ++j) {
    const double mean = sum[j] / r;
    const double variance = (sum_squares[j] - r * mean * mean) / (r - 1.0);
    const double dof_observed = 2.0 * mean * mean / variance;
    const double dof = allan_equivalent_dof(samples, sizes[j], term);
    // The sample variance of `runs` values has a relative standard error of about sqrt(2 / runs) (more for
    // skewed laws): 30 % at 400 runs is about 4 of them, and a dof off by a factor 2 fails.
    EXPECT_NEAR(dof_observed / dof, 1.0, 0.3) << "m = " << sizes[j] << ", dof " << dof;
  }
}

TEST(AllanDof, MatchesTheScatterOfWhiteNoise) {
  GyroNoise noise;
  noise.angle_random_walk_deg_rt_h = 0.01;
  expect_dof_matches_scatter(noise, NoiseTerm::AngleRandomWalk, 2048, sanitized() ? 150 : 400,
                             {1, 8, 64, 256});
}

TEST(AllanDof, MatchesTheScatterOfRateRandomWalk) {
  GyroNoise noise;
  noise.rate_random_walk_deg_h_rt_h = 1.0;
  expect_dof_matches_scatter(noise, NoiseTerm::RateRandomWalk, 2048, sanitized() ? 150 : 400, {8, 64, 256});
}

TEST(NoiseCharacterisation, BoundsCoverTheTruthAtTheirStatedRate) {
  GyroNoise noise;
  noise.angle_random_walk_deg_rt_h = 0.01;
  const double fs = 10.0;
  const int runs = sanitized() ? 100 : 300;
  std::vector<int> covered;
  std::vector<double> taus;
  for (int run = 0; run < runs; ++run) {
    const NoiseCharacterisation c = characterise_noise(
        generate(noise, fs, derive_stream_seed(5, static_cast<std::uint64_t>(run)), 4096), fs);
    if (covered.empty()) {
      covered.assign(c.allan.tau_s.size(), 0);
      taus = c.allan.tau_s;
    }
    for (std::size_t j = 0; j < taus.size(); ++j) {
      const double truth = 60.0 * noise.angle_random_walk_deg_rt_h / std::sqrt(taus[j]);
      covered[j] += (c.adev_low[j] <= truth && truth <= c.adev_high[j]) ? 1 : 0;
    }
  }
  // 68.3 % within 4 binomial standard errors. At the last point (m = N/4) the simple degrees of freedom of
  // NIST SP 1065 are too few (about 4 where the scatter says more), so its bounds are wider than stated:
  // measured 0.79 to 0.81. That is conservative, and is all the test asks there (docs/noise.md).
  const double tolerance = 4.0 * std::sqrt(0.683 * 0.317 / runs);
  for (std::size_t j = 0; j < taus.size(); ++j) {
    const double coverage = covered[j] / static_cast<double>(runs);
    if (j + 1 < taus.size()) {
      EXPECT_NEAR(coverage, 0.683, tolerance) << "tau = " << taus[j] << " s";
    } else {
      EXPECT_GT(coverage, 0.683 - tolerance) << "tau = " << taus[j] << " s";
    }
  }
}

TEST(NoiseCharacterisation, RecoversWhiteNoiseAndRateRandomWalk) {
  GyroNoise noise;
  noise.angle_random_walk_deg_rt_h = 0.01;  // sigma = 0.6 deg/h at 1 s
  noise.rate_random_walk_deg_h_rt_h = 1.0;  // crosses the white noise at tau = 3 * 3600 * N / K = 108 s
  const double fs = 20.0;
  // 40 runs under the sanitizers too (0.2 s for 10 there): the rms of 10 z-scores spreads by 1/sqrt(20) =
  // 0.22, too much for the band below (0.44 with the noise fit's quantization rule of issue 28).
  const int runs = 40;
  std::vector<double> z_n, z_k;
  for (int run = 0; run < runs; ++run) {
    const NoiseCharacterisation c = characterise_noise(
        generate(noise, fs, derive_stream_seed(9, static_cast<std::uint64_t>(run)), 80000), fs);
    const FittedNoiseTerm& n = c.term(NoiseTerm::AngleRandomWalk);
    const FittedNoiseTerm& k = c.term(NoiseTerm::RateRandomWalk);
    ASSERT_TRUE(n.present && k.present);
    z_n.push_back((n.value - noise.angle_random_walk_deg_rt_h) / n.std);
    z_k.push_back((k.value - noise.rate_random_walk_deg_h_rt_h) / k.std);
    EXPECT_NEAR(n.value / noise.angle_random_walk_deg_rt_h, 1.0, 0.05);
    EXPECT_NEAR(k.value / noise.rate_random_walk_deg_h_rt_h, 1.0, 0.6);
  }
  auto rms = [](const std::vector<double>& z) {
    return std::sqrt(std::inner_product(z.begin(), z.end(), z.begin(), 0.0) / static_cast<double>(z.size()));
  };
  // Honest, not tiny and not swollen: the rms z-score within [0.5, 1.3] (1.4 and 2.0 without the correlation
  // factor).
  EXPECT_GT(rms(z_n), 0.5);
  EXPECT_LT(rms(z_n), 1.3);
  EXPECT_GT(rms(z_k), 0.5);
  EXPECT_LT(rms(z_k), 1.3);
}

TEST(NoiseCharacterisation, RecoversBiasInstability) {
  GyroNoise noise;
  noise.angle_random_walk_deg_rt_h = 0.005;
  noise.bias_instability_deg_h = 0.05;
  const double fs = 5.0;
  const NoiseCharacterisation c =
      characterise_noise(generate(noise, fs, 31, sanitized() ? 50000 : 200000), fs);
  const FittedNoiseTerm& b = c.term(NoiseTerm::BiasInstability);
  ASSERT_TRUE(b.present);
  EXPECT_NEAR(b.value / noise.bias_instability_deg_h, 1.0, 0.25);
  EXPECT_NEAR(c.term(NoiseTerm::AngleRandomWalk).value / noise.angle_random_walk_deg_rt_h, 1.0, 0.1);
}

TEST(NoiseCharacterisation, ALargeConstantOffsetChangesNothing) {
  GyroNoise noise;
  noise.angle_random_walk_deg_rt_h = 0.01;
  noise.rate_random_walk_deg_h_rt_h = 1.0;
  const std::vector<double> y = generate(noise, 20.0, 3, 40000);
  std::vector<double> shifted = y;
  for (double& v : shifted) v += 1e7;
  const NoiseCharacterisation a = characterise_noise(y, 20.0);
  const NoiseCharacterisation b = characterise_noise(shifted, 20.0);
  for (std::size_t j = 0; j < a.allan.deviation.size(); ++j) {
    // 1e7 deg/h carries rounding of 1e7 * 2^-53 ~ 1e-9 deg/h per sample, far below the noise of 0.6 deg/h.
    EXPECT_NEAR(b.allan.deviation[j] / a.allan.deviation[j], 1.0, 1e-6) << j;
  }
  EXPECT_NEAR(b.term(NoiseTerm::AngleRandomWalk).value / a.term(NoiseTerm::AngleRandomWalk).value, 1.0, 1e-6);
}

TEST(NoiseCharacterisation, RefusesTooShortARecord) {
  EXPECT_THROW(characterise_noise(std::vector<double>(10, 1.0), 1.0), Error);
}

// A static record in gyrocal's format: white noise plus rate random walk on a constant Earth rate, at 20 Hz,
// with an optional hole (rows left out) to make the sampling uneven.
void write_static_record(const std::filesystem::path& path, std::size_t rows, std::size_t hole_at = 0) {
  GyroNoise noise;
  noise.angle_random_walk_deg_rt_h = 0.01;
  noise.rate_random_walk_deg_h_rt_h = 1.0;
  GyroNoiseGenerator generator(noise, 20.0, 4);
  std::ofstream out(path);
  RecordWriter writer(out, {{"test", "static"}}, {});
  RecordSample sample;
  sample.position_angle_deg = 90.0;
  for (std::size_t i = 0; i < rows; ++i) {
    sample.time_s = static_cast<double>(i) / 20.0;
    sample.outputs[0] = generator.next(9.5);
    if (hole_at == 0 || i < hole_at || i >= hole_at + 3) writer.write(sample);
  }
  writer.finish();
}

using Outcome = test::CliOutcome;

class NoiseCommand : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::fresh_test_folder("gyrocal-noise"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(NoiseCommand, WritesTheContractsJsonAndAConfigurationSection) {
  const auto record = dir_ / "static.csv";
  write_static_record(record, 40000);
  const Outcome o =
      test::run_cli("noise " + record.string() + " --json " + (dir_ / "noise.json").string(), dir_);
  ASSERT_EQ(o.status, 0) << o.err;
  std::ifstream in(dir_ / "noise.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_NEAR(j["sample_rate_hz"].get<double>(), 20.0, 1e-9);
  EXPECT_EQ(j["samples"].get<std::size_t>(), 40000u);
  // Every octave m = 1, 2, 4, ... <= N/4, with bounds around the deviation.
  std::size_t m = 1;
  for (const auto& point : j["allan"]) {
    EXPECT_NEAR(point["tau_s"].get<double>(), static_cast<double>(m) / 20.0, 1e-9 * static_cast<double>(m));
    EXPECT_LT(point["adev_low"].get<double>(), point["adev"].get<double>());
    EXPECT_GT(point["adev_high"].get<double>(), point["adev"].get<double>());
    EXPECT_EQ(point["clusters"].get<std::size_t>(), 40000u / m);
    m *= 2;
  }
  EXPECT_EQ(m, 16384u);  // the last was 8192 <= 10000
  const double n = j["terms"]["angle_random_walk_deg_rt_h"]["value"].get<double>();
  EXPECT_NEAR(n, 0.01, 4.0 * j["terms"]["angle_random_walk_deg_rt_h"]["std"].get<double>());
  EXPECT_TRUE(j["terms"].contains("rate_random_walk_deg_h_rt_h"));

  // --toml: a section that a configuration takes as it is, with the fitted values bit for bit.
  const Outcome t = test::run_cli("noise " + record.string() + " --toml", dir_);
  ASSERT_EQ(t.status, 0) << t.err;
  const Scenario s = parse_scenario(t.out, "noise --toml");
  EXPECT_EQ(s.noise.angle_random_walk_deg_rt_h, n);
}

// noise --html: a self-contained report of the same characterisation as --json, written atomically; bad paths
// are refused and leave nothing behind.
TEST_F(NoiseCommand, WritesASelfContainedHtmlReportAndRefusesBadPaths) {
  const auto record = dir_ / "static.csv";
  write_static_record(record, 8000);
  const auto html = dir_ / "noise.html", json_path = dir_ / "noise.json";
  const Outcome o = test::run_cli(
      "noise " + record.string() + " --json " + json_path.string() + " --html " + html.string(), dir_);
  ASSERT_EQ(o.status, 0) << o.err;
  const std::string page = test::slurp(html);
  const nlohmann::json j = nlohmann::json::parse(test::slurp(json_path));
  // The plot description holds every point of --json with its bounds, and the table every fitted term.
  const std::string open = "<script type=\"application/json\" id=\"gyrocal-plots\">";
  const std::size_t at = page.find(open);
  ASSERT_NE(at, std::string::npos);
  const std::size_t start = at + open.size();
  const nlohmann::json plots =
      nlohmann::json::parse(page.substr(start, page.find("</script>", start) - start));
  ASSERT_EQ(plots.size(), 1u);
  ASSERT_EQ(plots[0]["points"].size(), j["allan"].size());
  for (std::size_t k = 0; k < j["allan"].size(); ++k) {
    EXPECT_EQ(plots[0]["points"][k]["x"], j["allan"][k]["tau_s"]);
    EXPECT_EQ(plots[0]["points"][k]["y"], j["allan"][k]["adev"]);
    EXPECT_EQ(plots[0]["low"][k], j["allan"][k]["adev_low"]);
    EXPECT_EQ(plots[0]["high"][k], j["allan"][k]["adev_high"]);
  }
  ASSERT_FALSE(j["terms"].empty());
  for (const auto& [key, term] : j["terms"].items())
    EXPECT_NE(page.find("<td>" + key + "</td>"), std::string::npos) << key;
  // Nothing loaded from outside: the only addresses are in the inlined library's licence comments.
  EXPECT_EQ(page.find("<script src"), std::string::npos);
  EXPECT_EQ(page.find("<link"), std::string::npos);
  EXPECT_NE(page.find("Content-Security-Policy\" content=\"default-src 'none'"), std::string::npos);
  std::string outside = page;
  const std::string library(embedded_plot_library());
  ASSERT_NE(outside.find(library), std::string::npos);
  outside.erase(outside.find(library), library.size());
  EXPECT_EQ(outside.find("http://"), std::string::npos);
  EXPECT_EQ(outside.find("https://"), std::string::npos);

  // An earlier report is replaced without --force.
  EXPECT_EQ(test::run_cli("noise " + record.string() + " --html " + html.string(), dir_).status, 0);
  // The record itself is never the output.
  const std::string record_bytes = test::slurp(record);
  Outcome bad = test::run_cli("noise " + record.string() + " --html " + record.string(), dir_);
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("it is the input"), std::string::npos) << bad.err;
  EXPECT_EQ(test::slurp(record), record_bytes);
  // Another existing file only with --force; refused, neither it nor --json is written.
  const auto other = dir_ / "notes.txt", json2 = dir_ / "second.json";
  { std::ofstream(other) << "my notes\n"; }
  bad = test::run_cli("noise " + record.string() + " --json " + json2.string() + " --html " + other.string(),
                      dir_);
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find(other.string()), std::string::npos) << bad.err;
  EXPECT_EQ(test::slurp(other), "my notes\n");
  EXPECT_FALSE(std::filesystem::exists(json2));
  EXPECT_EQ(test::run_cli("noise " + record.string() + " --html " + other.string() + " --force", dir_).status,
            0);
  EXPECT_EQ(test::slurp(other).rfind("<!DOCTYPE html>", 0), 0u);
  // --json follows the same rule (docs/interface.md, "Files"): another existing file only with --force, an
  // earlier result of gyrocal without it; a refused --json leaves no report either.
  const auto toml = dir_ / "other.toml", html2 = dir_ / "second.html";
  { std::ofstream(toml) << "[test]\nrevolutions = 3\n"; }
  bad = test::run_cli("noise " + record.string() + " --json " + toml.string() + " --html " + html2.string(),
                      dir_);
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("not an earlier gyrocal result"), std::string::npos) << bad.err;
  EXPECT_EQ(test::slurp(toml), "[test]\nrevolutions = 3\n");
  EXPECT_FALSE(std::filesystem::exists(html2));
  EXPECT_EQ(test::run_cli("noise " + record.string() + " --json " + json_path.string(), dir_).status, 0);
  EXPECT_EQ(nlohmann::json::parse(test::slurp(json_path))["gyrocal"]["result"], "noise");
  EXPECT_EQ(test::run_cli("noise " + record.string() + " --json " + toml.string() + " --force", dir_).status,
            0);
  // A folder that does not exist: refused, nothing left behind.
  bad = test::run_cli("noise " + record.string() + " --html " + (dir_ / "no" / "r.html").string(), dir_);
  EXPECT_EQ(bad.status, 1);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "no"));
  // --json and --html naming one file.
  bad = test::run_cli("noise " + record.string() + " --json " + json2.string() + " --html " + json2.string(),
                      dir_);
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("both name"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(json2));
  // No temporary left in the folder.
  for (const auto& entry : std::filesystem::directory_iterator(dir_))
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
}

TEST_F(NoiseCommand, RefusesUnevenSamplingWithItsTime) {
  const auto record = dir_ / "gap.csv";
  write_static_record(record, 2000, 1000);  // rows 1000..1002 missing: 0.2 s between t = 49.95 s and 50.15 s
  const Outcome o = test::run_cli("noise " + record.string(), dir_);
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("uneven at t = 49.95 s"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find(record.string()), std::string::npos) << o.err;
}

}  // namespace
}  // namespace gyrocal
