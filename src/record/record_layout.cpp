#include "gyrocal/record/record_layout.hpp"

#include <array>
#include <cctype>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"

namespace gyrocal {

std::string_view to_string(TimeUnit unit) {
  switch (unit) {
    case TimeUnit::kSeconds:
      return "s";
    case TimeUnit::kMilliseconds:
      return "ms";
    case TimeUnit::kMicroseconds:
      return "us";
    case TimeUnit::kNanoseconds:
      return "ns";
  }
  return "s";
}

std::string_view to_string(AngleUnit unit) {
  return unit == AngleUnit::kRadians ? "rad" : "deg";
}

std::optional<TimeUnit> parse_time_unit(std::string_view text) {
  for (TimeUnit unit :
       {TimeUnit::kSeconds, TimeUnit::kMilliseconds, TimeUnit::kMicroseconds, TimeUnit::kNanoseconds}) {
    if (text == to_string(unit)) return unit;
  }
  return std::nullopt;
}

std::optional<AngleUnit> parse_angle_unit(std::string_view text) {
  for (AngleUnit unit : {AngleUnit::kDegrees, AngleUnit::kRadians}) {
    if (text == to_string(unit)) return unit;
  }
  return std::nullopt;
}

namespace {

bool is_line_break(char c) {
  return c == '\n' || c == '\r';
}

/// A character a number can hold or begin with ("1.5e-3", "+2", "inf", "nan"): as a delimiter it would cut
/// numbers apart, as the start of a comment prefix it would take rows for comments.
bool can_be_in_a_number(char c) {
  const auto u = static_cast<unsigned char>(c);
  return std::isdigit(u) != 0 || std::isalpha(u) != 0 || c == '.' || c == '+' || c == '-';
}

}  // namespace

bool RecordLayout::IsValid(std::string* error, std::string* key) const {
  const auto fail = [&](std::string_view k, std::string text) {
    if (error != nullptr) *error = std::move(text);
    if (key != nullptr) *key = std::string(k);
    return false;
  };
  const auto printable = [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return u >= 0x20 && u < 0x7f ? fmt::format("'{}'", c) : fmt::format("\\x{:02X}", u);
  };
  if (is_line_break(delimiter) || delimiter == '"' || static_cast<unsigned char>(delimiter) >= 0x80 ||
      (delimiter != '\t' && static_cast<unsigned char>(delimiter) < 0x20) || can_be_in_a_number(delimiter)) {
    return fail(
        "delimiter",
        fmt::format("record.delimiter {} cannot separate numbers: use a punctuation character such as "
                    "',' or ';', a tab, or \" \" for any run of spaces or tabs",
                    printable(delimiter)));
  }
  for (char c : comment) {
    if (is_line_break(c)) return fail("comment", "record.comment must not hold a line break");
  }
  const auto starts_a_number = [this](char c) {
    return std::isdigit(static_cast<unsigned char>(c)) != 0 || c == '.' || c == decimal || c == '+' ||
           c == '-';
  };
  if (!comment.empty() && (starts_a_number(comment.front()) || comment.front() == ' ' ||
                           comment.front() == '\t' || comment.front() == delimiter)) {
    return fail("comment", fmt::format("record.comment '{}' begins with {}, which a row or a field can begin "
                                       "with: rows would be taken for comments",
                                       comment, printable(comment.front())));
  }
  if (decimal != '.' && decimal != ',') {
    return fail("decimal",
                fmt::format("record.decimal must be \".\" or \",\" (the numbers' decimal mark), not {}",
                            printable(decimal)));
  }
  if (decimal == delimiter) {
    return fail("decimal", fmt::format("record.decimal {} is also record.delimiter: a decimal comma needs "
                                       "another delimiter, such as ';'",
                                       printable(decimal)));
  }
  if (!(std::isfinite(output_scale_per_deg_h) && output_scale_per_deg_h != 0.0)) {
    return fail(
        "output_scale_per_deg_h",
        fmt::format("record.output_scale_per_deg_h must be a finite non-zero number (output units per "
                    "deg/h, negative for an inverted output; the output is divided by it), not {}",
                    output_scale_per_deg_h));
  }
  if (!(std::isfinite(output_scale_per_g) && output_scale_per_g != 0.0)) {
    return fail("output_scale_per_g",
                fmt::format("record.output_scale_per_g must be a finite non-zero number (output units per g, "
                            "negative for an inverted output; the output is divided by it), not {}",
                            output_scale_per_g));
  }
  // One scale applies, the one of the quantity the output measures; the other must stay at its default.
  if (output_quantity == OutputQuantity::kRate && output_scale_per_g != 1.0) {
    return fail(
        "output_scale_per_g",
        fmt::format("record.output_scale_per_g = {} is an accelerometer's scale (output units per g), "
                    "but the output is a gyro's rate: give record.output_scale_per_deg_h instead",
                    output_scale_per_g));
  }
  if (output_quantity == OutputQuantity::kSpecificForce && output_scale_per_deg_h != 1.0) {
    return fail("output_scale_per_deg_h",
                fmt::format("record.output_scale_per_deg_h = {} is a gyro's scale (output units per deg/h), "
                            "but the output is an accelerometer's specific force: give "
                            "record.output_scale_per_g instead",
                            output_scale_per_deg_h));
  }
  // A unit's name is printed in every table and stored with every result: a few letters, digits and signs.
  const auto unit_name_problem = [&](std::string_view k,
                                     const std::string& name) -> std::optional<std::string> {
    if (name.size() > limits::kOutputUnitBytes)
      return fmt::format(
          "record.{} '{}...' is {} bytes long, more than the {} a unit's name may have (it is "
          "printed in every table)",
          k, name.substr(0, limits::kOutputUnitBytes), name.size(), limits::kOutputUnitBytes);
    for (char c : name) {
      const auto u = static_cast<unsigned char>(c);
      if ((std::isalnum(u) == 0 || u >= 0x80) &&
          std::string_view("/^*._%-").find(c) == std::string_view::npos)
        return fmt::format(
            "record.{} '{}' holds {}: a unit's name is letters, digits and / ^ * . _ % - (\"V\", "
            "\"mV\", \"mA\", \"counts\"; \"u\" for micro)",
            k, name, printable(c));
    }
    return std::nullopt;
  };
  if (auto problem = unit_name_problem("output_unit", output_unit_name)) return fail("output_unit", *problem);
  if (outputs.size() > limits::kMaxOutputColumns)
    return fail("outputs", fmt::format("record.outputs holds {} output columns, more than the {} a record is "
                                       "read with at once (limits::kMaxOutputColumns)",
                                       outputs.size(), limits::kMaxOutputColumns));
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const OutputColumn& o = outputs[i];
    const std::string k = fmt::format("outputs[{}]", i);
    if (!(std::isfinite(o.scale) && o.scale != 0.0))
      return fail(
          k, fmt::format("record.{}.scale must be a finite non-zero number (output units per {}), not {}", k,
                         o.unit(), o.scale));
    if (!std::isfinite(o.offset))
      return fail(k, fmt::format("record.{}.offset must be a finite number, not {}", k, o.offset));
    if (auto problem = unit_name_problem(k + ".unit_name", o.unit_name)) return fail(k, *problem);
  }
  const std::array<std::pair<std::string_view, double>, 4> offsets = {{
      {"output_offset", output_offset},
      {"main_angle_offset_deg", main_angle_offset_deg},
      {"counter_angle_offset_deg", counter_angle_offset_deg},
      {"position_angle_offset_deg", position_angle_offset_deg},
  }};
  for (const auto& [name, value] : offsets) {
    if (!std::isfinite(value))
      return fail(name, fmt::format("record.{} must be a finite number, not {}", name, value));
  }
  if (skip_rows < 0)
    return fail("skip_rows",
                fmt::format("record.skip_rows must be 0 or more (lines skipped before the header), not {}",
                            skip_rows));
  const std::array<std::pair<std::string_view, std::int64_t>, 3> counts = {{
      {"main_counts_per_revolution", main_counts_per_revolution},
      {"counter_counts_per_revolution", counter_counts_per_revolution},
      {"position_counts_per_revolution", position_counts_per_revolution},
  }};
  for (const auto& [name, value] : counts) {
    if (value != 0 && value < 2) {
      return fail(name, fmt::format("record.{} must be 0 (the column holds angles in angle_unit) or an "
                                    "integer >= 2 (encoder counts per revolution), not {}",
                                    name, value));
    }
  }
  // The output columns are the output keys' one, or each of `outputs` (then output_column is not read).
  std::vector<std::pair<std::string, const std::string*>> columns = {
      {"time_column", &time_column},
      {"main_angle_column", &main_angle_column},
      {"counter_angle_column", &counter_angle_column},
      {"position_angle_column", &position_angle_column},
  };
  if (outputs.empty()) columns.emplace_back("output_column", &output_column);
  for (std::size_t i = 0; i < outputs.size(); ++i)
    columns.emplace_back(fmt::format("outputs[{}].column", i), &outputs[i].column);
  for (std::size_t i = 0; i < columns.size(); ++i) {
    const auto& [name, column] = columns[i];
    const bool required = i == 0 || i >= 4;  // the time and the outputs
    if (column->empty()) {
      if (!required) continue;
      return fail(name, fmt::format("record.{} must name a column; only the angle columns may be empty "
                                    "(absent)",
                                    name));
    }
    for (char c : *column) {
      if (is_line_break(c) || c == '"' || (delimiter == ' ' ? c == ' ' || c == '\t' : c == delimiter)) {
        return fail(name, fmt::format("record.{} = '{}' holds {}, which no column name of a header split at "
                                      "the delimiter can hold",
                                      name, *column, printable(c)));
      }
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (*columns[j].second == *column) {
        return fail(name, fmt::format("record.{} and record.{} both name the column '{}'; each column holds "
                                      "one quantity",
                                      columns[j].first, name, *column));
      }
    }
  }
  return true;
}

void require_angle_columns(const std::optional<RecordLayout>& layout, const std::string& record_name) {
  if (!layout || layout->has_angles()) return;
  std::string empty;
  for (const auto& [key, column] :
       {std::pair<std::string_view, const std::string*>{"main_angle_column", &layout->main_angle_column},
        {"counter_angle_column", &layout->counter_angle_column},
        {"position_angle_column", &layout->position_angle_column}}) {
    if (column->empty()) empty += fmt::format("{}record.{}", empty.empty() ? "" : ", ", key);
  }
  throw Error(
      fmt::format("Cannot calibrate from {}: {} {} empty (absent), but a calibration reads the main, "
                  "counter and position angles; name their columns in [record].",
                  record_name, empty, empty.find(',') == std::string::npos ? "is" : "are"));
}

bool RecordLayout::is_default_angle_name(std::string_view name) {
  const RecordLayout defaults;
  return name == defaults.main_angle_column || name == defaults.counter_angle_column ||
         name == defaults.position_angle_column;
}

namespace {

/// The unit the reader gives an output of `quantity` in, and the [record] key of its scale.
std::string_view unit_of(OutputQuantity quantity) {
  return quantity == OutputQuantity::kSpecificForce ? "g" : "deg/h";
}
std::string_view scale_key_of(OutputQuantity quantity) {
  return quantity == OutputQuantity::kSpecificForce ? "output_scale_per_g" : "output_scale_per_deg_h";
}

}  // namespace

std::string_view OutputColumn::unit() const {
  return unit_of(quantity);
}

std::string OutputColumn::column_unit() const {
  return unit_name.empty() ? std::string(unit()) : unit_name;
}

std::string_view OutputColumn::scale_key() const {
  return scale_key_of(quantity);
}

std::vector<OutputColumn> RecordLayout::output_columns() const {
  if (!outputs.empty()) return outputs;
  return {OutputColumn{output_column, output_quantity, OutputForm::kRate, output_scale(), output_offset,
                       output_unit_name}};
}

double RecordLayout::output_scale() const {
  return output_quantity == OutputQuantity::kSpecificForce ? output_scale_per_g : output_scale_per_deg_h;
}

std::string_view RecordLayout::output_unit() const {
  return unit_of(output_quantity);
}

std::string RecordLayout::column_unit() const {
  return output_unit_name.empty() ? std::string(output_unit()) : output_unit_name;
}

std::string accelerometer_output_unit(const std::optional<RecordLayout>& layout) {
  return layout ? layout->column_unit() : std::string("g");
}

std::string_view RecordLayout::output_scale_key() const {
  return scale_key_of(output_quantity);
}

double output_scale_per_g(const std::optional<RecordLayout>& layout) {
  return layout && layout->output_quantity == OutputQuantity::kSpecificForce ? layout->output_scale_per_g
                                                                             : 1.0;
}

bool RecordLayout::has_angles() const {
  return !main_angle_column.empty() && !counter_angle_column.empty() && !position_angle_column.empty();
}

}  // namespace gyrocal
