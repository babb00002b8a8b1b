// The record reader's parser of short plain decimals (record/decimal.hpp): every text it accepts reads as the
// correctly rounded double, checked against glibc's strtod (an independent route: a big-number algorithm, not
// fast_float), and as fast_float reads it (the same double, ending at the same byte), so that the reader's
// values and refusals are the same as with fast_float alone; the texts it declines are left to fast_float.
#include <gtest/gtest.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <fast_float/fast_float.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/record/decimal.hpp"
#include "gyrocal/record/record.hpp"

namespace gyrocal {
namespace {

/// `text` in a buffer with the room parse_short_decimal may read around it, filled with digits (and the byte
/// after the text set to `after`, unless `after` is 0): digits that it must not take for the number's.
class Padded {
 public:
  explicit Padded(const std::string& text, char after = 0)
      : bytes_(std::string(kDecimalReadBefore, '7') + text + std::string(kDecimalReadAfter + 1, '7')),
        size_(text.size()) {
    if (after != 0) bytes_[kDecimalReadBefore + size_] = after;
  }
  const char* first() const { return bytes_.data() + kDecimalReadBefore; }
  const char* last() const { return first() + size_; }

 private:
  std::string bytes_;
  std::size_t size_;
};

std::uint64_t bits(double x) {
  return std::bit_cast<std::uint64_t>(x);
}

/// glibc's strtod of the first `length` bytes of `text` (in the C locale of a test program: '.' is the mark).
double strtod_of(const std::string& text, std::size_t length) {
  const std::string copy = text.substr(0, length);
  char* end = nullptr;
  const double value = std::strtod(copy.c_str(), &end);
  EXPECT_EQ(static_cast<std::size_t>(end - copy.c_str()), length)
      << "strtod stops elsewhere in '" << text << "'";
  return value;
}

struct Outcome {
  bool accepted = false;
  std::size_t length = 0;  ///< bytes read, when accepted
  double value = 0.0;
};

/// Parses `text` (followed in the buffer by `after` and digits) with parse_short_decimal, and checks an
/// accepted text against fast_float (same end, same bits) and, for the mark '.', against strtod.
Outcome check(const std::string& text, char decimal = '.', char after = ',') {
  const Padded padded(text, after);
  Outcome out;
  double value = 12345.0;  // unchanged when declined
  const char* end = parse_short_decimal(padded.first(), padded.last(), decimal, value);
  if (end == nullptr) {
    EXPECT_EQ(value, 12345.0) << "a declined text changed the value: '" << text << "'";
    return out;
  }
  out.accepted = true;
  out.length = static_cast<std::size_t>(end - padded.first());
  out.value = value;
  double reference = 0.0;
  const auto ff =
      fast_float::from_chars_advanced(padded.first(), padded.last(), reference,
                                      fast_float::parse_options{fast_float::chars_format::general, decimal});
  EXPECT_EQ(ff.ec, std::errc()) << "'" << text << "' is accepted but fast_float refuses it";
  EXPECT_EQ(ff.ptr, end) << "'" << text << "': fast_float ends elsewhere";
  EXPECT_EQ(bits(reference), bits(value))
      << "'" << text << "': " << value << " but fast_float reads " << reference;
  if (decimal == '.') {
    const double exact = strtod_of(text, out.length);
    EXPECT_EQ(bits(exact), bits(value)) << "'" << text << "': " << value << " but strtod reads " << exact;
  }
  return out;
}

/// Accepted whole, with the correctly rounded value `expected` (strtod's and fast_float's are checked too).
void expect_accepted(const std::string& text, double expected) {
  const Outcome out = check(text);
  EXPECT_TRUE(out.accepted) << "'" << text << "' is declined";
  EXPECT_EQ(out.length, text.size()) << "'" << text << "' is read in part";
  EXPECT_EQ(bits(out.value), bits(expected)) << "'" << text << "'";
}

TEST(ShortDecimal, EdgeCasesAreCorrectlyRoundedOrLeftToFastFloat) {
  expect_accepted("0", 0.0);
  expect_accepted("-0", -0.0);  // negative zero keeps its sign, as with fast_float
  expect_accepted("-0.000", -0.0);
  expect_accepted("0.0", 0.0);
  expect_accepted("123.456789012", 123.456789012);
  expect_accepted("0.1", 0.1);
  expect_accepted("-0.005", -0.005);
  expect_accepted("5.", 5.0);
  expect_accepted(".5", 0.5);
  expect_accepted("-.5", -0.5);
  expect_accepted("357.1638594870602", 357.1638594870602);    // 16 digits: below 2^53
  expect_accepted("2.8361410858975753", 2.8361410858975753);  // 17 digits: above 2^53
  expect_accepted("0.3000000000000001", 0.3000000000000001);
  expect_accepted("1.7976931348623157", 1.7976931348623157);
  expect_accepted("0.0000000000000001", 1e-16);  // 16 digits after the mark
  expect_accepted("9999999999999999", 9999999999999999.0);
  expect_accepted("999999999999999", 999999999999999.0);  // 15 digits: an integer converted directly
  expect_accepted("-123456789012345", -123456789012345.0);
  expect_accepted("16777216", 16777216.0);
  expect_accepted("999.9999999999999999", 1000.0);  // 19 digits
  expect_accepted("0000000000000001.500", 1.5);     // 19 digits, leading zeros
  // Near 2^53, where doubles are 2 apart: a tie goes to the even mantissa.
  expect_accepted("9007199254740992", 9007199254740992.0);
  expect_accepted("9007199254740993", 9007199254740992.0);
  expect_accepted("9007199254740995", 9007199254740996.0);
  expect_accepted("9007199254740993.0",
                  9007199254740992.0);  // the same tie with q = -1 (Eisel-Lemire's route)
  expect_accepted("9007199254740995.000", 9007199254740996.0);
  expect_accepted("9007199254740993.001", 9007199254740994.0);  // just above the tie
  expect_accepted("-9007199254740994.5", -9007199254740994.0);
  // Declined: left to fast_float, which reads exponents, long digit strings, infinities, and refuses a '+'.
  for (const std::string text : {"",
                                 "-",
                                 ".",
                                 "-.",
                                 "+1",
                                 "1e5",
                                 "1E5",
                                 "-2.5e-3",
                                 "1e",
                                 "inf",
                                 "-inf",
                                 "nan",
                                 "infinity",
                                 "--1",
                                 "12345678901234567",
                                 "0.00000000000000001",
                                 "0.30000000000000004",
                                 "99999999999999999999",
                                 "1234567890.1234567890",
                                 " 1",
                                 "\t1",
                                 "x1",
                                 ",1"}) {
    EXPECT_FALSE(check(text).accepted) << "'" << text << "'";
  }
  // Read in part exactly as fast_float reads them (the reader then refuses the field as fast_float's reading
  // would have it refused): a second mark, a hexadecimal prefix, a blank inside.
  EXPECT_EQ(check("1.2.3").length, 3u);
  EXPECT_EQ(check("1..2").length, 2u);
  EXPECT_EQ(check("0x10").length, 1u);
  EXPECT_EQ(check("12 3").length, 2u);
  // The decimal comma of a rig's layout.
  const Outcome comma = check("-12,75", ',', ';');
  EXPECT_TRUE(comma.accepted);
  EXPECT_EQ(comma.value, -12.75);
  EXPECT_EQ(check("12.75", ',', ';').length, 2u);  // '.' is no mark then: 12, as fast_float reads it
}

TEST(ShortDecimal, ReadsOnlyUpToLastWhateverFollows) {
  // The buffer holds digits before and after the text; a number cut by `last` ends there.
  for (const std::string text : {"1", "12.5", "-3.25", "123456789.123456789", "0.0000000000000001"}) {
    for (std::size_t length = 1; length <= text.size(); ++length) {
      const std::string part = text.substr(0, length);
      const Padded padded(part);  // followed by '7's
      double value = 0.0;
      const char* end = parse_short_decimal(padded.first(), padded.last(), '.', value);
      if (end == nullptr) continue;  // "-" or "12.": checked elsewhere
      EXPECT_EQ(end, padded.last()) << part;
      EXPECT_EQ(bits(value), bits(strtod_of(part, part.size()))) << part;
    }
  }
}

/// A random plain decimal: up to `max_whole` digits, a mark and up to `max_fraction` digits, either sign.
std::string random_plain(std::mt19937_64& random, int max_whole, int max_fraction) {
  std::uniform_int_distribution<int> digit('0', '9');
  std::string text = random() % 2 == 0 ? "-" : "";
  const int whole = static_cast<int>(random() % static_cast<unsigned>(max_whole + 1));
  const int fraction = static_cast<int>(random() % static_cast<unsigned>(max_fraction + 1));
  for (int i = 0; i < whole; ++i) text += static_cast<char>(digit(random));
  if (fraction > 0 || random() % 4 == 0) text += '.';
  for (int i = 0; i < fraction; ++i) text += static_cast<char>(digit(random));
  return text;
}

TEST(ShortDecimal, RandomTextsOfTheRecordsFormsAreCorrectlyRounded) {
  std::mt19937_64 random(20261125);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> decade(-8, 16);
  int accepted = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    // What gyrocal's writer and a rig write: the shortest round-trip form of a double (std::to_chars, fixed
    // notation when it is shorter), the same in fixed notation, and a fixed number of decimals.
    const double value = unit(random) * std::pow(10.0, decade(random));
    char buffer[400];
    std::string text;
    switch (trial % 4) {
      case 0:
        text.assign(buffer, std::to_chars(buffer, buffer + sizeof buffer, value).ptr);
        break;
      case 1:
        text.assign(buffer,
                    std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed).ptr);
        break;
      case 2:
        text.assign(buffer, std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed,
                                          static_cast<int>(random() % 12))
                                .ptr);
        break;
      default:
        text = random_plain(random, 18, 18);
        break;
    }
    const Outcome out = check(text);
    // Every plain form within the limits (16 digits before the mark, 16 after, 19 in all) is taken.
    std::size_t whole = 0, fraction = 0, at = text[0] == '-' ? 1 : 0;
    for (; at < text.size() && text[at] >= '0' && text[at] <= '9'; ++at) ++whole;
    const bool mark = at < text.size() && text[at] == '.';
    if (mark) ++at;
    for (; at < text.size() && text[at] >= '0' && text[at] <= '9'; ++at) ++fraction;
    const bool plain = at == text.size() && whole + fraction > 0;
    if (plain && whole <= 16 && fraction <= 16 && whole + fraction <= 19) {
      EXPECT_TRUE(out.accepted && out.length == text.size()) << "'" << text << "' is not taken whole";
    }
    if (!plain || whole > 16 || fraction > 16 || whole + fraction > 19) {
      EXPECT_FALSE(out.accepted && out.length == text.size()) << "'" << text << "' is outside the limits";
    }
    accepted += out.accepted ? 1 : 0;
    if (::testing::Test::HasFailure()) break;
  }
  EXPECT_GT(accepted, 100000);
}

TEST(ShortDecimal, AnyTextItTakesReadsAsWithFastFloat) {
  // Random bytes from the characters a field holds and the ones near them: every text taken ends where
  // fast_float ends and has its double (check()); the others are fast_float's to read or refuse.
  const std::string alphabet = "0123456789012345678901234567890123456789.-+eE,; \tx\r";
  std::mt19937_64 random(17);
  for (int trial = 0; trial < 200000; ++trial) {
    std::string text;
    const std::size_t length = random() % 36;
    for (std::size_t i = 0; i < length; ++i) text += alphabet[random() % alphabet.size()];
    check(text, trial % 3 == 0 ? ',' : '.', trial % 2 == 0 ? ',' : '9');
    if (::testing::Test::HasFailure()) break;
  }
}

TEST(ShortDecimal, TheSse2HelpersAgreeWithTheirPortableForms) {
  // Where there is SSE2 the digits are found and read 16 at a time; elsewhere byte by byte and 8 at a time.
  // Both on random bytes (digits, and the bytes next to '0' and '9'), every count of digits.
  const std::string alphabet = "0123456789/:.-, \x80\xff";
  std::mt19937_64 random(3);
  for (int trial = 0; trial < 20000; ++trial) {
    std::string bytes(48, '0');
    for (char& c : bytes) c = alphabet[random() % alphabet.size()];
    EXPECT_EQ(short_decimal::digits_of_32(bytes.data()), short_decimal::digits_of_32_portable(bytes.data()))
        << bytes;
    std::string digits(48, '0');
    for (char& c : digits) c = static_cast<char>('0' + random() % 10);
    for (unsigned n = 0; n <= 16; ++n) {
      const char* end = digits.data() + 16 + random() % 32;
      const std::uint64_t expected = n == 0 ? 0 : std::stoull(std::string(end - n, end));
      EXPECT_EQ(short_decimal::up_to_16_digits(end, n), expected) << std::string(end - n, end);
      EXPECT_EQ(short_decimal::up_to_16_digits_portable(end, n), expected) << std::string(end - n, end);
    }
    if (::testing::Test::HasFailure()) break;
  }
}

TEST(ShortDecimal, TheReaderGivesStrtodsDoubleForEveryForm) {
  // Rows mixing the fast forms with the ones left to fast_float (exponents, '+' in an exponent, spaces, long
  // digit strings), in gyrocal's format and through a layout with ';' and a decimal comma.
  std::mt19937_64 random(5);
  std::uniform_int_distribution<int> decade(-20, 20);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::string native =
      std::string(kRecordMagic) + "\ntime_s,main_angle_deg,counter_angle_deg,position_angle_deg,gyro_deg_h\n";
  std::string mapped = "t;m;c;p;w\n";
  std::vector<std::vector<std::string>> fields;
  for (int row = 0; row < 3000; ++row) {
    std::vector<std::string> texts;
    char buffer[64];
    texts.push_back(std::to_string(row) + "." + std::to_string(random() % 1000));
    for (int i = 0; i < 4; ++i) {
      const double value = unit(random) * std::pow(10.0, decade(random));
      std::string text(buffer, std::to_chars(buffer, buffer + sizeof buffer, value).ptr);
      if (row % 7 == 0) text = random_plain(random, 20, 20);
      if (text == "-" || text == "." || text == "-." || text.empty()) text = "0";
      if (row % 11 == 0 && i == 2) text = " " + text + "\t";
      if (row % 13 == 0 && i == 3) text = "1.5E+2";
      texts.push_back(text);
    }
    for (std::size_t i = 0; i < texts.size(); ++i) {
      native += (i == 0 ? "" : ",") + texts[i];
      std::string comma = texts[i];
      for (char& c : comma)
        if (c == '.') c = ',';
      mapped += (i == 0 ? "" : ";") + comma;
    }
    native += row % 5 == 0 ? "\r\n" : "\n";
    mapped += "\n";
    fields.push_back(texts);
  }
  RecordLayout layout;
  layout.delimiter = ';';
  layout.decimal = ',';
  layout.time_column = "t";
  layout.main_angle_column = "m";
  layout.counter_angle_column = "c";
  layout.position_angle_column = "p";
  layout.output_column = "w";
  for (const bool through_layout : {false, true}) {
    RecordReader reader = through_layout ? RecordReader::from_string(mapped, layout, "mapped.csv", 4096)
                                         : RecordReader::from_string(native, "native.csv", 4096);
    RecordSample sample;
    for (const auto& texts : fields) {
      ASSERT_TRUE(reader.next(sample));
      const double read[5] = {sample.time_s, sample.main_angle_deg, sample.counter_angle_deg,
                              sample.position_angle_deg, sample.outputs[0]};
      for (std::size_t i = 0; i < 5; ++i) {
        const double exact = std::strtod(texts[i].c_str(), nullptr);
        EXPECT_EQ(bits(read[i]), bits(exact)) << "'" << texts[i] << "', through a layout: " << through_layout;
      }
    }
    EXPECT_FALSE(reader.next(sample));
  }
}

/// What reading `text` gives: every value's bits, or the refusal's message.
std::string reading(const std::string& text, const std::optional<RecordLayout>& layout, std::size_t chunk) {
  std::string out;
  try {
    RecordReader reader = RecordReader::from_string(text, layout, "mixed.csv", chunk);
    RecordSample s;
    while (reader.next(s)) {
      for (const double v :
           {s.time_s, s.main_angle_deg, s.counter_angle_deg, s.position_angle_deg, s.outputs[0]})
        out += std::to_string(bits(v)) + ",";
      for (std::size_t e = 0; e < reader.extra_column_count(); ++e)
        out += std::to_string(bits(s.extra[e])) + ",";
      out += std::to_string(reader.line_number()) + "\n";
    }
  } catch (const Error& e) {
    out += e.what();
  }
  return out;
}

TEST(ShortDecimal, TheCommonRowPathAndTheGeneralPathAgree) {
  // A row wholly in the read buffer is read by the common-row path when it can be; cut by the end of a read,
  // or of another form, by the general path. Read in one piece and in pieces of 7 bytes (nearly every row
  // through the general path), rows of every form, with one byte changed, inserted or deleted here and there,
  // must give the same values, or the same refusal with the same line.
  RecordLayout semicolon;  // ';', a decimal comma, ns stamps, a comment prefix
  semicolon.delimiter = ';';
  semicolon.decimal = ',';
  semicolon.comment = "%";
  semicolon.time_column = "t";
  semicolon.time_unit = TimeUnit::kNanoseconds;
  semicolon.main_angle_column = "m";
  semicolon.counter_angle_column = "c";
  semicolon.position_angle_column = "p";
  semicolon.output_column = "w";
  RecordLayout skipping = semicolon;  // ',' and a column skipped, ms stamps
  skipping.delimiter = ',';
  skipping.decimal = '.';
  skipping.comment = "//";
  skipping.time_unit = TimeUnit::kMilliseconds;
  const std::string forms[] = {"0",
                               "-0",
                               "12.5",
                               "-3.25",
                               "357.1638594870602",
                               "2.8361410858975753",
                               "1e5",
                               "+1",
                               "inf",
                               "12345678901234567890",
                               "0.000000000000000001",
                               " 7",
                               "8 ",
                               "-",
                               "1.",
                               ".5",
                               "0x1",
                               ""};
  std::mt19937_64 random(11);
  const std::string alphabet = "0123456789.,;-+eE \t\r\n#%/x";
  for (int trial = 0; trial < 1500; ++trial) {
    const int kind = trial % 3;
    const std::string delimiter = kind == 1 ? ";" : ",";
    std::string text = kind == 0 ? std::string(kRecordMagic) + "\n" +
                                       "time_s,main_angle_deg,counter_angle_deg,"
                                       "position_angle_deg,gyro_deg_h\n"
                       : kind == 1 ? "t;m;c;p;w\n"
                                   : "t,x,m,c,p,w\n";
    const int rows = 1 + static_cast<int>(random() % 12);
    for (int row = 0; row < rows; ++row) {
      text += std::to_string(kind == 0 ? row + 1 : (row + 1) * 5);
      for (int column = 0; column < (kind == 2 ? 5 : 4); ++column) {
        std::string field = random() % 3 == 0 ? forms[random() % std::size(forms)]
                                              : std::to_string(static_cast<int>(random() % 2000) - 1000) +
                                                    "." + std::to_string(random() % 100000000);
        if (kind == 1)
          for (char& c : field)
            if (c == '.') c = ',';
        text += delimiter + field;
      }
      text += random() % 5 == 0 ? "\r\n" : "\n";
    }
    for (int change = static_cast<int>(random() % 3); change > 0; --change) {
      const std::size_t at = random() % (text.size() + 1);
      const char c = alphabet[random() % alphabet.size()];
      switch (random() % 3) {
        case 0:
          text.insert(at, 1, c);
          break;
        case 1:
          if (at < text.size()) text.erase(at, 1);
          break;
        default:
          if (at < text.size()) text[at] = c;
      }
    }
    const std::optional<RecordLayout> layout =
        kind == 0 ? std::nullopt : std::optional<RecordLayout>(kind == 1 ? semicolon : skipping);
    EXPECT_EQ(reading(text, layout, text.size() + 1), reading(text, layout, 7)) << text;
    if (::testing::Test::HasFailure()) break;
  }
}

}  // namespace
}  // namespace gyrocal
