// A whole IMU's configuration (docs/imu.md, "Configuration"): [sensor] kind = "imu" and its [[channel]]
// tables read into Scenario::imu_channels (axes, outputs, truth, noise), the default IMU written by `init
// --sensor imu` and read back unchanged, every bad channel refused naming its key and line, and the commands
// that do not serve an IMU yet refusing one with one sentence.
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <variant>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/LU>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/record/record.hpp"
#include "support/cli_run.hpp"

namespace gyrocal {
namespace {

using test::CliOutcome;
using test::fresh_test_folder;
using test::run_cli;

bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

/// The message parse_scenario throws for `text` (read as "imu.toml"); "" when it accepts it.
std::string refusal(const std::string& text) {
  try {
    parse_scenario(text, "imu.toml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

/// Expects `text` refused with a message holding each of `words`.
void expect_refused(const std::string& text, const std::vector<std::string>& words) {
  const std::string message = refusal(text);
  ASSERT_FALSE(message.empty()) << "accepted:\n" << text;
  for (const std::string& w : words)
    EXPECT_NE(message.find(w), std::string::npos) << "'" << w << "' not in: " << message;
}

/// A matrix from its rows, written out by hand.
Eigen::Matrix3d rows(std::initializer_list<std::initializer_list<double>> r) {
  Eigen::Matrix3d m;
  int i = 0;
  for (const auto& row : r) {
    int j = 0;
    for (double v : row) m(i, j++) = v;
    ++i;
  }
  return m;
}

// ---- a six-channel configuration read ------------------------------------------------------------------

// Line numbers matter below: the refusals name them.
constexpr const char* kSixChannels = R"(# six channels on unusual axes
[sensor]
kind = "imu"

[calibration]
gyro_model = "drift+rate"

[[channel]]
name = "gx"
sensor = "gyro"
input_axis = "+x"
second_axis = "+y"
output = "increment"
output_scale = 4.84813681109536e-6
output_unit = "rad/s"
[channel.truth]
dF = 2.5
dIO = -0.125
scale_factor_error_ppm = 40.0
input_axis_misalignment_arcsec = [3.0, -4.0]
[channel.noise]
angle_random_walk_deg_rt_h = 0.003

[[channel]]
name = "gy"
sensor = "gyro"
input_axis = "-z"
second_axis = "+y"
column = "GYRO_Y"
output_scale = -2.0

[[channel]]
name = "gz"
sensor = "gyro"
input_axis = "+z"
second_axis = "-x"

[[channel]]
name = "ax"
sensor = "accelerometer"
input_axis = "-y"
second_axis = "+z"
output = "increment"
output_scale = 9.80665
[channel.truth]
K0_ug = -35.0
K1 = 0.999
delta_o_urad = 12.5
[channel.noise]
velocity_random_walk_ug_rt_hz = 25.0

[[channel]]
name = "ay"
sensor = "accelerometer"
input_axis = "+x"
second_axis = "-z"
output = "rate"

[[channel]]
name = "az"
sensor = "accelerometer"
input_axis = "-x"
second_axis = "-y"
)";

TEST(ImuConfig, SixChannelsReadWithTheirAxesOutputsTruthAndNoise) {
  const Scenario s = parse_scenario(kSixChannels, "imu.toml");
  ASSERT_TRUE(s.is_imu());
  ASSERT_EQ(s.imu_channels.size(), 6u);
  const std::vector<std::string> names = {"gx", "gy", "gz", "ax", "ay", "az"};
  // Columns: the input axis, the second axis, input x second, in body axes (written out by hand).
  const std::vector<Eigen::Matrix3d> axes = {
      rows({{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}),    // I +x, O +y, S +z
      rows({{0, 0, 1}, {0, 1, 0}, {-1, 0, 0}}),   // I -z, O +y, S = -z x y = +x
      rows({{0, -1, 0}, {0, 0, -1}, {1, 0, 0}}),  // I +z, O -x, S = z x -x = -y
      rows({{0, 0, -1}, {-1, 0, 0}, {0, 1, 0}}),  // i -y, p +z, o = -y x z = -x
      rows({{1, 0, 0}, {0, 0, 1}, {0, -1, 0}}),   // i +x, p -z, o = x x -z = +y
      rows({{-1, 0, 0}, {0, -1, 0}, {0, 0, 1}}),  // i -x, p -y, o = -x x -y = +z
  };
  for (std::size_t k = 0; k < 6; ++k) {
    const SensorChannel& c = s.imu_channels[k];
    EXPECT_EQ(c.name, names[k]);
    EXPECT_EQ(c.axes, axes[k]) << c.name << ":\n" << c.axes;
    // A proper rotation: the sensor's axes are right-handed as the body's.
    const Eigen::Matrix3d gram = c.axes.transpose() * c.axes;
    EXPECT_TRUE(gram == Eigen::Matrix3d::Identity()) << c.name;
    EXPECT_EQ(c.axes.determinant(), 1.0) << c.name;
    EXPECT_EQ(kind_of(c.sensor), k < 3 ? SensorKind::kGyro : SensorKind::kAccelerometer) << c.name;
    EXPECT_EQ(c.output.quantity, k < 3 ? OutputQuantity::kRate : OutputQuantity::kSpecificForce) << c.name;
    EXPECT_EQ(c.output.offset, 0.0);
  }
  // Outputs: the column is the name unless `column` says; rate unless `output` says; scale 1 unless given.
  const auto& ch = s.imu_channels;
  EXPECT_EQ(ch[0].output.column, "gx");
  EXPECT_EQ(ch[0].output.form, OutputForm::kIncrement);
  EXPECT_TRUE(same_bits(ch[0].output.scale, 4.84813681109536e-6));
  EXPECT_EQ(ch[0].output.unit_name, "rad/s");
  EXPECT_EQ(ch[1].output.column, "GYRO_Y");
  EXPECT_EQ(ch[1].output.form, OutputForm::kRate);
  EXPECT_EQ(ch[1].output.scale, -2.0);
  EXPECT_EQ(ch[1].output.unit_name, "");
  EXPECT_EQ(ch[2].output.column, "gz");
  EXPECT_EQ(ch[2].output.scale, 1.0);
  EXPECT_EQ(ch[3].output.form, OutputForm::kIncrement);
  EXPECT_TRUE(same_bits(ch[3].output.scale, 9.80665));
  EXPECT_EQ(ch[4].output.form, OutputForm::kRate);
  EXPECT_EQ(ch[5].output.scale, 1.0);

  // Truth and noise: the keys given, and the lone sensor's defaults for the rest (docs/contract.md: [gyro]
  // dI = 0.5 deg/h/g and 0.002 deg/sqrt(h); [accelerometer] K2 = 15 ug/g^2 and 10 ug/sqrt(Hz)).
  const Gyro& gx = std::get<Gyro>(ch[0].sensor);
  EXPECT_EQ(gx.drift[Coefficient::dF], 2.5);
  EXPECT_EQ(gx.drift[Coefficient::dIO], -0.125);
  EXPECT_EQ(gx.drift[Coefficient::dI], 0.5);
  EXPECT_EQ(gx.rate.scale_factor_error_ppm, 40.0);
  EXPECT_EQ(gx.rate.input_axis_misalignment_O_arcsec, 3.0);
  EXPECT_EQ(gx.rate.input_axis_misalignment_S_arcsec, -4.0);
  EXPECT_EQ(gx.noise.angle_random_walk_deg_rt_h, 0.003);
  // [calibration] gyro_model is every gyro channel's.
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(std::get<Gyro>(ch[k].sensor).model, GyroModel::kDriftRate);
  const Gyro& gy = std::get<Gyro>(ch[1].sensor);
  EXPECT_EQ(gy.drift[Coefficient::dF], 1.0);
  EXPECT_EQ(gy.drift[Coefficient::dOS], -0.015);
  EXPECT_EQ(gy.rate.scale_factor_error_ppm, 0.0);
  EXPECT_EQ(gy.noise.angle_random_walk_deg_rt_h, 0.002);
  const Accelerometer& ax = std::get<Accelerometer>(ch[3].sensor);
  EXPECT_EQ(ax.coefficients[AccelCoefficient::K0], -35.0);
  EXPECT_EQ(ax.coefficients[AccelCoefficient::K1], 0.999);
  EXPECT_EQ(ax.coefficients[AccelCoefficient::delta_o], 12.5);
  EXPECT_EQ(ax.coefficients[AccelCoefficient::K2], 15.0);
  EXPECT_EQ(ax.noise.velocity_random_walk_ug_rt_hz, 25.0);
  EXPECT_EQ(ax.noise.bias_instability_ug, 0.0);
  const Accelerometer& ay = std::get<Accelerometer>(ch[4].sensor);
  EXPECT_EQ(ay.coefficients[AccelCoefficient::K1], 1.0);
  EXPECT_EQ(ay.noise.velocity_random_walk_ug_rt_hz, 10.0);

  // The unit's channels are these, and its record is read with one output column per channel, in order.
  EXPECT_EQ(s.channels().size(), 6u);
  const std::optional<RecordLayout> layout = s.reading_layout();
  ASSERT_TRUE(layout.has_value());
  ASSERT_EQ(layout->outputs.size(), 6u);
  for (std::size_t k = 0; k < 6; ++k) EXPECT_EQ(layout->outputs[k], ch[k].output);
  EXPECT_EQ(layout->time_column, "time_s");
}

TEST(ImuConfig, ARecordLackingAChannelsColumnIsRefusedNamingIt) {
  // Rate outputs, so that the reader's own handling of increments plays no part.
  const Scenario s = parse_scenario(R"([sensor]
kind = "imu"
[[channel]]
name = "gx"
sensor = "gyro"
input_axis = "+x"
second_axis = "+y"
[[channel]]
name = "ax"
sensor = "accelerometer"
input_axis = "+x"
second_axis = "+y"
column = "accel_x_g"
)",
                                    "imu.toml");
  const std::string rows_text = "0.0,0,0,0,1.5,0.25\n0.005,1,0,0,1.5,0.25\n";
  const std::string complete = "time_s,main_angle_deg,counter_angle_deg,position_angle_deg,gx,accel_x_g\n";
  EXPECT_NO_THROW(RecordReader::from_string(complete + rows_text, s.reading_layout(), "imu.csv"));
  const std::string lacking = "time_s,main_angle_deg,counter_angle_deg,position_angle_deg,gx,ax\n";
  try {
    RecordReader::from_string(lacking + rows_text, s.reading_layout(), "imu.csv");
    FAIL() << "a record without accel_x_g was read";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("imu.csv"), std::string::npos) << message;
    EXPECT_NE(message.find("accel_x_g"), std::string::npos) << message;
  }
}

// ---- the default IMU ----------------------------------------------------------------------------------

TEST(ImuConfig, DefaultImuIsTheUsualTriadWrittenAsIncrements) {
  const Scenario s = default_imu_scenario();
  ASSERT_EQ(s.imu_channels.size(), 6u);
  const std::vector<std::string> names = {"gx", "gy", "gz", "ax", "ay", "az"};
  // gx: I +x, O +y; gy: I +y, O +z; gz: I +z, O +x (S = I x O), and the accelerometers alike.
  const std::vector<Eigen::Matrix3d> axes = {
      rows({{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}),
      rows({{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}),
      rows({{0, 1, 0}, {0, 0, 1}, {1, 0, 0}}),
  };
  // 1 deg/h in rad/s, from pi (not from the library's constants); the standard gravity in m/s^2.
  const double rad_s_per_deg_h = std::numbers::pi / 180.0 / 3600.0;
  for (std::size_t k = 0; k < 6; ++k) {
    const SensorChannel& c = s.imu_channels[k];
    const bool gyro = k < 3;
    EXPECT_EQ(c.name, names[k]);
    EXPECT_EQ(c.output.column, names[k]);
    EXPECT_EQ(c.axes, axes[k % 3]) << c.name;
    EXPECT_EQ(kind_of(c.sensor), gyro ? SensorKind::kGyro : SensorKind::kAccelerometer);
    EXPECT_EQ(c.output.form, OutputForm::kIncrement) << c.name;
    if (gyro)
      EXPECT_NEAR(c.output.scale, rad_s_per_deg_h, 1e-15 * rad_s_per_deg_h) << c.name;
    else
      EXPECT_EQ(c.output.scale, 9.80665) << c.name;
    if (gyro) {
      const Gyro& g = std::get<Gyro>(c.sensor);
      EXPECT_EQ(g.noise.angle_random_walk_deg_rt_h, 0.003);
      // A few deg/h at most: a navigation-grade gyro's drift terms.
      for (double v : g.drift.values) EXPECT_LE(std::abs(v), 3.0) << c.name;
      EXPECT_EQ(g.model, s.gyro_model);
    } else {
      const Accelerometer& a = std::get<Accelerometer>(c.sensor);
      EXPECT_EQ(a.noise.velocity_random_walk_ug_rt_hz, 10.0);
      EXPECT_NEAR(a.coefficients[AccelCoefficient::K1], 1.0, 1e-3) << c.name;
    }
  }
  // Each channel its own truth: a channel read from another's column is then seen.
  for (std::size_t a = 0; a < 6; ++a) {
    for (std::size_t b = a + 1; b < 6; ++b) {
      const Sensor &sa = s.imu_channels[a].sensor, &sb = s.imu_channels[b].sensor;
      if (kind_of(sa) != kind_of(sb)) continue;
      if (kind_of(sa) == SensorKind::kGyro)
        EXPECT_NE(std::get<Gyro>(sa).drift.values, std::get<Gyro>(sb).drift.values) << a << " " << b;
      else
        EXPECT_NE(std::get<Accelerometer>(sa).coefficients.values,
                  std::get<Accelerometer>(sb).coefficients.values);
    }
  }
  // The default accelerometer's test (static + 6 + 12 rad/s, four beta, eight gamma), estimating the radius.
  EXPECT_EQ(s.test.rates_rad_s, (std::vector<double>{0.0, 6.0, 12.0}));
  EXPECT_EQ(s.test.beta_rad.size(), 4u);
  EXPECT_EQ(s.test.gamma_rad.size(), 8u);
  EXPECT_EQ(s.estimate, (std::vector<std::string>{"radius_error", "radius_stretch"}));
  // The demo's arm: 20 um long, stretching 1e-7 m/(rad/s)^2, known to 5 um and 20 %.
  const Scenario demo = demo_imu_scenario();
  EXPECT_EQ(demo.errors.radius_error_m, 20e-6);
  EXPECT_EQ(demo.errors.radius_stretch_m_per_rad2_s2, 1e-7);
  EXPECT_EQ(demo.uncertainty.radius_error_m, 5e-6);
  EXPECT_EQ(demo.uncertainty.radius_stretch_m_per_rad2_s2, 2e-8);
  EXPECT_EQ(demo.imu_channels.size(), 6u);
}

/// Every field of two IMU scenarios' channels, bit for bit.
void expect_same_channels(const Scenario& a, const Scenario& b) {
  ASSERT_EQ(a.imu_channels.size(), b.imu_channels.size());
  for (std::size_t k = 0; k < a.imu_channels.size(); ++k) {
    const SensorChannel &x = a.imu_channels[k], &y = b.imu_channels[k];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.axes, y.axes) << x.name;
    EXPECT_EQ(x.output, y.output) << x.name;
    ASSERT_EQ(kind_of(x.sensor), kind_of(y.sensor)) << x.name;
    if (const Gyro* g = std::get_if<Gyro>(&x.sensor)) {
      const Gyro& h = std::get<Gyro>(y.sensor);
      for (std::size_t i = 0; i < kNumGyroCoefficients; ++i)
        EXPECT_TRUE(same_bits(g->drift.values[i], h.drift.values[i])) << x.name << " " << i;
      EXPECT_TRUE(same_bits(g->rate.scale_factor_error_ppm, h.rate.scale_factor_error_ppm));
      EXPECT_TRUE(
          same_bits(g->rate.input_axis_misalignment_O_arcsec, h.rate.input_axis_misalignment_O_arcsec));
      EXPECT_TRUE(
          same_bits(g->rate.input_axis_misalignment_S_arcsec, h.rate.input_axis_misalignment_S_arcsec));
      EXPECT_TRUE(same_bits(g->noise.angle_random_walk_deg_rt_h, h.noise.angle_random_walk_deg_rt_h));
      EXPECT_TRUE(same_bits(g->noise.bias_instability_deg_h, h.noise.bias_instability_deg_h));
      EXPECT_TRUE(same_bits(g->noise.rate_random_walk_deg_h_rt_h, h.noise.rate_random_walk_deg_h_rt_h));
      EXPECT_TRUE(same_bits(g->noise.quantization_deg_h, h.noise.quantization_deg_h));
      EXPECT_TRUE(same_bits(g->noise.output_lag_s, h.noise.output_lag_s));
      EXPECT_EQ(g->model, h.model);
    } else {
      const Accelerometer& p = std::get<Accelerometer>(x.sensor);
      const Accelerometer& q = std::get<Accelerometer>(y.sensor);
      for (std::size_t i = 0; i < kNumAccelCoefficients; ++i)
        EXPECT_TRUE(same_bits(p.coefficients.values[i], q.coefficients.values[i])) << x.name << " " << i;
      EXPECT_TRUE(same_bits(p.noise.velocity_random_walk_ug_rt_hz, q.noise.velocity_random_walk_ug_rt_hz));
      EXPECT_TRUE(same_bits(p.noise.bias_instability_ug, q.noise.bias_instability_ug));
      EXPECT_TRUE(same_bits(p.noise.quantization_ug, q.noise.quantization_ug));
    }
  }
}

TEST(ImuConfig, DefaultAndDemoImuRoundTripThroughTheWriter) {
  for (const Scenario& s : {default_imu_scenario(), demo_imu_scenario()}) {
    const std::string text = scenario_to_toml(s);
    const Scenario back = parse_scenario(text, "imu-init.toml");
    ASSERT_TRUE(back.is_imu());
    expect_same_channels(back, s);
    EXPECT_EQ(back.estimate, s.estimate);
    EXPECT_EQ(back.test.rates_rad_s, s.test.rates_rad_s);
    EXPECT_EQ(back.test.revolutions, s.test.revolutions);
    EXPECT_EQ(back.test.static_hold_s, s.test.static_hold_s);
    EXPECT_EQ(back.errors.radius_error_m, s.errors.radius_error_m);
    EXPECT_EQ(back.uncertainty.radius_error_m, s.uncertainty.radius_error_m);
    EXPECT_EQ(back.reading_layout(), s.reading_layout());
    // Everything else too: the file it writes again is the same, character for character.
    EXPECT_EQ(scenario_to_toml(back), text);
    // An IMU's file holds no lone sensor's section.
    EXPECT_EQ(text.find("\n[gyro]"), std::string::npos);
    EXPECT_EQ(text.find("\n[accelerometer]"), std::string::npos);
    EXPECT_NE(text.find("[[channel]]"), std::string::npos);
  }
  // A channel of its own column and of rates, read back as it was.
  Scenario s = parse_scenario(kSixChannels, "imu.toml");
  expect_same_channels(parse_scenario(scenario_to_toml(s), "again.toml"), s);
}

TEST(ImuConfig, AChannelOnAxesNoFileCanStateIsNotWritten) {
  Scenario s = default_imu_scenario();
  s.imu_channels[2].axes = Eigen::Matrix3d::Identity() * -1.0;  // left-handed
  try {
    scenario_to_toml(s);
    FAIL() << "written";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("channel gz"), std::string::npos) << e.what();
  }
}

TEST(ImuConfig, InitWritesTheDefaultImu) {
  const std::filesystem::path dir = fresh_test_folder("imu-init");
  const CliOutcome o = run_cli("init --sensor imu " + (dir / "imu.toml").string(), dir);
  ASSERT_EQ(o.status, 0) << o.err;
  const Scenario s = load_scenario(dir / "imu.toml");
  expect_same_channels(s, default_imu_scenario());
  EXPECT_EQ(s.estimate, default_imu_scenario().estimate);
  // Commented: every channel key says what it is.
  const std::string text = test::slurp(dir / "imu.toml");
  EXPECT_NE(text.find("kind = \"imu\""), std::string::npos);
  EXPECT_NE(text.find("output = \"increment\""), std::string::npos);
  EXPECT_NE(text.find("output_unit = \"rad/s\""), std::string::npos);
  EXPECT_NE(text.find("output_unit = \"m/s^2\""), std::string::npos);
  std::filesystem::remove_all(dir);
}

// ---- refusals -------------------------------------------------------------------------------------------

constexpr const char* kImu = "[sensor]\nkind = \"imu\"\n";  // lines 1-2

/// A channel table of a gyro (or an accelerometer) on +x/+y with `extra` lines after its keys.
std::string channel(const std::string& name, const std::string& sensor = "gyro",
                    const std::string& extra = "") {
  return "[[channel]]\nname = \"" + name + "\"\nsensor = \"" + sensor +
         "\"\ninput_axis = \"+x\"\nsecond_axis = \"+y\"\n" + extra;
}

TEST(ImuConfig, AChannelWithoutNameOrSensorOrAxisIsRefused) {
  // Lines 3-7: gx; line 8: the second [[channel]].
  expect_refused(std::string(kImu) + channel("gx") + "[[channel]]\nsensor = \"gyro\"\n",
                 {"imu.toml, line 8:", "channel[1] has no name"});
  expect_refused(
      std::string(kImu) + "[[channel]]\nname = \"gx\"\ninput_axis = \"+x\"\nsecond_axis = \"+y\"\n",
      {"imu.toml, line 3:", "channel[0] (\"gx\") has no sensor", "\"gyro\" or \"accelerometer\""});
  expect_refused(std::string(kImu) + "[[channel]]\nname = \"gx\"\nsensor = \"gyro\"\nsecond_axis = \"+y\"\n",
                 {"line 3:", "has no input_axis"});
  expect_refused(std::string(kImu) + "[[channel]]\nname = \"gx\"\nsensor = \"gyro\"\ninput_axis = \"+x\"\n",
                 {"line 3:", "has no second_axis"});
  expect_refused(
      std::string(kImu) + "[[channel]]\nname = \"gx\"\nsensor = \"magnetometer\"\n",
      {"line 5:", "channel[0].sensor must be \"gyro\" or \"accelerometer\", not \"magnetometer\""});
  expect_refused(std::string(kImu) + channel(""), {"line 4:", "channel[0].name is empty"});
  expect_refused(std::string(kImu) + channel("g x"),
                 {"line 4:", "channel[0].name = \"g x\"", "letters, digits"});
  expect_refused(
      std::string(kImu) + channel(std::string(limits::kChannelNameBytes + 1, 'g')),
      {"line 4:", "at most " + std::to_string(limits::kChannelNameBytes), "limits::kChannelNameBytes"});
}

TEST(ImuConfig, TwoChannelsOfOneNameOrOneColumnAreRefused) {
  // gx on lines 3-7, the second channel's name on line 9.
  expect_refused(std::string(kImu) + channel("gx") + channel("gx", "accelerometer"),
                 {"imu.toml, line 9:", "channel[1].name = \"gx\" repeats channel[0].name (line 4)"});
  expect_refused(std::string(kImu) + channel("gx") + channel("ax", "accelerometer", "column = \"gx\"\n"),
                 {"imu.toml, line 13:", "channel[1].column = \"gx\" is also channel[0]'s column (line 4)"});
  // A column that is also the time column.
  expect_refused(std::string(kImu) + channel("gx", "gyro", "column = \"time_s\"\n"),
                 {"imu.toml, line 8:", "channel[0].column", "time_s"});
}

TEST(ImuConfig, AxesMustBeBodyAxesAndTheSecondPerpendicularToTheInput) {
  const auto axes = [](const std::string& input, const std::string& second) {
    return std::string(kImu) + "[[channel]]\nname = \"gx\"\nsensor = \"gyro\"\ninput_axis = \"" + input +
           "\"\nsecond_axis = \"" + second + "\"\n";
  };
  expect_refused(
      axes("+x", "+x"),
      {"imu.toml, line 7:", "channel[0].second_axis = \"+x\" is the same axis as channel[0].input_axis",
       "perpendicular"});
  expect_refused(
      axes("+y", "-y"),
      {"imu.toml, line 7:", "channel[0].second_axis = \"-y\" is opposite to channel[0].input_axis = \"+y\""});
  expect_refused(
      axes("x", "+y"),
      {"imu.toml, line 6:", "channel[0].input_axis must be one of +x, -x, +y, -y, +z, -z", "not \"x\""});
  expect_refused(axes("+x", "+w"),
                 {"imu.toml, line 7:", "channel[0].second_axis must be one of", "not \"+w\""});
}

TEST(ImuConfig, TheOtherSensorsKeyInAChannelIsRefused) {
  expect_refused(
      std::string(kImu) + channel("ax", "accelerometer", "[channel.truth]\nK0_ug = 1.0\ndF = 0.5\n"),
      {"imu.toml, line 10:", "channel[0].truth.dF is a gyro's key", "channel[0] (\"ax\") is an accelerometer",
       "[accelerometer]"});
  expect_refused(std::string(kImu) + channel("gx", "gyro", "[channel.truth]\nK1 = 1.0\n"),
                 {"imu.toml, line 9:", "channel[0].truth.K1 is an accelerometer's key", "is a gyro"});
  expect_refused(std::string(kImu) +
                     channel("ax", "accelerometer", "[channel.noise]\nangle_random_walk_deg_rt_h = 0.1\n"),
                 {"imu.toml, line 9:", "channel[0].noise.angle_random_walk_deg_rt_h is a gyro's key",
                  "[accelerometer.noise]"});
  expect_refused(
      std::string(kImu) + channel("gx", "gyro", "[channel.noise]\nvelocity_random_walk_ug_rt_hz = 1\n"),
      {"imu.toml, line 9:", "channel[0].noise.velocity_random_walk_ug_rt_hz is an accelerometer's key"});
  // An unknown key in the truth, in the noise and in the channel itself.
  expect_refused(std::string(kImu) + channel("gx", "gyro", "[channel.truth]\ndX = 1.0\n"),
                 {"imu.toml, line 9:", "unknown key channel[0].truth.dX"});
  expect_refused(std::string(kImu) + channel("gx", "gyro", "input = \"+x\"\n"),
                 {"imu.toml, line 8:", "unknown key channel[0].input", "input_axis"});
  // A value out of range is refused as in [gyro] and [accelerometer], with the channel's key.
  expect_refused(std::string(kImu) + channel("ax", "accelerometer", "[channel.truth]\nK1 = 0\n"),
                 {"imu.toml, line 9:", "channel[0].truth.K1 must be a non-zero scale factor"});
  expect_refused(
      std::string(kImu) + channel("gx", "gyro", "[channel.noise]\nangle_random_walk_deg_rt_h = -1\n"),
      {"imu.toml, line 9:", "channel[0].noise.angle_random_walk_deg_rt_h must be"});
}

TEST(ImuConfig, OutputScaleAndFormAreChecked) {
  expect_refused(
      std::string(kImu) + channel("gx", "gyro", "output_scale = 0\n"),
      {"imu.toml, line 8:", "channel[0].output_scale must be a finite non-zero number", "per deg/h"});
  expect_refused(std::string(kImu) + channel("ax", "accelerometer", "output_scale = 0.0\n"),
                 {"imu.toml, line 8:", "channel[0].output_scale", "per g"});
  expect_refused(std::string(kImu) + channel("gx", "gyro", "output_scale = inf\n"),
                 {"imu.toml, line 8:", "channel[0].output_scale must be a finite number, not inf"});
  expect_refused(std::string(kImu) + channel("gx", "gyro", "output_scale = nan\n"),
                 {"imu.toml, line 8:", "channel[0].output_scale must be a finite number"});
  expect_refused(
      std::string(kImu) + channel("gx", "gyro", "output = \"integral\"\n"),
      {"imu.toml, line 8:", "channel[0].output must be \"rate\"", "\"increment\"", "not \"integral\""});
  expect_refused(std::string(kImu) + channel("gx", "gyro", "output_unit = \"deg per hour\"\n"),
                 {"imu.toml, line 8:", "channel[0].output_unit"});
}

TEST(ImuConfig, TheKindAndTheChannelsGoTogether) {
  expect_refused(std::string(kImu),
                 {"imu.toml, line 2:", "sensor.kind = \"imu\" needs one [[channel]]", "none"});
  expect_refused("channel = []\n" + std::string(kImu), {"imu.toml, line 1:", "channel holds no channel"});
  expect_refused(std::string(kImu) + "[channel]\nname = \"gx\"\n",
                 {"imu.toml, line 3:", "channel must be an array of tables"});
  // [[channel]] without kind = "imu": a gyro's file, and an accelerometer's.
  expect_refused(channel("gx"), {"imu.toml, line 1:", "channel ([[channel]]) describes an IMU's channel",
                                 "sensor.kind is \"gyro\"", "kind = \"imu\""});
  expect_refused("[sensor]\nkind = \"accelerometer\"\n" + channel("ax", "accelerometer"),
                 {"imu.toml, line 3:", "sensor.kind is \"accelerometer\""});
  // An unknown kind names the three.
  expect_refused("[sensor]\nkind = \"imus\"\n", {"line 2:", "\"gyro\", \"accelerometer\" or \"imu\""});
}

TEST(ImuConfig, MoreChannelsThanTheLimitAreRefused) {
  std::string text = kImu;
  for (std::size_t k = 0; k < limits::kMaxImuChannels; ++k) text += channel("c" + std::to_string(k));
  EXPECT_EQ(refusal(text), "");  // the limit itself is accepted
  text += channel("extra");      // its header on line 3 + 5 * kMaxImuChannels
  expect_refused(text, {"imu.toml, line " + std::to_string(3 + 5 * limits::kMaxImuChannels) + ":",
                        "channel holds " + std::to_string(limits::kMaxImuChannels + 1) + " channels",
                        "at most " + std::to_string(limits::kMaxImuChannels), "limits::kMaxImuChannels"});
}

TEST(ImuConfig, ALoneSensorsSectionsAreRefusedInAnImu) {
  expect_refused(
      std::string(kImu) + channel("gx") + "[gyro]\ndF = 1.0\n",
      {"imu.toml, line 9:", "gyro.dF is a lone sensor's key, but sensor.kind is \"imu\"", "[channel.truth]"});
  expect_refused(std::string(kImu) + channel("gx") + "[accelerometer.noise]\nquantization_ug = 1.0\n",
                 {"imu.toml, line 9:", "accelerometer.noise.quantization_ug is a lone sensor's key"});
  expect_refused(std::string(kImu) + channel("gx") + "[record]\ntime_unit = \"ms\"\noutput_column = \"w\"\n",
                 {"imu.toml, line 10:", "record.output_column describes a lone sensor's output column"});
  // [record]'s other keys serve an IMU's record as a lone sensor's.
  const Scenario s =
      parse_scenario(std::string(kImu) + channel("gx") + "[record]\ntime_unit = \"ms\"\n", "imu.toml");
  EXPECT_EQ(s.reading_layout()->time_unit, TimeUnit::kMilliseconds);
  EXPECT_EQ(s.reading_layout()->outputs.at(0).column, "gx");
}

// ---- the commands that do not serve an IMU yet ---------------------------------------------------------

TEST(ImuConfig, CommandsThatDoNotServeAnImuRefuseItInOneSentence) {
  const std::string expected_tail =
      " does not serve an IMU configuration yet ([sensor] kind = \"imu\"); docs/imu.md, \"What serves an "
      "IMU\", lists the commands that do.";
  try {
    refuse_imu(default_imu_scenario(), "inputs");
    FAIL() << "an IMU was served";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "inputs" + expected_tail);
  }
  EXPECT_NO_THROW(refuse_imu(default_scenario(), "inputs"));
  EXPECT_NO_THROW(refuse_imu(default_accelerometer_scenario(), "inputs"));

  const std::filesystem::path dir = fresh_test_folder("imu-unserved");
  const std::string config = (dir / "imu.toml").string();
  { std::ofstream(config) << scenario_to_toml(default_imu_scenario()); }
  const std::string json = (dir / "out.json").string();
  const std::vector<std::pair<std::string, std::string>> commands = {
      {"inputs", "inputs --beta-deg 0 --time-s 1 --config " + config + " --json " + json},
  };
  // (plan, sensitivity, noise and montecarlo --samples serve an IMU: tests/test_imu_cli.cpp,
  // test_imu_sensitivity.cpp, test_imu_noise.cpp, test_imu_montecarlo.cpp.)
  for (const auto& [command, args] : commands) {
    const CliOutcome o = run_cli(args, dir);
    EXPECT_EQ(o.status, 1) << command << ": " << o.err;
    EXPECT_EQ(o.err, "gyrocal: " + command + expected_tail + "\n") << command;
    EXPECT_FALSE(std::filesystem::exists(json)) << command;
  }
  // report draws an IMU's result (tests/test_imu_report.cpp); one that lacks what its page reads is refused
  // naming the key, and no page is written.
  const std::string result = (dir / "imu-result.json").string();
  { std::ofstream(result) << R"({"method": "least-squares", "channels": {"gx": {"sensor": "gyro"}}})"; }
  const std::string html = (dir / "r.html").string();
  const CliOutcome o = run_cli("report " + result + " --html " + html, dir);
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_NE(o.err.find("the IMU result's channels.gx.coefficients is missing"), std::string::npos) << o.err;
  EXPECT_FALSE(std::filesystem::exists(html));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace gyrocal
