// A record of several output columns (an IMU's channels, docs/records.md "Several output columns"): the
// reader gives every column in one pass through its own offset and scale, and the reducer reduces each
// column beside the others, with its own outlier rule and standard errors, exactly as it reduces that column
// alone.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/simulate/simulator.hpp"
#include "support/rig_record.hpp"

namespace gyrocal {
namespace {

/// A layout of three output columns after the time and the angles: a gyro's rate in mV (2 mV per deg/h,
/// offset 1 mV), an accelerometer's specific force in V (0.5 V per g) and a gyro's rate with its sign
/// inverted.
RecordLayout three_columns() {
  RecordLayout l;
  l.delimiter = ';';
  l.time_column = "t";
  l.main_angle_column = "main";
  l.counter_angle_column = "counter";
  l.position_angle_column = "pos";
  l.outputs = {
      OutputColumn{"gx", OutputQuantity::kRate, OutputForm::kRate, 2.0, 1.0, "mV"},
      OutputColumn{"ax", OutputQuantity::kSpecificForce, OutputForm::kRate, 0.5, 0.0, "V"},
      OutputColumn{"gz", OutputQuantity::kRate, OutputForm::kRate, -1.0, 0.0, ""},
  };
  return l;
}

std::string error_of(const RecordLayout& l) {
  std::string error;
  EXPECT_FALSE(l.IsValid(&error));
  return error;
}

TEST(OutputColumns, TheReaderGivesEveryColumnThroughItsOwnOffsetAndScale) {
  // The columns in another order than the layout's, with one the layout does not name.
  const std::string text =
      "t;gz;temp;ax;main;counter;pos;gx\n"
      "0.0;-3.5;21.0;0.25;0;0;0;9\n"
      "0.1;4;21.5;-1;1;2;3;-1\n";
  RecordReader reader = RecordReader::from_string(text, three_columns(), "imu.csv");
  EXPECT_EQ(reader.output_count(), 3u);
  EXPECT_EQ(reader.output_column(), "gx");
  RecordSample s;
  ASSERT_TRUE(reader.next(s));
  EXPECT_EQ(s.outputs[0], (9.0 - 1.0) / 2.0);  // deg/h
  EXPECT_EQ(s.outputs[1], 0.25 / 0.5);         // g
  EXPECT_EQ(s.outputs[2], 3.5);                // deg/h, the sign turned
  ASSERT_TRUE(reader.next(s));
  EXPECT_EQ(s.outputs[0], -1.0);
  EXPECT_EQ(s.outputs[1], -2.0);
  EXPECT_EQ(s.outputs[2], -4.0);
  EXPECT_EQ(s.position_angle_deg, 3.0);
  EXPECT_FALSE(reader.next(s));
}

TEST(OutputColumns, AColumnMissingFromTheHeaderIsRefusedNamingIt) {
  try {
    RecordReader::from_string("t;main;counter;pos;gx;gz\n0;0;0;0;1;1\n", three_columns(), "imu.csv");
    FAIL() << "no refusal";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("imu.csv, line 1"), std::string::npos) << m;
    EXPECT_NE(m.find("[[channel]] 2's column = 'ax' is not a column"), std::string::npos) << m;
  }
}

TEST(OutputColumns, AnOutputBeyondItsBoundIsRefusedNamingItsColumn) {
  try {
    RecordReader reader = RecordReader::from_string("t;main;counter;pos;gx;ax;gz\n0;0;0;0;1;1e300;1\n",
                                                    three_columns(), "imu.csv");
    RecordSample s;
    reader.next(s);
    FAIL() << "no refusal";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("imu.csv, line 2: column 6 (ax)"), std::string::npos) << m;
    EXPECT_NE(m.find("output_scale of [[channel]] 2"), std::string::npos) << m;
  }
}

TEST(OutputColumns, ALayoutThatCannotBeReadIsRefusedNamingTheColumn) {
  RecordLayout twice = three_columns();
  twice.outputs[2].column = "gx";
  EXPECT_NE(
      error_of(twice).find("record.outputs[0].column and record.outputs[2].column both name the column 'gx'"),
      std::string::npos)
      << error_of(twice);
  RecordLayout angle = three_columns();
  angle.outputs[1].column = "pos";
  EXPECT_NE(error_of(angle).find("both name the column 'pos'"), std::string::npos);
  RecordLayout zero = three_columns();
  zero.outputs[2].scale = 0.0;
  EXPECT_NE(error_of(zero).find("record.outputs[2].scale must be a finite non-zero number"),
            std::string::npos);
  RecordLayout many = three_columns();
  for (std::size_t i = 3; i <= limits::kMaxOutputColumns; ++i) {
    OutputColumn c;
    c.column = fmt::format("c{}", i);
    many.outputs.push_back(c);
  }
  EXPECT_NE(error_of(many).find("more than the 8 a record is read with at once"), std::string::npos)
      << error_of(many);
}

TEST(OutputColumns, OneSensorsLayoutIsOneColumnFromItsOutputKeys) {
  RecordLayout l;
  l.output_column = "a_mV";
  l.output_quantity = OutputQuantity::kSpecificForce;
  l.output_scale_per_g = 250.0;
  l.output_offset = -3.0;
  l.output_unit_name = "mV";
  const std::vector<OutputColumn> columns = l.output_columns();
  ASSERT_EQ(columns.size(), 1u);
  EXPECT_EQ(columns[0],
            (OutputColumn{"a_mV", OutputQuantity::kSpecificForce, OutputForm::kRate, 250.0, -3.0, "mV"}));
  EXPECT_EQ(columns[0].scale_key(), "output_scale_per_g");
  EXPECT_EQ(columns[0].column_unit(), "mV");
}

/// The default test at 50 Hz and 12 revolutions, simulated with noise.
std::vector<RecordSample> simulated_rows(const Scenario& s) {
  std::vector<RecordSample> rows;
  SimulationOptions so;
  so.seed = 11;
  simulate(s, so, [&](const RecordSample& x) { rows.push_back(x); });
  return rows;
}

Scenario small_test() {
  Scenario s = default_scenario();
  s.test.sample_rate_hz = 50.0;
  s.test.revolutions = 12;
  return s;
}

/// The rows' column `column` alone, reduced by a reducer of one output column.
Reduction reduce_alone(const Scenario& s, const std::vector<RecordSample>& rows, std::size_t column) {
  Reducer reducer(s.test, ReduceOptions{}, "alone", s.centrifuge.rate_rad_s);
  for (RecordSample x : rows) {
    x.outputs[0] = x.outputs[column];
    reducer.push(x);
  }
  return reducer.finish();
}

void expect_same_values(const DwellValues& a, const DwellValues& b) {
  EXPECT_EQ(a.value, b.value);
  EXPECT_EQ(a.std_err, b.std_err);
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.outlier_samples, b.outlier_samples);
  EXPECT_EQ(a.revolutions, b.revolutions);
  EXPECT_EQ(a.dof, b.dof);
}

TEST(OutputColumns, EachColumnIsReducedAsItIsAloneWithItsOwnOutliers) {
  const Scenario s = small_test();
  std::vector<RecordSample> rows = simulated_rows(s);
  // Column 1: -3 x column 0 + 7 (a sensor of another scale and bias: the reduction is linear and the outlier
  // rule scale-free, so its values are -3 v + 7 and its standard errors 3 se). Column 2: column 0 with a
  // spike every 101 rows (its own outliers).
  std::size_t spikes = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    rows[i].outputs[1] = -3.0 * rows[i].outputs[0] + 7.0;
    rows[i].outputs[2] = rows[i].outputs[0] + (i % 101 == 50 ? 1e4 : 0.0);
    spikes += i % 101 == 50;
  }
  Reducer reducer(s.test, ReduceOptions{}, "three", s.centrifuge.rate_rad_s);
  reducer.set_output_columns({"gx", "gy", "gz"});
  for (const RecordSample& x : rows) reducer.push(x);
  EXPECT_THROW(
      {
        Reducer one_only(s.test, ReduceOptions{}, "three", s.centrifuge.rate_rad_s);
        one_only.set_output_columns({"gx", "gy"});
        one_only.finish();
      },
      Error);
  const std::vector<Reduction> channels = reducer.finish_channels();
  ASSERT_EQ(channels.size(), 3u);
  for (std::size_t c = 0; c < 3; ++c) {
    SCOPED_TRACE(c);
    const Reduction alone = reduce_alone(s, rows, c);
    const Reduction& r = channels[c];
    ASSERT_EQ(r.dwells.size(), alone.dwells.size());
    ASSERT_EQ(r.positions.size(), alone.positions.size());
    for (std::size_t d = 0; d < r.dwells.size(); ++d)
      expect_same_values(r.dwells[d].output, alone.dwells[d].output);
    for (std::size_t p = 0; p < r.positions.size(); ++p) {
      EXPECT_EQ(r.positions[p].channel, static_cast<int>(c));
      EXPECT_EQ(r.positions[p].mean, alone.positions[p].mean);
      EXPECT_EQ(r.positions[p].std_err, alone.positions[p].std_err);
      EXPECT_EQ(r.positions[p].index, alone.positions[p].index);
    }
    EXPECT_EQ(r.outliers, alone.outliers);
    EXPECT_EQ(r.samples_used, alone.samples_used);
  }
  // Independently of the reducer's own route: the linear column.
  for (std::size_t p = 0; p < channels[0].positions.size(); ++p) {
    const ReducedPosition &a = channels[0].positions[p], &b = channels[1].positions[p];
    EXPECT_NEAR(b.mean, -3.0 * a.mean + 7.0, 1e-12 * (3.0 * std::abs(a.mean) + 7.0)) << p;
    EXPECT_NEAR(b.std_err, 3.0 * a.std_err, 1e-9 * a.std_err) << p;
  }
  EXPECT_EQ(channels[0].outliers, 0u);
  EXPECT_EQ(channels[1].outliers, 0u);
  // Every spike inside a dwell's measured part is found, in column 2 alone.
  EXPECT_GT(channels[2].outliers, spikes / 3);
  EXPECT_LE(channels[2].outliers, spikes);
}

TEST(OutputColumns, ARigsImperfectRecordKeepsEveryColumnOfEveryRow) {
  // Every imperfection a rig's record has (jitter, ms stamps, quantised encoders, a ripple, a gap, a clock
  // jump, an encoder glitch, spikes), with the rows that wait in the reducer's queues (a window replayed into
  // a run, rows held as a possible glitch, the guard before a dwell's end): each column of the several is
  // still reduced as it is alone.
  Scenario s = default_scenario();
  s.test.sample_rate_hz = 50.0;
  s.test.revolutions = 8;
  s.test.rates_rad_s = {9.9, 7.0};
  std::vector<testing::RigRow> rig;
  testing::rig_rows(s, testing::every_imperfection(), testing::RigMotion{}, 5,
                    [&](const testing::RigRow& r) { rig.push_back(r); });
  std::vector<RecordSample> rows = testing::as_samples(rig);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    rows[i].outputs[1] = 0.25 * rows[i].outputs[0] - 40.0;
    rows[i].outputs[2] = static_cast<double>(i % 13);  // a column of its own, unrelated to the others
  }
  Reducer reducer(s.test, ReduceOptions{}, "rig", s.centrifuge.rate_rad_s);
  reducer.set_output_columns({"a", "b", "c"});
  for (const RecordSample& x : rows) reducer.push(x);
  const std::vector<Reduction> channels = reducer.finish_channels();
  for (std::size_t c = 0; c < 3; ++c) {
    SCOPED_TRACE(c);
    const Reduction alone = reduce_alone(s, rows, c);
    ASSERT_EQ(channels[c].positions.size(), alone.positions.size());
    for (std::size_t p = 0; p < alone.positions.size(); ++p) {
      EXPECT_EQ(channels[c].positions[p].mean, alone.positions[p].mean) << p;
      EXPECT_EQ(channels[c].positions[p].std_err, alone.positions[p].std_err) << p;
    }
    EXPECT_EQ(channels[c].encoder_glitch_rows, alone.encoder_glitch_rows);
    EXPECT_EQ(channels[c].gaps, alone.gaps);
  }
  EXPECT_GT(channels[0].gaps, 0u);
  EXPECT_GT(channels[0].outliers, 0u);  // the spikes, in the columns that carry them
  EXPECT_EQ(channels[1].outliers, channels[0].outliers);
}

TEST(OutputColumns, ARecordOfSeveralColumnsIsReducedInOnePassThroughItsLayout) {
  const Scenario s = small_test();
  std::vector<RecordSample> rows = simulated_rows(s);
  RecordLayout l;
  l.outputs = {OutputColumn{"g1", OutputQuantity::kRate, OutputForm::kRate, 1.0, 0.0, ""},
               OutputColumn{"g2", OutputQuantity::kRate, OutputForm::kRate, 1.0, 0.0, ""}};
  std::string text = "time_s,main_angle_deg,counter_angle_deg,position_angle_deg,g2,g1\n";
  for (RecordSample& x : rows) {
    x.outputs[1] = 0.5 * x.outputs[0] - 2.0;
    text += fmt::format("{},{},{},{},{},{}\n", x.time_s, x.main_angle_deg, x.counter_angle_deg,
                        x.position_angle_deg, x.outputs[1], x.outputs[0]);
  }
  RecordReader reader = RecordReader::from_string(text, l, "two.csv");
  const std::vector<Reduction> channels =
      reduce_record_channels(reader, s.test, ReduceOptions{}, s.centrifuge.rate_rad_s);
  ASSERT_EQ(channels.size(), 2u);
  for (std::size_t c = 0; c < 2; ++c) {
    const Reduction alone = reduce_alone(s, rows, c);
    ASSERT_EQ(channels[c].positions.size(), alone.positions.size());
    for (std::size_t p = 0; p < alone.positions.size(); ++p) {
      EXPECT_EQ(channels[c].positions[p].mean, alone.positions[p].mean) << c << " " << p;
      EXPECT_EQ(channels[c].positions[p].std_err, alone.positions[p].std_err) << c << " " << p;
    }
  }
  // reduce_record is for one column.
  RecordReader again = RecordReader::from_string(text, l, "two.csv");
  EXPECT_THROW(reduce_record(again, s.test, ReduceOptions{}, s.centrifuge.rate_rad_s), Error);
}

}  // namespace
}  // namespace gyrocal
