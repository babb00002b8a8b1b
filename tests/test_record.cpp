// The record format (docs/contract.md, "Record (CSV)") and the atomic output file.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "gyrocal/core/atomic_file.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/record/record.hpp"

namespace gyrocal {
namespace {

namespace fs = std::filesystem;

constexpr const char* kHeader = "time_s,main_angle_deg,counter_angle_deg,position_angle_deg,gyro_deg_h";

/// A double drawn over the whole range of magnitudes: tiny, huge, subnormal, either sign.
double random_double(std::mt19937_64& random) {
  using limits = std::numeric_limits<double>;
  static const double special[] = {limits::denorm_min(),
                                   -limits::denorm_min(),
                                   limits::max(),
                                   limits::lowest(),
                                   limits::min(),
                                   -0.0,
                                   0.1,
                                   1.0 / 3.0};
  std::uniform_int_distribution<int> kind(0, 9);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  switch (kind(random)) {
    case 3:
      return special[random() % std::size(special)];
    case 0:
      return unit(random) * std::numeric_limits<double>::denorm_min() * 1e6;  // subnormal
    case 1:
      return unit(random) * std::numeric_limits<double>::max();
    case 2:
      return unit(random) * 1e-300;
    default: {
      // Any finite bit pattern.
      for (;;) {
        const double value = std::bit_cast<double>(random());
        if (std::isfinite(value)) return value;
      }
    }
  }
}

std::vector<RecordSample> read_all(RecordReader& reader) {
  std::vector<RecordSample> samples;
  RecordSample sample;
  while (reader.next(sample)) samples.push_back(sample);
  return samples;
}

/// The message of the gyrocal::Error that reading `text` throws, or "" if it reads.
std::string read_error(const std::string& text, std::size_t chunk_bytes = RecordReader::kDefaultChunkBytes) {
  try {
    RecordReader reader = RecordReader::from_string(text, "bad.csv", chunk_bytes);
    read_all(reader);
  } catch (const Error& error) {
    return error.what();
  }
  return "";
}

std::string valid_record(int rows) {
  std::string text = std::string(kRecordMagic) + "\n# rig = A\n" + kHeader + "\n";
  for (int i = 0; i < rows; ++i) text += std::to_string(i) + ",1,2,3,4.5\n";
  return text;
}

TEST(Record, RoundTripIsBitForBit) {
  std::mt19937_64 random(42);
  std::vector<RecordSample> written;
  std::ostringstream out;
  {
    RecordWriter writer(out, {}, {"temperature_c", "pressure_pa"});
    // Times over the whole range, strictly increasing.
    std::vector<double> times(20000);
    for (double& time_s : times) time_s = random_double(random);
    times.push_back(-0.0);
    std::sort(times.begin(), times.end());
    times.erase(std::unique(times.begin(), times.end()), times.end());
    for (const double time_s : times) {
      RecordSample sample;
      sample.time_s = time_s;
      sample.main_angle_deg = random_double(random);
      sample.counter_angle_deg = random_double(random);
      sample.position_angle_deg = random_double(random);
      // The output within its bound (limits::kOutputMagnitude; beyond it the reader refuses the row, as
      // test_numeric_bounds checks), over the whole range of magnitudes below it.
      do {
        sample.outputs[0] = random_double(random);
      } while (!(std::abs(sample.outputs[0]) <= limits::kOutputMagnitude));
      sample.extra[0] = random_double(random);
      sample.extra[1] = random_double(random);
      writer.write(sample);
      written.push_back(sample);
    }
    writer.finish();
  }
  RecordReader reader = RecordReader::from_string(out.str());
  const std::vector<RecordSample> read = read_all(reader);
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    const RecordSample& a = written[i];
    const RecordSample& b = read[i];
    const double pairs[][2] = {{a.time_s, b.time_s},
                               {a.main_angle_deg, b.main_angle_deg},
                               {a.counter_angle_deg, b.counter_angle_deg},
                               {a.position_angle_deg, b.position_angle_deg},
                               {a.outputs[0], b.outputs[0]},
                               {a.extra[0], b.extra[0]},
                               {a.extra[1], b.extra[1]}};
    for (const auto& pair : pairs) {
      ASSERT_EQ(std::bit_cast<std::uint64_t>(pair[0]), std::bit_cast<std::uint64_t>(pair[1]))
          << "row " << i << ": " << pair[0] << " read back as " << pair[1];
    }
  }
}

TEST(Record, MetadataAndExtraColumnsPassThrough) {
  const RecordMetadata metadata = {{"rig", "centrifuge 2"}, {"gyro_serial", "X-17"}, {"note", "a = b"}};
  std::ostringstream first;
  {
    RecordWriter writer(first, metadata, {"temperature_c"});
    RecordSample sample;
    sample.extra[0] = 21.5;
    writer.write(sample);
    sample.time_s = 0.005;
    sample.extra[0] = 21.25;
    writer.write(sample);
    writer.finish();
  }
  // Copy reader -> writer, then compare texts: nothing is lost or changed.
  RecordReader reader = RecordReader::from_string(first.str());
  EXPECT_EQ(reader.metadata(), metadata);
  EXPECT_EQ(reader.extra_column_count(), 1u);
  EXPECT_EQ(reader.columns().back(), "temperature_c");
  std::ostringstream second;
  {
    RecordWriter writer(second, reader.metadata(),
                        {reader.columns().begin() + kRecordColumns.size(), reader.columns().end()});
    RecordSample sample;
    while (reader.next(sample)) writer.write(sample);
    writer.finish();
  }
  EXPECT_EQ(second.str(), first.str());
  EXPECT_NE(first.str().find("# rig = centrifuge 2\n"), std::string::npos);
  EXPECT_NE(first.str().find(",21.25\n"), std::string::npos);
}

TEST(Record, AcceptsCrlfBlankLinesCommentsSpacesAndAMissingFinalNewline) {
  const std::string text =
      "# gyrocal-record 1\r\n# a comment without equals sign\r\n#  key =  value \r\n\r\n" +
      std::string(kHeader) + ", temperature_c\r\n0, 1 ,2,3,4,20\r\n\r\n  \r\n1e-3,1,2,3,4,20";
  RecordReader reader = RecordReader::from_string(text);
  EXPECT_EQ(reader.metadata(), (RecordMetadata{{"key", "value"}}));
  EXPECT_EQ(reader.line_number(), 5u);
  const std::vector<RecordSample> samples = read_all(reader);
  ASSERT_EQ(samples.size(), 2u);
  EXPECT_EQ(samples[0].main_angle_deg, 1.0);
  EXPECT_EQ(samples[1].time_s, 1e-3);
  EXPECT_EQ(samples[1].extra[0], 20.0);
  EXPECT_EQ(reader.line_number(), 9u);
}

TEST(Record, HeaderWithoutRowsIsAnEmptyRecord) {
  RecordReader reader = RecordReader::from_string(std::string(kRecordMagic) + "\n" + kHeader + "\n");
  RecordSample sample;
  EXPECT_FALSE(reader.next(sample));
}

struct BadRecord {
  const char* what;
  std::string text;
  std::string expected;  ///< a part of the message
};

TEST(Record, BadRecordsAreRefusedWithTheirLine) {
  const std::string magic = std::string(kRecordMagic) + "\n";
  const std::string head = magic + "# rig = A\n" + kHeader + "\n";  // rows start on line 4
  const std::vector<BadRecord> cases = {
      {"empty file", "", "bad.csv is empty"},
      {"not a record", "time_s,gyro\n1,2\n", "bad.csv, line 1: this is not a gyrocal record"},
      {"other version", "# gyrocal-record 2\n", "line 1: record format version '2' is not supported"},
      {"no header", magic + "# a = b\n", "line 2: the record ends without a header line"},
      {"header missing", magic + "0,1,2,3,4\n", "line 2: the header line is missing"},
      {"wrong column", magic + "time_s,main_angle_deg,counter_angle_deg,beta_deg,gyro_deg_h\n",
       "line 2: the header must begin with time_s,main_angle_deg,counter_angle_deg,position_angle_deg,"
       "gyro_deg_h, but column 4 is 'beta_deg'"},
      {"short header", magic + "time_s,main_angle_deg\n", "line 2: the header must begin with"},
      {"repeated extra", magic + kHeader + ",t,t\n", "line 2: column 7 of the header repeats the name 't'"},
      {"too many extras", magic + kHeader + ",a,b,c,d,e,f,g,h,i\n", "line 2: the header has 9 extra columns"},
      {"empty metadata key", magic + "# = 3\n" + kHeader + "\n", "line 2: the metadata line has no key"},
      {"too few fields", head + "0,1,2,3,4\n1,2,3,4\n", "line 5: the row has 4 fields but the header has 5"},
      {"too many fields", head + "0,1,2,3,4\n1,2,3,4,5,6\n", "line 5: the row has 6 fields"},
      {"not a number", head + "0,1,2,3,4\n0.1,1,x2,3,4\n", "line 5: column 3 (counter_angle_deg) is 'x2'"},
      {"number with garbage", head + "0,1,2,3,4.5.6\n", "line 4: column 5 (gyro_deg_h) is '4.5.6'"},
      {"empty field", head + "0,,2,3,4\n", "line 4: column 2 (main_angle_deg) is empty"},
      {"nan", head + "0,1,2,3,4\n1,nan,2,3,4\n",
       "line 5: column 2 (main_angle_deg) is 'nan'; a record holds"},
      {"inf", head + "0,1,2,3,-inf\n", "line 4: column 5 (gyro_deg_h) is '-inf'"},
      {"overflow", head + "0,1,2,3,1e999\n", "line 4: column 5 (gyro_deg_h) is '1e999'"},
      {"time repeats", head + "0,1,2,3,4\n0.5,1,2,3,4\n\n0.5,1,2,3,4\n",
       "line 7: time_s 0.5 does not increase"},
      {"time decreases", head + "0,1,2,3,4\n-1,1,2,3,4\n", "line 5: time_s -1 does not increase"},
      {"metadata after header", head + "0,1,2,3,4\n# late = 1\n", "line 5: a '#' line follows the header"},
      {"truncated last line", head + "0,1,2,3,4\n1,2,3", "line 5: the last line is truncated"},
      {"truncated after comma", head + "0,1,2,3,4\n1,2,3,4,", "line 5: the last line is truncated"},
      {"long line", magic + std::string(100000, 'a'), "line 2: the line is longer than 65536 bytes"},
  };
  for (const BadRecord& bad : cases) {
    for (const std::size_t chunk_bytes : {RecordReader::kDefaultChunkBytes, std::size_t{3}}) {
      const std::string message = read_error(bad.text, chunk_bytes);
      EXPECT_NE(message.find(bad.expected), std::string::npos)
          << bad.what << " (chunk " << chunk_bytes << "): got \"" << message << "\"";
    }
  }
}

TEST(Record, CompleteLastLineWithoutNewlineIsAccepted) {
  RecordReader reader = RecordReader::from_string(valid_record(3) + "3,1,2,3,4");
  EXPECT_EQ(read_all(reader).size(), 4u);
}

TEST(Record, GarbageNeverCrashes) {
  std::mt19937_64 random(7);
  const std::string valid = valid_record(50);
  std::vector<std::string> inputs;
  // Every truncation of a valid record.
  for (std::size_t length = 0; length <= valid.size(); length += 3) inputs.push_back(valid.substr(0, length));
  // Random bytes, alone and after a valid head, and valid records with random bytes flipped.
  const std::string alphabet = "0123456789.,-+eE#\n\r \tnaif";
  for (int i = 0; i < 300; ++i) {
    std::string noise(random() % 200, '\0');
    for (char& c : noise) c = i % 2 ? alphabet[random() % alphabet.size()] : static_cast<char>(random());
    inputs.push_back(noise);
    inputs.push_back(valid.substr(0, 40) + noise);
    std::string flipped = valid;
    for (int k = 0; k < 3; ++k) flipped[random() % flipped.size()] = static_cast<char>(random());
    inputs.push_back(flipped);
  }
  int accepted = 0;
  for (const std::string& input : inputs) {
    for (const std::size_t chunk_bytes :
         {std::size_t{1}, std::size_t{64}, RecordReader::kDefaultChunkBytes}) {
      try {
        RecordReader reader = RecordReader::from_string(input, "garbage.csv", chunk_bytes);
        read_all(reader);
        ++accepted;
      } catch (const Error& error) {
        EXPECT_NE(std::string(error.what()).find("garbage.csv"), std::string::npos) << error.what();
      }
    }
  }
  EXPECT_GT(accepted, 0);
}

TEST(Record, LinesCrossingChunkBoundariesFromAFile) {
  const fs::path path =
      fs::temp_directory_path() / ("gyrocal_test_record_" + std::to_string(::getpid()) + ".csv");
  const int rows = 200000;  // about 5 MB: several 1 MiB chunks
  {
    AtomicOutputFile file(path, true);
    RecordWriter writer(file.stream(), {{"rows", std::to_string(rows)}}, {"temperature_c"});
    RecordSample sample;
    for (int i = 0; i < rows; ++i) {
      sample.time_s = i * 0.005;
      sample.main_angle_deg = i * 2.8359375;
      sample.outputs[0] = 1.0 / (i + 1);
      sample.extra[0] = 20.0 + i * 1e-6;
      writer.write(sample);
    }
    writer.finish();
    file.commit();
  }
  ASSERT_GT(fs::file_size(path), 3 * RecordReader::kDefaultChunkBytes);
  for (const std::size_t chunk_bytes : {RecordReader::kDefaultChunkBytes, std::size_t{4093}}) {
    RecordReader reader(path, chunk_bytes);
    RecordSample sample;
    int count = 0;
    while (reader.next(sample)) {
      ASSERT_EQ(sample.time_s, count * 0.005);
      ASSERT_EQ(sample.main_angle_deg, count * 2.8359375);
      ASSERT_EQ(sample.outputs[0], 1.0 / (count + 1));
      ASSERT_EQ(sample.extra[0], 20.0 + count * 1e-6);
      ++count;
    }
    EXPECT_EQ(count, rows);
    EXPECT_EQ(reader.line_number(), static_cast<std::uint64_t>(rows) + 3);
  }
  fs::remove(path);
}

TEST(Record, MissingFileIsNamed) {
  try {
    RecordReader reader("/nonexistent/record.csv");
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("Cannot open record '/nonexistent/record.csv'"),
              std::string::npos);
  }
}

TEST(Record, WriterRefusesWhatTheReaderWouldRefuse) {
  std::ostringstream out;
  RecordWriter writer(out, {}, {});
  RecordSample sample;
  writer.write(sample);
  EXPECT_THROW(writer.write(sample), Error);  // time does not increase
  sample.time_s = 1.0;
  sample.outputs[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(writer.write(sample), Error);
  EXPECT_THROW(RecordWriter(out, {{"a=b", "c"}}, {}), Error);
  EXPECT_THROW(RecordWriter(out, {{"a", "line\nbreak"}}, {}), Error);
  EXPECT_THROW(RecordWriter(out, {}, {"time_s"}), Error);
  EXPECT_THROW(RecordWriter(out, {}, {"bad,name"}), Error);
}

class AtomicFile : public ::testing::Test {
 protected:
  void SetUp() override {
    directory_ = fs::temp_directory_path() / ("gyrocal_test_atomic_" + std::to_string(::getpid()));
    fs::create_directories(directory_);
  }
  void TearDown() override { fs::remove_all(directory_); }
  std::size_t entries() const {
    return static_cast<std::size_t>(
        std::distance(fs::directory_iterator(directory_), fs::directory_iterator()));
  }
  static std::string contents(const fs::path& path) {
    std::ifstream in(path);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  fs::path directory_;
};

TEST_F(AtomicFile, NothingIsLeftWithoutCommit) {
  const fs::path target = directory_ / "out.csv";
  try {
    AtomicOutputFile file(target, false);
    file.write("partial");
    EXPECT_EQ(entries(), 1u);  // the temporary
    throw std::runtime_error("simulation failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(entries(), 0u);
}

TEST_F(AtomicFile, CommitCreatesTheWholeFile) {
  const fs::path target = directory_ / "out.csv";
  const std::string big(3 << 20, 'x');  // bigger than the buffer
  {
    AtomicOutputFile file(target, false);
    file.write("head\n");
    file.stream() << "line " << 2 << '\n';
    file.write(big);
    EXPECT_FALSE(fs::exists(target));
    file.commit();
  }
  EXPECT_EQ(contents(target), "head\nline 2\n" + big);
  EXPECT_EQ(entries(), 1u);
}

TEST_F(AtomicFile, RefusesToOverwriteWithoutTheFlag) {
  const fs::path target = directory_ / "out.csv";
  write_file_atomically(target, "first", false);
  try {
    write_file_atomically(target, "second", false);
    FAIL() << "no error";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(target.string()), std::string::npos) << message;
    EXPECT_NE(message.find("exists; use --force to overwrite"), std::string::npos) << message;
  }
  EXPECT_EQ(contents(target), "first");
  // A file that appears between the constructor and commit() is not overwritten either.
  const fs::path later = directory_ / "later.csv";
  AtomicOutputFile file(later, false);
  write_file_atomically(later, "other writer", false);
  file.write("mine");
  EXPECT_THROW(file.commit(), Error);
  EXPECT_EQ(contents(later), "other writer");
  EXPECT_EQ(entries(), 2u);

  write_file_atomically(target, "second", true);
  EXPECT_EQ(contents(target), "second");
}

TEST_F(AtomicFile, ReportsAMissingDirectory) {
  EXPECT_THROW(AtomicOutputFile(directory_ / "no" / "out.csv", false), Error);
}

}  // namespace
}  // namespace gyrocal
