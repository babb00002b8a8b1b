// An accelerometer's records, configuration and noise (issue 19; docs/accelerometer.md, docs/records.md,
// docs/noise.md): [record] output_scale_per_g read into g and refused where it does not fit the sensor, a
// record whose output column is the other sensor's refused naming the column and the kind, and the noise of a
// static accelerometer record keyed as [accelerometer.noise].
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gyrocal/analysis/record_noise.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/record_check.hpp"
#include "gyrocal/plan/positions.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/simulate/accelerometer_noise.hpp"
#include "support/cli_run.hpp"
#include "support/rig_record.hpp"
#include "support/sanitized.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;

/// The message of parsing a configuration, or "" when it parses.
std::string config_error(const std::string& toml) {
  try {
    parse_scenario(toml, "rig.toml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

constexpr std::string_view kAccelerometer = "[sensor]\nkind = \"accelerometer\"\n";

TEST(AccelerometerRecordConfig, OutputScalePerGReadsTheRigsUnitsIntoG) {
  const Scenario s = parse_scenario(std::string(kAccelerometer) +
                                        "[record]\ntime_column = \"t\"\noutput_column = \"U_mV\"\n"
                                        "output_scale_per_g = -2500.0\noutput_offset = 12.5\n",
                                    "rig.toml");
  ASSERT_TRUE(s.record.has_value());
  const RecordLayout& l = *s.record;
  EXPECT_EQ(l.output_quantity, OutputQuantity::kSpecificForce);
  EXPECT_EQ(l.output_scale(), -2500.0);
  EXPECT_EQ(l.output_unit(), "g");
  EXPECT_EQ(output_scale_per_g(s.record), -2500.0);  // what K1 is reported in the rig's units with
  // A row of 0.5 g on an inverted channel of 2500 mV/g with a 12.5 mV zero: 12.5 - 1250 mV.
  RecordReader reader = RecordReader::from_string("t,U_mV\n0,-1237.5\n0.01,12.5\n", s.record, "rig.csv");
  EXPECT_EQ(reader.output_unit(), "g");
  RecordSample row;
  ASSERT_TRUE(reader.next(row));
  EXPECT_DOUBLE_EQ(row.outputs[0], 0.5);
  ASSERT_TRUE(reader.next(row));
  EXPECT_EQ(row.outputs[0], 0.0);
  // The written configuration reads back as the same layout.
  EXPECT_EQ(parse_scenario(scenario_to_toml(s), "again.toml").record, s.record);
  // An accelerometer's [record] without output_column reads gyrocal's own column name, accel_g.
  const Scenario plain = parse_scenario(std::string(kAccelerometer) + "[record]\n", "rig.toml");
  EXPECT_EQ(plain.record->output_column, "accel_g");
  EXPECT_EQ(output_scale_per_g(plain.record), 1.0);
  // A gyro's layout, or none, is no accelerometer's scale.
  EXPECT_EQ(output_scale_per_g(std::nullopt), 1.0);
  EXPECT_EQ(output_scale_per_g(parse_scenario("[record]\noutput_scale_per_deg_h = 3.0\n", "g.toml").record),
            1.0);
}

TEST(AccelerometerRecordConfig, AScaleThatDoesNotFitTheSensorIsRefusedNamingTheKeyAndTheKind) {
  const std::string gyro_with_g = config_error("[record]\noutput_scale_per_g = 2.0\n");
  EXPECT_NE(gyro_with_g.find("rig.toml, line 2: record.output_scale_per_g is an accelerometer's scale"),
            std::string::npos)
      << gyro_with_g;
  EXPECT_NE(gyro_with_g.find("sensor.kind absent or \"gyro\""), std::string::npos) << gyro_with_g;

  const std::string accel_with_deg_h =
      config_error(std::string(kAccelerometer) + "[record]\noutput_scale_per_deg_h = 2.0\n");
  EXPECT_NE(accel_with_deg_h.find("rig.toml, line 4: record.output_scale_per_deg_h is a gyro's scale"),
            std::string::npos)
      << accel_with_deg_h;
  EXPECT_NE(accel_with_deg_h.find("sensor.kind is \"accelerometer\""), std::string::npos) << accel_with_deg_h;

  const std::string both = config_error(std::string(kAccelerometer) +
                                        "[record]\noutput_scale_per_g = 2.0\noutput_scale_per_deg_h = 2.0\n");
  EXPECT_NE(both.find("line 5: record.output_scale_per_deg_h and record.output_scale_per_g are both given"),
            std::string::npos)
      << both;

  for (const char* bad : {"0", "nan", "inf"}) {
    const std::string zero =
        config_error(std::string(kAccelerometer) + "[record]\noutput_scale_per_g = " + bad + "\n");
    EXPECT_NE(zero.find("line 4: record.output_scale_per_g must be a finite"), std::string::npos) << zero;
  }
  // A layout built in code that mixes the two is refused by its own check, naming the key.
  RecordLayout mixed;
  mixed.output_scale_per_g = 3.0;
  std::string error, key;
  EXPECT_FALSE(mixed.IsValid(&error, &key));
  EXPECT_EQ(key, "output_scale_per_g");
  mixed.output_quantity = OutputQuantity::kSpecificForce;
  EXPECT_TRUE(mixed.IsValid(&error, &key)) << error;
  mixed.output_scale_per_deg_h = 2.0;
  EXPECT_FALSE(mixed.IsValid(&error, &key));
  EXPECT_EQ(key, "output_scale_per_deg_h");
}

/// The message of require_output_for_sensor on `text` read as gyrocal's own format (or through `layout`).
std::string output_error(const std::string& text, SensorKind kind,
                         const std::optional<RecordLayout>& layout = std::nullopt) {
  try {
    require_output_for_sensor(RecordReader::from_string(text, layout, "r.csv"), kind, "c.toml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(AccelerometerRecordCheck, AnOutputColumnOfTheOtherSensorIsRefusedNamingTheColumnAndTheKind) {
  const std::string magic = std::string(kRecordMagic) + "\n";
  const std::string full_accel =
      magic + "time_s,main_angle_deg,counter_angle_deg,position_angle_deg,accel_g\n";
  const std::string full_gyro =
      magic + "time_s,main_angle_deg,counter_angle_deg,position_angle_deg,gyro_deg_h\n";
  const std::string lone_accel = magic + "time_s,accel_g\n";
  const std::string lone_gyro = magic + "time_s,gyro_deg_h\n";
  for (const std::string& accel : {full_accel, lone_accel}) {
    const std::string e = output_error(accel, SensorKind::kGyro);
    EXPECT_NE(e.find("r.csv: its output column is accel_g"), std::string::npos) << e;
    EXPECT_NE(e.find("the sensor of c.toml is the gyro (sensor.kind absent or \"gyro\")"), std::string::npos)
        << e;
    EXPECT_EQ(output_error(accel, SensorKind::kAccelerometer), "");
  }
  for (const std::string& gyro : {full_gyro, lone_gyro}) {
    const std::string e = output_error(gyro, SensorKind::kAccelerometer);
    EXPECT_NE(e.find("r.csv: its output column is gyro_deg_h"), std::string::npos) << e;
    EXPECT_NE(e.find("an accelerometer (sensor.kind = \"accelerometer\")"), std::string::npos) << e;
    EXPECT_EQ(output_error(gyro, SensorKind::kGyro), "");
  }
  // Through a layout: a column named as the other sensor's own is refused; a rig's own name is the
  // configuration's sensor.
  const RecordLayout accel_layout =
      *parse_scenario(std::string(kAccelerometer) + "[record]\noutput_column = \"gyro_deg_h\"\n", "c.toml")
           .record;
  EXPECT_NE(output_error("time_s,gyro_deg_h\n", SensorKind::kAccelerometer, accel_layout)
                .find("its output column is gyro_deg_h"),
            std::string::npos);
  const RecordLayout rig = *parse_scenario(std::string(kAccelerometer) +
                                               "[record]\noutput_column = \"U\"\noutput_scale_per_g = 5.0\n",
                                           "c.toml")
                                .record;
  EXPECT_EQ(output_error("time_s,U\n", SensorKind::kAccelerometer, rig), "");
}

class AccelerometerRecordCli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::fresh_test_folder("gyrocal-accel-record"); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(AccelerometerRecordCli, CalibrateAndNoiseRefuseTheOtherSensorsRecordNamingTheColumn) {
  // A short static accelerometer record of its output alone, and a gyro's.
  {
    std::ofstream a(dir_ / "accel.csv"), g(dir_ / "gyro.csv");
    a << kRecordMagic << "\ntime_s,main_angle_deg,counter_angle_deg,position_angle_deg,accel_g\n";
    g << kRecordMagic << "\ntime_s,main_angle_deg,counter_angle_deg,position_angle_deg,gyro_deg_h\n";
    for (int i = 0; i < 64; ++i) {
      a << fmt::format("{},0,0,0,{}\n", i * 0.01, 1.0 + 1e-5 * std::sin(1.7 * i * i));
      g << fmt::format("{},0,0,0,{}\n", i * 0.01, 9.0 + 0.1 * std::sin(1.7 * i * i));
    }
  }
  {
    std::ofstream c(dir_ / "accel.toml");
    c << kAccelerometer;
  }
  const test::CliOutcome calibrate = test::run_cli("calibrate " + (dir_ / "accel.csv").string(), dir_);
  EXPECT_NE(calibrate.status, 0);
  EXPECT_NE(calibrate.err.find("its output column is accel_g"), std::string::npos) << calibrate.err;
  EXPECT_NE(calibrate.err.find("the built-in scenario is the gyro"), std::string::npos) << calibrate.err;

  const test::CliOutcome noise = test::run_cli(
      "noise " + (dir_ / "gyro.csv").string() + " --config " + (dir_ / "accel.toml").string(), dir_);
  EXPECT_NE(noise.status, 0);
  EXPECT_NE(noise.err.find("its output column is gyro_deg_h"), std::string::npos) << noise.err;
  EXPECT_NE(noise.err.find("sensor.kind = \"accelerometer\""), std::string::npos) << noise.err;
}

TEST_F(AccelerometerRecordCli, InitWritesADefaultAccelerometerScenarioThatSimulates) {
  const fs::path config = dir_ / "accel.toml", record = dir_ / "accel.csv";
  const test::CliOutcome init = test::run_cli("init --sensor accelerometer " + config.string(), dir_);
  ASSERT_EQ(init.status, 0) << init.err;
  const std::string text = test::slurp(config);
  // One sensor's file: no [gyro*] section or gyro key, the accelerometer's sections with the contract's
  // defaults.
  EXPECT_EQ(text.find("[gyro"), std::string::npos);
  EXPECT_EQ(text.find("gyro_model"), std::string::npos);
  for (const char* line :
       {"kind = \"accelerometer\"", "[accelerometer]", "K0_ug = 50.0", "K1 = 1.0", "K3_ug_g3 = 0.8",
        "delta_p_urad = 300.0", "[accelerometer.noise]", "velocity_random_walk_ug_rt_hz = 10.0",
        "bias_instability_ug = 0.0", "quantization_ug = 0.0", "# output_scale_per_g = 1.0",
        "# output_column = \"accel_g\""})
    EXPECT_NE(text.find(line), std::string::npos) << line;
  // It reads back as the default accelerometer scenario, whose test identifies all eleven coefficients: a
  // static set and two speeds (K0, K2, Kpp, Koo apart), four beta, and more than seven gamma (K3 apart from
  // the scale: docs/accelerometer.md).
  const Scenario s = load_scenario(config);
  EXPECT_EQ(s.sensor_kind, SensorKind::kAccelerometer);
  EXPECT_EQ(scenario_to_toml(s), text);
  EXPECT_EQ(scenario_to_toml(default_accelerometer_scenario()), text);
  EXPECT_EQ(s.accelerometer.coefficients.values, Accelerometer::default_coefficients().values);
  EXPECT_EQ(s.accelerometer.noise.velocity_random_walk_ug_rt_hz, 10.0);
  const std::vector<double>& rates = s.test.rates_rad_s;
  EXPECT_EQ(std::count(rates.begin(), rates.end(), 0.0), 1);
  EXPECT_EQ(std::count_if(rates.begin(), rates.end(), [](double r) { return r != 0.0; }), 2);
  EXPECT_EQ(s.test.beta_rad.size(), 4u);
  EXPECT_GE(s.test.gamma_rad.size(), 7u);
  // The gyro's default is what `init` writes without --sensor, and with --sensor gyro.
  const test::CliOutcome gyro = test::run_cli("init --sensor gyro", dir_);
  EXPECT_EQ(gyro.out, scenario_to_toml(default_scenario()));
  EXPECT_EQ(test::run_cli("init", dir_).out, gyro.out);
  const test::CliOutcome wrong = test::run_cli("init --sensor magnetometer", dir_);
  EXPECT_NE(wrong.status, 0);
  EXPECT_NE(wrong.err.find("--sensor"), std::string::npos) << wrong.err;

  // simulate writes its record: the accelerometer's column, in g.
  const test::CliOutcome sim =
      test::run_cli("simulate --config " + config.string() + " --out " + record.string(), dir_);
  ASSERT_EQ(sim.status, 0) << sim.err;
  RecordReader reader(record);
  EXPECT_EQ(reader.output_column(), "accel_g");
  EXPECT_EQ(reader.output_unit(), "g");
}

TEST(AccelerometerRigRecord, ARigsRecordInMillivoltsPerGReadsBackInG) {
  // A short default accelerometer test on a rig whose channel gives 2500 mV/g, inverted: every imperfection
  // but the drive's offset (so that the largest centripetal force is the planned rate's) and spikes.
  Scenario s = default_accelerometer_scenario();
  s.test.revolutions = 4;
  s.test.static_hold_s = 2.0;
  s.test.settle_s = 1.0;
  s.test.sample_rate_hz = 100.0;
  constexpr double kMilliVoltPerG = -2500.0;
  s.accelerometer.coefficients[AccelCoefficient::K1] = kMilliVoltPerG;
  testing::RigImperfections imp = testing::every_imperfection();
  imp.rate_offset = 0.0;
  imp.spikes = 0;
  imp.clock_jump_s = 0.0;
  std::vector<testing::RigRow> rows;
  testing::rig_rows(s, imp, {}, 3, [&rows](const testing::RigRow& r) { rows.push_back(r); });
  std::string text = "t_ms;theta;psi;beta;U_mV\n";
  for (const testing::RigRow& r : rows)
    text += fmt::format("{};{};{};{};{}\n", r.time_s * 1e3, r.main_angle_deg, r.counter_angle_deg,
                        r.position_angle_deg, r.output);
  const Scenario rig = parse_scenario(
      std::string(kAccelerometer) +
          "[record]\ndelimiter = \";\"\ntime_column = \"t_ms\"\ntime_unit = \"ms\"\n"
          "main_angle_column = \"theta\"\ncounter_angle_column = \"psi\"\nposition_angle_column = \"beta\"\n"
          "output_column = \"U_mV\"\noutput_scale_per_g = -2500.0\n",
      "rig.toml");
  RecordReader reader = RecordReader::from_string(text, rig.record, "rig.csv");
  require_output_for_sensor(reader, SensorKind::kAccelerometer, "rig.toml");
  EXPECT_EQ(reader.output_unit(), "g");
  // The planned centripetal force at the top rate, g: omega^2 R0 / g.
  double top_rate = 0.0;
  for (double r : s.test.rates_rad_s) top_rate = std::max(top_rate, std::abs(r));
  const double top_g = top_rate * top_rate * s.centrifuge.radius_m / s.site.gravity_m_s2;
  double largest = 0.0;
  std::size_t up = 0, down = 0;
  RecordSample sample;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    ASSERT_TRUE(reader.next(sample));
    ASSERT_NEAR(sample.outputs[0], rows[i].output / kMilliVoltPerG, 1e-15 * std::abs(rows[i].output));
    largest = std::max(largest, std::abs(sample.outputs[0]));
    // Stopped (the main encoder unchanged since the last row) with the input axis vertical (beta 90 or 270
    // deg): one g along it, up or down, whatever gamma.
    const bool stopped = i > 0 && rows[i].main_angle_deg == rows[i - 1].main_angle_deg;
    const double beta = rows[i].position_angle_deg;
    if (stopped && std::abs(beta - 90.0) < 0.01) {
      EXPECT_NEAR(sample.outputs[0], 1.0, 1e-3) << "row " << i;
      ++up;
    }
    if (stopped && std::abs(beta - 270.0) < 0.01) {
      EXPECT_NEAR(sample.outputs[0], -1.0, 1e-3) << "row " << i;
      ++down;
    }
  }
  EXPECT_FALSE(reader.next(sample));
  EXPECT_GT(up, 1000u);
  EXPECT_GT(down, 1000u);
  // Spinning, the centripetal force sweeps the input axis: its largest reading is the top rate's (with the
  // drive's ripple of 2e-4 and gravity across it, to second order).
  EXPECT_NEAR(largest, top_g, 2e-3 * top_g);

  // The reducer finds every dwell of the plan in it, in the rig's own order: each spinning (rate, beta) and
  // each static hold (beta, gamma).
  RecordReader again = RecordReader::from_string(text, rig.record, "rig.csv");
  const Reduction reduction = reduce_record(again, s.test, s.reduce, s.centrifuge.rate_rad_s);
  const std::size_t spinning = 2 * s.test.beta_rad.size(),
                    holds = s.test.beta_rad.size() * s.test.gamma_rad.size();
  EXPECT_EQ(reduction.dwells.size(), spinning + holds);
  // (The platform's moves between holds and the rest before the test are steady runs that give no dwell.)
}

using testing::sanitized;

/// A static accelerometer's output (its input axis up: 1 g) with `noise`, in output units of `k1` per g, at
/// fs, written as "time,output" rows after `head`.
void write_static_accelerometer(const fs::path& path, const std::string& head,
                                const AccelerometerNoise& noise, double k1, double fs, std::size_t rows,
                                std::uint64_t seed) {
  AccelerometerNoiseGenerator generator(noise, k1, fs, seed);
  std::ofstream out(path);
  out << head;
  for (std::size_t i = 0; i < rows; ++i)
    out << fmt::format("{},{}\n", static_cast<double>(i) / fs, generator.next(k1 * 1.0));
}

TEST_F(AccelerometerRecordCli, NoiseRecoversAStaticAccelerometersWhiteNoiseAndBiasInstability) {
  // White noise of 10 ug/sqrt(Hz) and a bias instability of 1.5 ug, whose floor (1.0 ug) meets the white
  // noise's 10/sqrt(tau) ug at tau ~ 100 s: a record of 11 h at 5 Hz sees both.
  AccelerometerNoise noise;
  noise.velocity_random_walk_ug_rt_hz = 10.0;
  noise.bias_instability_ug = 1.5;
  const double fs = 5.0;
  const std::size_t rows = sanitized() ? 50000 : 200000;
  const fs::path native = dir_ / "static.csv", rig = dir_ / "rig.csv", config = dir_ / "rig.toml";
  write_static_accelerometer(native, std::string(kRecordMagic) + "\ntime_s,accel_g\n", noise, 1.0, fs, rows,
                             8);
  // The same noise from a channel of 2 V/g, read through [record] output_scale_per_g.
  write_static_accelerometer(rig, "t,U_V\n", noise, 2.0, fs, rows, 8);
  {
    std::ofstream c(config);
    c << kAccelerometer
      << "[record]\ntime_column = \"t\"\noutput_column = \"U_V\"\noutput_scale_per_g = 2.0\n";
  }
  const test::CliOutcome o =
      test::run_cli("noise " + native.string() + " --json " + (dir_ / "noise.json").string(), dir_);
  ASSERT_EQ(o.status, 0) << o.err;
  const nlohmann::json j = nlohmann::json::parse(test::slurp(dir_ / "noise.json"));
  EXPECT_EQ(j["sensor"], "accelerometer");
  EXPECT_EQ(j["unit"], "ug");
  const nlohmann::json& terms = j["terms"];
  ASSERT_TRUE(terms.contains("velocity_random_walk_ug_rt_hz")) << terms.dump();
  ASSERT_TRUE(terms.contains("bias_instability_ug")) << terms.dump();
  EXPECT_FALSE(terms.contains("angle_random_walk_deg_rt_h"));
  const double n = terms["velocity_random_walk_ug_rt_hz"]["value"],
               n_std = terms["velocity_random_walk_ug_rt_hz"]["std"];
  const double b = terms["bias_instability_ug"]["value"], b_std = terms["bias_instability_ug"]["std"];
  // Within three stated standard uncertainties, and the uncertainties themselves a fraction of the values.
  EXPECT_NEAR(n, 10.0, 3.0 * n_std);
  EXPECT_NEAR(b, 1.5, 3.0 * b_std);
  EXPECT_LT(n_std, 0.1 * n);
  EXPECT_LT(b_std, 0.3 * b);
  // The Allan deviation at the first octave is the white noise's, in ug: N sqrt(fs) (one sample's sigma).
  EXPECT_NEAR(j["allan"][0]["adev"].get<double>() / (10.0 * std::sqrt(fs)), 1.0, 0.02);

  // Through [record]: the same rows in g, so the same characterisation, bit for bit; --toml prints
  // [accelerometer.noise], which an accelerometer's configuration takes as it is.
  RecordNoiseOptions options;
  options.sensor = SensorKind::kAccelerometer;
  const RecordNoise from_rig = characterise_record_noise(rig, options, load_scenario(config).record);
  const RecordNoise from_native = characterise_record_noise(native);
  EXPECT_EQ(from_rig.noise.allan.deviation, from_native.noise.allan.deviation);
  const test::CliOutcome t =
      test::run_cli("noise " + rig.string() + " --config " + config.string() + " --toml", dir_);
  ASSERT_EQ(t.status, 0) << t.err;
  EXPECT_NE(t.out.find("[accelerometer.noise]"), std::string::npos) << t.out;
  const Scenario s = parse_scenario(std::string(kAccelerometer) + t.out, "noise --toml");
  EXPECT_EQ(s.accelerometer.noise.velocity_random_walk_ug_rt_hz, n);
  EXPECT_EQ(s.accelerometer.noise.bias_instability_ug, b);
  EXPECT_EQ(s.accelerometer.noise.quantization_ug, 0.0);  // a continuous output: no grid

  // The report page names the accelerometer's terms and units.
  const test::CliOutcome html =
      test::run_cli("noise " + native.string() + " --html " + (dir_ / "noise.html").string(), dir_);
  ASSERT_EQ(html.status, 0) << html.err;
  const std::string page = test::slurp(dir_ / "noise.html");
  EXPECT_NE(page.find("velocity random walk"), std::string::npos);
  EXPECT_NE(page.find("velocity_random_walk_ug_rt_hz"), std::string::npos);
  EXPECT_NE(page.find("\xC2\xB5g"), std::string::npos);
  EXPECT_EQ(page.find("angle random walk"), std::string::npos);
}

TEST(AccelerometerNoiseRecord, AnOutputsResolutionIsTheStepOfTheGridItsValuesLieOn) {
  // quantization_ug = 2: every output is a multiple of 2 ug (referred to the input), whatever K1.
  AccelerometerNoise noise;
  noise.velocity_random_walk_ug_rt_hz = 10.0;
  noise.quantization_ug = 2.0;
  const double fs = 100.0;
  AccelerometerNoiseGenerator generator(noise, 2.0, fs, 4);
  std::vector<double> t, g;
  for (int i = 0; i < 20000; ++i) {
    t.push_back(i / fs);
    g.push_back(generator.next(2.0 * -1.0) / 2.0);  // input axis down, read in g
  }
  RecordNoiseOptions options;
  options.sensor = SensorKind::kAccelerometer;
  const RecordNoise r = characterise_samples_noise(t, g, "q", options);
  ASSERT_TRUE(r.resolution.has_value());
  EXPECT_NEAR(*r.resolution, 2.0, 1e-6);
  // A continuous output lies on no grid; nor do values whose steps are not multiples of one step.
  noise.quantization_ug = 0.0;
  AccelerometerNoiseGenerator continuous(noise, 1.0, fs, 4);
  std::vector<double> c;
  for (std::size_t i = 0; i < t.size(); ++i) c.push_back(continuous.next(1.0));
  EXPECT_FALSE(characterise_samples_noise(t, c, "c", options).resolution.has_value());
  const auto repeated = [](std::vector<double> levels) {
    std::vector<double> v;
    for (int k = 0; k < 4; ++k) v.insert(v.end(), levels.begin(), levels.end());
    return v;
  };
  EXPECT_FALSE(output_grid_step(repeated({0.0, 1.0, 2.5})).has_value());
  EXPECT_NEAR(output_grid_step(repeated({0.0, 3.0, 9.0, 6.0})).value(), 3.0, 1e-12);
}

}  // namespace
}  // namespace gyrocal
