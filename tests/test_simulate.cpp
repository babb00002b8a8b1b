// The simulator (simulate/simulator.hpp) and `gyrocal simulate`: the record alone is enough to recompute the
// truth, it follows the plan, it is reproducible from its seed, and it is a valid record with its metadata.
// Reduced plans (few revolutions, a low sample rate) keep the run short, also under the sanitizers.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/model/gyro.hpp"
#include "gyrocal/plan/timeline.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/sensor/accelerometer.hpp"
#include "gyrocal/simulate/simulator.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;

/// The default scenario with a short test: rate 9.9 rad/s, then stopped, then -5 rad/s; 3 revolutions per
/// dwell sampled at 50 Hz.
Scenario reduced_scenario() {
  Scenario s = default_scenario();
  s.test.sample_rate_hz = 50.0;
  s.test.revolutions = 3;
  s.test.settle_s = 0.5;
  s.test.rates_rad_s = {9.9, 0.0, -5.0};
  return s;
}

std::string simulate_to_string(const Scenario& s, const SimulationOptions& options = {}) {
  std::ostringstream out;
  simulate_record(s, options, out);
  return out.str();
}

std::vector<RecordSample> read_all(RecordReader& reader) {
  std::vector<RecordSample> rows;
  RecordSample sample;
  while (reader.next(sample)) rows.push_back(sample);
  return rows;
}

/// The measurement interval holding t, or nullptr.
const MeasurementInterval* interval_at(const Timeline& timeline, double t) {
  for (const MeasurementInterval& m : timeline.measurements) {
    if (t >= m.start_s && t < m.end_s) return &m;
  }
  return nullptr;
}

/// Difference of two encoder readings in degrees, modulo 360, in (-180, 180].
double angle_step_deg(double from, double to) {
  const double d = std::fmod(to - from, 360.0);
  return d > 180.0 ? d - 360.0 : (d <= -180.0 ? d + 360.0 : d);
}

TEST(Simulate, NoiseFreeOutputIsTheModelAtTheRecordedAngles) {
  Scenario s = reduced_scenario();
  s.noise = GyroNoise{};
  const CentrifugeModel model = s.model();
  const Timeline timeline = make_timeline(s.test, model);
  RecordReader reader = RecordReader::from_string(simulate_to_string(s));
  const double delta_omega = s.errors.counter_rate_mismatch_rad_s;
  std::map<const MeasurementInterval*, int> checked;
  RecordSample row;
  while (reader.next(row)) {
    const MeasurementInterval* m = interval_at(timeline, row.time_s);
    if (m == nullptr) continue;
    // Only the record's angles and the interval's configured rates: theta steady, psi_r servoed (dwell) or
    // indexed (hold), beta fixed.
    JointState j;
    j.main_angle_rad = row.main_angle_deg * kDegToRad;
    j.main_rate_rad_s = m->rate_rad_s;
    j.counter_angle_rad = row.counter_angle_deg * kDegToRad;
    j.counter_rate_rad_s = m->kind == SegmentKind::kDwell ? -m->rate_rad_s + delta_omega : 0.0;
    j.position_angle_rad = row.position_angle_deg * kDegToRad;
    const SensorInputs in = exact_inputs(model, j);
    ASSERT_NEAR(row.outputs[0], gyro_output_deg_h(s.gyro, in.rate_rad_s.x(), in.specific_force_g), 1e-9)
        << "at t = " << row.time_s << " s";
    ++checked[m];
  }
  // Every measurement interval was sampled through.
  ASSERT_EQ(checked.size(), timeline.measurements.size());
  for (const auto& [m, count] : checked) {
    EXPECT_NEAR(count, (m->end_s - m->start_s) * s.test.sample_rate_hz, 1.0);
  }
}

TEST(Simulate, AnAccelerometersRecordIsItsModelAtTheRecordedAngles) {
  // [sensor] kind = "accelerometer": the fifth column is accel_g and holds the IEEE 1293 model's output at
  // the exact specific force of the record's angles (computed here from the model's chain, not the
  // simulator's).
  Scenario s = reduced_scenario();
  s.sensor_kind = SensorKind::kAccelerometer;
  s.accelerometer.noise = AccelerometerNoise{};
  s.accelerometer.coefficients[AccelCoefficient::K1] = 1.25;  // output units per g
  const CentrifugeModel model = s.model();
  const Timeline timeline = make_timeline(s.test, model);
  const std::string text = simulate_to_string(s);
  RecordReader reader = RecordReader::from_string(text);
  EXPECT_EQ(reader.output_column(), "accel_g");
  EXPECT_EQ(reader.output_unit(), "g");
  EXPECT_NE(text.find("# truth_K3 = 0.8\n"), std::string::npos);
  EXPECT_EQ(text.find("truth_dF"), std::string::npos);  // no gyro truth in an accelerometer's record
  const double delta_omega = s.errors.counter_rate_mismatch_rad_s;
  std::size_t checked = 0;
  RecordSample row;
  while (reader.next(row)) {
    const MeasurementInterval* m = interval_at(timeline, row.time_s);
    if (m == nullptr) continue;
    JointState j;
    j.main_angle_rad = row.main_angle_deg * kDegToRad;
    j.main_rate_rad_s = m->rate_rad_s;
    j.counter_angle_rad = row.counter_angle_deg * kDegToRad;
    j.counter_rate_rad_s = m->kind == SegmentKind::kDwell ? -m->rate_rad_s + delta_omega : 0.0;
    j.position_angle_rad = row.position_angle_deg * kDegToRad;
    const Eigen::Vector3d f = exact_inputs(model, j).specific_force_g;
    const AccelerometerCoefficients& k = s.accelerometer.coefficients;
    const double micro = 1e-6;
    const double input =
        k[AccelCoefficient::K0] * micro + f.x() + k[AccelCoefficient::K2] * micro * f.x() * f.x() +
        k[AccelCoefficient::K3] * micro * f.x() * f.x() * f.x() +
        micro * (k[AccelCoefficient::Kip] * f.x() * f.y() + k[AccelCoefficient::Kio] * f.x() * f.z() +
                 k[AccelCoefficient::Kpo] * f.y() * f.z() + k[AccelCoefficient::Kpp] * f.y() * f.y() +
                 k[AccelCoefficient::Koo] * f.z() * f.z() + k[AccelCoefficient::delta_p] * f.y() +
                 k[AccelCoefficient::delta_o] * f.z());
    ASSERT_NEAR(row.outputs[0], 1.25 * input, 1e-12) << "at t = " << row.time_s << " s";
    ++checked;
  }
  EXPECT_GT(checked, 100u);
}

TEST(Simulate, RecordFollowsThePlan) {
  Scenario s = reduced_scenario();
  const Timeline timeline = make_timeline(s.test, s.model());
  RecordReader reader = RecordReader::from_string(simulate_to_string(s));
  const std::vector<RecordSample> rows = read_all(reader);
  ASSERT_EQ(rows.size(), sample_count(timeline, s.test.sample_rate_hz));
  const double dt = 1.0 / s.test.sample_rate_hz;
  const MotionLimits limits;
  const double max_main_deg = 9.9 * dt * kRadToDeg;
  const double max_position_deg = limits.platform_rate_rad_s * dt * kRadToDeg;
  std::map<const MeasurementInterval*, std::vector<double>> gammas_deg;  // gamma of each dwell's samples
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const RecordSample& r = rows[i];
    EXPECT_EQ(r.time_s, static_cast<double>(i) / s.test.sample_rate_hz);
    for (const double angle : {r.main_angle_deg, r.counter_angle_deg, r.position_angle_deg}) {
      EXPECT_GE(angle, 0.0);
      EXPECT_LT(angle, 360.0);
    }
    if (i > 0) {
      // No jump: each encoder moves at most what its top rate allows in one sample.
      const RecordSample& p = rows[i - 1];
      EXPECT_LE(std::abs(angle_step_deg(p.main_angle_deg, r.main_angle_deg)), max_main_deg * (1 + 1e-9));
      EXPECT_LE(std::abs(angle_step_deg(p.counter_angle_deg, r.counter_angle_deg)),
                max_main_deg * (1 + 1e-6));
      EXPECT_LE(std::abs(angle_step_deg(p.position_angle_deg, r.position_angle_deg)),
                max_position_deg * (1 + 1e-9));
    }
    // The encoders read the timeline's joints at the row's time.
    const JointState j = joint_state_at(timeline, r.time_s);
    EXPECT_NEAR(angle_step_deg(j.main_angle_rad * kRadToDeg, r.main_angle_deg), 0.0, 1e-9);
    EXPECT_NEAR(angle_step_deg(j.counter_angle_rad * kRadToDeg, r.counter_angle_deg), 0.0, 1e-9);
    EXPECT_NEAR(angle_step_deg(j.position_angle_rad * kRadToDeg, r.position_angle_deg), 0.0, 1e-9);
    const MeasurementInterval* m = interval_at(timeline, r.time_s);
    if (m == nullptr) continue;
    EXPECT_NEAR(angle_step_deg(m->beta_rad * kRadToDeg, r.position_angle_deg), 0.0, 1e-9);
    if (m->kind == SegmentKind::kHold) {
      EXPECT_NEAR(angle_step_deg(-m->gamma_rad * kRadToDeg, r.counter_angle_deg), 0.0, 1e-9);
    } else {
      gammas_deg[m].push_back(360.0 - r.counter_angle_deg);
    }
  }
  // In every dwell the arm passes every gamma of the plan at least revolutions - 1 times: gamma steps by less
  // than 180 deg per sample, so a pass is a sign change of the step-wise distance to gamma.
  ASSERT_EQ(gammas_deg.size(), 8u);
  for (const auto& [m, gammas] : gammas_deg) {
    for (const double gamma_rad : s.test.gamma_rad) {
      int passes = 0;
      for (std::size_t i = 1; i < gammas.size(); ++i) {
        const double a = angle_step_deg(gamma_rad * kRadToDeg, gammas[i - 1]);
        const double b = angle_step_deg(gamma_rad * kRadToDeg, gammas[i]);
        if ((a < 0.0) != (b < 0.0) && std::abs(a - b) < 180.0) ++passes;
      }
      EXPECT_GE(passes, s.test.revolutions - 1)
          << "gamma " << gamma_rad * kRadToDeg << " deg, dwell at " << m->start_s << " s";
    }
  }
}

TEST(Simulate, SameSeedSameBytesAnotherSeedOtherBytes) {
  Scenario s = reduced_scenario();
  s.test.rates_rad_s = {9.9};
  s.noise.bias_instability_deg_h = 0.01;
  s.noise.rate_random_walk_deg_h_rt_h = 0.01;
  const std::string a = simulate_to_string(s);
  EXPECT_EQ(a, simulate_to_string(s));
  SimulationOptions other;
  other.seed = s.test.seed + 1;
  const std::string b = simulate_to_string(s, other);
  EXPECT_NE(a, b);
  // Only the seed line and the gyro column differ: the noise depends on the seed, nothing else does.
  RecordReader ra = RecordReader::from_string(a), rb = RecordReader::from_string(b);
  const std::vector<RecordSample> rows_a = read_all(ra), rows_b = read_all(rb);
  ASSERT_EQ(rows_a.size(), rows_b.size());
  int different = 0;
  for (std::size_t i = 0; i < rows_a.size(); ++i) {
    EXPECT_EQ(rows_a[i].main_angle_deg, rows_b[i].main_angle_deg);
    EXPECT_EQ(rows_a[i].counter_angle_deg, rows_b[i].counter_angle_deg);
    different += rows_a[i].outputs[0] != rows_b[i].outputs[0];
  }
  EXPECT_EQ(different, int(rows_a.size()));
}

TEST(Simulate, RecordIsValidWithItsMetadata) {
  const Scenario s = reduced_scenario();
  std::vector<double> fractions;
  SimulationOptions options;
  options.progress = [&fractions](double f) { fractions.push_back(f); };
  std::ostringstream out;
  const SimulationSummary summary = simulate_record(s, options, out);
  RecordReader reader = RecordReader::from_string(out.str());
  EXPECT_EQ(read_all(reader).size(), summary.samples);
  const Timeline timeline = make_timeline(s.test, s.model());
  EXPECT_EQ(summary.samples, sample_count(timeline, s.test.sample_rate_hz));
  EXPECT_EQ(summary.duration_s, timeline.duration_s);
  EXPECT_EQ(summary.seed, s.test.seed);
  ASSERT_FALSE(fractions.empty());
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  EXPECT_EQ(fractions.back(), 1.0);

  std::map<std::string, std::string> meta(reader.metadata().begin(), reader.metadata().end());
  for (const char* key : {"generator", "seed", "sample_rate_hz", "settle_s", "revolutions", "rates_rad_s",
                          "beta_deg", "gamma_deg", "radius_m", "angles", "hold_s", "duration_s", "samples"}) {
    EXPECT_TRUE(meta.count(key)) << key;
  }
  EXPECT_EQ(meta["seed"], "1");
  EXPECT_EQ(meta["sample_rate_hz"], "50");
  EXPECT_EQ(meta["revolutions"], "3");
  EXPECT_EQ(meta["rates_rad_s"], "[9.9, 0, -5]");
  EXPECT_EQ(meta["beta_deg"], "[0, 180, 90, 270]");
  EXPECT_EQ(meta["gamma_deg"], "[0, 180, 90, 270]");
  EXPECT_EQ(meta["radius_m"], "1");
  EXPECT_EQ(meta["samples"], std::to_string(summary.samples));
  // The truth reads back bit for bit.
  for (std::size_t i = 0; i < kNumGyroCoefficients; ++i) {
    const std::string key = "truth_" + std::string(kCoefficientNames[i]);
    ASSERT_TRUE(meta.count(key)) << key;
    EXPECT_EQ(std::stod(meta[key]), s.gyro.values[i]) << key;
  }
}

// The command line: the default test as a valid record; a configured test, --force, and never over its own
// configuration.
class SimulateCommand : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("gyrocal_test_simulate_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Runs gyrocal with `arguments`; returns the exit status, standard output in `out`.
  int run(const std::string& arguments, std::string* out = nullptr) {
    const fs::path stdout_path = dir_ / "stdout.txt";
    const std::string command = std::string(GYROCAL_CLI) + " " + arguments + " > " + stdout_path.string() +
                                " 2> " + (dir_ / "stderr.txt").string();
    const int status = std::system(command.c_str());
    if (out) {
      std::ifstream in(stdout_path);
      *out = std::string(std::istreambuf_iterator<char>(in), {});
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  std::string read(const fs::path& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

  fs::path dir_;
};

TEST_F(SimulateCommand, WritesTheDefaultTestAsAValidRecord) {
  const fs::path record = dir_ / "record.csv";
  std::string out;
  // Progress shows after 1 s even when standard error is a file (a line per tenth); a sanitizer build on a
  // busy machine takes longer than that, so the delay is moved out of reach: what must stay empty is every
  // warning.
  ::setenv("GYROCAL_PROGRESS_AFTER_S", "3600", 1);
  const int status = run("simulate --out " + record.string(), &out);
  ::unsetenv("GYROCAL_PROGRESS_AFTER_S");
  ASSERT_EQ(status, 0) << read(dir_ / "stderr.txt");
  EXPECT_TRUE(read(dir_ / "stderr.txt").empty())
      << read(dir_ / "stderr.txt");  // no warning on the default test
  RecordReader reader(record);
  const std::vector<RecordSample> rows = read_all(reader);
  const Scenario s = default_scenario();
  EXPECT_EQ(rows.size(), sample_count(make_timeline(s.test, s.model()), s.test.sample_rate_hz));
  EXPECT_NE(out.find(std::to_string(rows.size()) + " samples"), std::string::npos) << out;
  EXPECT_EQ(std::vector<fs::path>(fs::directory_iterator(dir_), {}).size(), 3u);  // no temporary left
}

TEST_F(SimulateCommand, UsesTheConfigurationAndNeverOverwritesIt) {
  const fs::path config = dir_ / "test.toml";
  std::ofstream(config) << "[test]\nsample_rate_hz = 20.0\nrevolutions = 2\nrates_rad_s = [0.0]\n";
  const std::string text = read(config);
  EXPECT_NE(run("simulate --force --config " + config.string() + " --out " + config.string()), 0);
  EXPECT_EQ(read(config), text);
  const fs::path record = dir_ / "record.csv";
  ASSERT_EQ(run("simulate --config " + config.string() + " --out " + record.string()), 0)
      << read(dir_ / "stderr.txt");
  RecordReader reader(record);
  std::map<std::string, std::string> meta(reader.metadata().begin(), reader.metadata().end());
  EXPECT_EQ(meta["rates_rad_s"], "[0]");
  EXPECT_EQ(meta["sample_rate_hz"], "20");
  // The same record again is refused unless --force, and the file is left as it was.
  const std::string before = read(record);
  const std::string other_seed =
      "simulate --seed 7 --config " + config.string() + " --out " + record.string();
  EXPECT_NE(run(other_seed), 0);
  EXPECT_NE(read(dir_ / "stderr.txt").find("--force"), std::string::npos);
  EXPECT_EQ(read(record), before);
  ASSERT_EQ(run(other_seed + " --force"), 0);
  EXPECT_NE(read(record), before);
}

}  // namespace
}  // namespace gyrocal
