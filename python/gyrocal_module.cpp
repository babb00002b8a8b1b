// The compiled part of the Python module gyrocal (docs/python.md): thin bindings over the library, so that
// its numbers are the command line's. No physics here: every number comes from the same functions the command
// line calls. python/gyrocal/__init__.py holds the Python-facing functions and their argument handling.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "gyrocal/analysis/record_noise.hpp"
#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/history/read.hpp"
#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/identify/imu_calibration.hpp"
#include "gyrocal/identify/model_terms.hpp"
#include "gyrocal/identify/record_check.hpp"
#include "gyrocal/identify/scenario_options.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/reduce/feasibility.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/result/calibration_json.hpp"
#include "gyrocal/result/history_json.hpp"
#include "gyrocal/result/imu_calibration_json.hpp"
#include "gyrocal/result/noise_json.hpp"
#include "gyrocal/simulate/simulator.hpp"

namespace py = pybind11;

namespace gyrocal {
namespace {

/// A one-dimensional float64 array (NumPy converts what it is given; C order, so data() is the values in
/// order).
using Column = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// The JSON as the Python objects json.loads gives for the command line's text, so that a dict from the
/// module equals the command line's JSON parsed by Python (NaN written as null, as the command line writes
/// it).
py::object json_to_python(const nlohmann::ordered_json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

/// The name a scenario's record, configuration and Python messages go by.
constexpr const char* kScenarioName = "the scenario";

/// gyrocal's own output column of a sensor: gyro_deg_h (deg/h) or accel_g (g).
std::string native_output_column(SensorKind kind) {
  return std::string(kind == SensorKind::kAccelerometer ? Accelerometer::native_column : Gyro::native_column);
}

/// The IMU's functions are called only for an IMU's scenario (python/gyrocal/__init__.py chooses them).
void refuse_lone(const Scenario& scenario) {
  if (!scenario.is_imu())
    throw Error(
        "the scenario is not an IMU's ([sensor] kind = \"imu\"): the IMU's functions read an IMU's "
        "channels.");
}

/// The options `gyrocal calibrate` builds, by the same library function (identify/scenario_options.hpp):
/// each choice left empty (None in Python) takes the scenario's [calibration] gyro_model, estimate and
/// reduction; [reduce] applies always.
CalibrationOptions python_calibration_options(const Scenario& scenario, const std::string& method,
                                              const std::string& compensation, const std::string& reduction,
                                              const std::optional<std::vector<std::string>>& estimate,
                                              const std::string& gyro_model) {
  CalibrationChoices choices;
  choices.method = method;
  choices.compensation = compensation;
  choices.estimate = estimate;
  choices.estimate_source = "estimate";
  choices.gyro_model = gyro_model;
  choices.reduction = reduction;
  return calibration_options(scenario, choices);
}

/// Checks that a dict's columns make a record the reader would accept: one dimension, the same length, finite
/// values, the output (the last column) within limits::kOutputMagnitude, time strictly increasing. `name`
/// stands for the record in messages; rows are counted from 0.
void check_columns(const std::vector<const Column*>& columns, const std::vector<std::string>& names,
                   const std::string& name) {
  const py::ssize_t n = columns.front()->size();
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (columns[c]->ndim() != 1)
      throw Error(fmt::format("{}: column {} has {} dimensions; a record's column has one.", name, names[c],
                              columns[c]->ndim()));
    if (columns[c]->size() != n)
      throw Error(fmt::format("{}: column {} has {} values but column {} has {}.", name, names[c],
                              columns[c]->size(), names.front(), n));
    const double* v = columns[c]->data();
    // The output (the last column) within limits::kOutputMagnitude, as the record reader holds it.
    const bool output = c + 1 == columns.size();
    for (py::ssize_t i = 0; i < n; ++i) {
      if (!std::isfinite(v[i]))
        throw Error(fmt::format("{}, row {}: {} is {}, not a finite number.", name, i, names[c], v[i]));
      if (output && !(std::abs(v[i]) <= limits::kOutputMagnitude))
        throw Error(fmt::format(
            "{}, row {}: {} is {}; an output is at most {} in magnitude (limits::kOutputMagnitude): no "
            "sensor "
            "writes such a value, and the squares a calibration sums of it would leave a double's range.",
            name, i, names[c], v[i], limits::kOutputMagnitude));
    }
  }
  const double* t = columns.front()->data();
  for (py::ssize_t i = 1; i < n; ++i)
    if (!(t[i] > t[i - 1]))
      throw Error(fmt::format("{}, row {}: time_s {} does not increase from the previous row's {}.", name, i,
                              t[i], t[i - 1]));
}

py::tuple exact_inputs_py(const Scenario& scenario, const Column& time_s, double beta_deg) {
  // As `gyrocal inputs`, which refuses a number that is not finite (--beta-deg nan, --time-s inf).
  if (!std::isfinite(beta_deg))
    throw Error(fmt::format("beta_deg must be a finite number, not {}.", beta_deg));
  if (time_s.ndim() != 1)
    throw Error(
        fmt::format("time_s has {} dimensions; give a number or a one-dimensional array.", time_s.ndim()));
  for (py::ssize_t i = 0; i < time_s.size(); ++i) {
    if (!std::isfinite(time_s.data()[i]))
      throw Error(fmt::format("time_s[{}] must be a finite number, not {}.", i, time_s.data()[i]));
    check_time_within_test(time_s.data()[i], scenario.test, fmt::format("time_s[{}]", i));
  }
  const CentrifugeModel model = scenario.model();
  // As `gyrocal inputs --time-s`: a spinning dwell at the configured rate, beta in radians from degrees.
  const double rate = scenario.centrifuge.rate_rad_s, beta = beta_deg * kDegToRad;
  const py::ssize_t n = time_s.size();
  py::array_t<double> omega({n, py::ssize_t{3}}), force({n, py::ssize_t{3}});
  const double* t = time_s.data();
  double* w = omega.mutable_data();
  double* f = force.mutable_data();
  {
    py::gil_scoped_release release;
    for (py::ssize_t i = 0; i < n; ++i) {
      const SensorInputs in = exact_inputs(model, spinning_joint_state(model, rate, beta, t[i]));
      for (int k = 0; k < 3; ++k) {
        w[3 * i + k] = in.rate_rad_s[k];
        f[3 * i + k] = in.specific_force_g[k];
      }
    }
  }
  return py::make_tuple(omega, force);
}

/// The record `gyrocal simulate` writes, keyed as its header: time_s, the three angles, then the output: a
/// lone sensor's in deg/h (gyro_deg_h) or g (accel_g), an IMU's every channel's column in its own units
/// (simulate_written).
py::dict simulate_py(const Scenario& scenario, std::optional<std::uint64_t> seed) {
  const std::vector<SensorChannel> channels = scenario.channels();
  std::vector<std::vector<double>> columns(4 + channels.size());
  {
    py::gil_scoped_release release;
    SimulationOptions options;
    options.seed = seed;
    simulate_written(scenario, options, [&columns](const RecordSample& s) {
      columns[0].push_back(s.time_s);
      columns[1].push_back(s.main_angle_deg);
      columns[2].push_back(s.counter_angle_deg);
      columns[3].push_back(s.position_angle_deg);
      for (std::size_t c = 4; c < columns.size(); ++c) columns[c].push_back(s.outputs[c - 4]);
    });
  }
  py::dict out;
  for (std::size_t c = 0; c < columns.size(); ++c) {
    const std::string key = c < 4               ? std::string(kRecordColumns[c])
                            : scenario.is_imu() ? channels[c - 4].output.column
                                                : std::string(native_output_column(scenario.sensor_kind));
    out[py::str(key)] = py::array_t<double>(static_cast<py::ssize_t>(columns[c].size()), columns[c].data());
  }
  return out;
}

py::object calibrate_path_py(const std::string& path, const Scenario& scenario, const std::string& method,
                             const std::string& compensation, const std::string& reduction,
                             const std::optional<std::vector<std::string>>& estimate,
                             const std::string& gyro_model) {
  const CalibrationOptions options =
      python_calibration_options(scenario, method, compensation, reduction, estimate, gyro_model);
  nlohmann::ordered_json j;
  {
    py::gil_scoped_release release;
    // The record's output must be the scenario's sensor's, as `gyrocal calibrate` checks. One reader checks
    // it and reads the rows: a pipe or a FIFO can be opened only once.
    RecordReader reader(path, scenario.record);
    require_output_for_sensor(reader, scenario.sensor_kind, kScenarioName);
    j = calibration_to_json(calibrate_record(reader, scenario.model(), scenario.test, options));
  }
  j["record"] = path;  // as `gyrocal calibrate --json` writes it
  return json_to_python(j);
}

py::object calibrate_arrays_py(const Column& time_s, const Column& main_deg, const Column& counter_deg,
                               const Column& position_deg, const Column& gyro_deg_h, const Scenario& scenario,
                               const std::string& method, const std::string& compensation,
                               const std::string& reduction,
                               const std::optional<std::vector<std::string>>& estimate,
                               const std::string& gyro_model, const std::string& name) {
  // Not const: the output's range is kept for the misfit's causes.
  CalibrationOptions options =
      python_calibration_options(scenario, method, compensation, reduction, estimate, gyro_model);
  const std::vector<const Column*> columns = {&time_s, &main_deg, &counter_deg, &position_deg, &gyro_deg_h};
  std::vector<std::string> column_names(kRecordColumns.begin(), kRecordColumns.end());
  column_names[4] = native_output_column(scenario.sensor_kind);
  check_columns(columns, column_names, name);
  nlohmann::ordered_json j;
  {
    py::gil_scoped_release release;
    // What calibrate_record does, with the rows from the arrays instead of a RecordReader.
    const CentrifugeModel model = scenario.model();
    Reducer reducer(reduction_plan(scenario.test, options.sensor, options.reduce), options.reduce, name,
                    model.geometry().rate_rad_s);
    RecordSample s;
    for (py::ssize_t i = 0; i < time_s.size(); ++i) {
      s.time_s = time_s.data()[i];
      s.main_angle_deg = main_deg.data()[i];
      s.counter_angle_deg = counter_deg.data()[i];
      s.position_angle_deg = position_deg.data()[i];
      s.outputs[0] = gyro_deg_h.data()[i];
      options.output.range.push(s.outputs[0]);  // for the misfit's causes (a flat top)
      reducer.push(s);
    }
    const Reduction reduction_result = reducer.finish();
    const std::vector<PositionModelTerms> model_terms =
        calibration_model_terms(reduction_result, model, options);
    j = calibration_to_json(identify(reduction_result, model_terms, model, options));
  }
  j["record"] = name;
  return json_to_python(j);
}

py::object noise_path_py(const std::string& path, const std::optional<Scenario>& scenario) {
  nlohmann::json j;
  {
    py::gil_scoped_release release;
    // The scenario's [record] says how the record is laid out (docs/records.md), its [sensor] kind whose
    // output it holds (without a scenario, the record's output column says).
    RecordNoiseOptions options;
    if (scenario) {
      options.sensor = scenario->sensor_kind;
      options.config_name = kScenarioName;
    }
    j = noise_to_json(characterise_record_noise(path, options, scenario ? scenario->record : std::nullopt));
  }
  return json_to_python(j);
}

/// `output` is the column named `output_column` (gyro_deg_h in deg/h, accel_g in g).
py::object noise_arrays_py(const Column& time_s, const Column& output, const std::string& output_column,
                           const std::string& name) {
  check_columns({&time_s, &output}, {"time_s", output_column}, name);
  const std::vector<double> t(time_s.data(), time_s.data() + time_s.size());
  const std::vector<double> w(output.data(), output.data() + output.size());
  RecordNoiseOptions options;
  options.sensor = sensor_of_output_column(output_column).value_or(SensorKind::kGyro);
  nlohmann::json j;
  {
    py::gil_scoped_release release;
    j = noise_to_json(characterise_samples_noise(t, w, name, options));
  }
  return json_to_python(j);
}

// --- A whole IMU (docs/imu.md, docs/python.md "An IMU") ----------------------------------------------------

/// The columns an IMU's record is read with through its scenario's layout (Scenario::reading_layout()), in
/// order: the time, the angle columns the layout names (with `angles`; a noise needs none), then every
/// channel's output column. A mapping given for the record holds them under these names, in the columns' own
/// units (an increment as an increment), as the file holds them.
std::vector<std::string> imu_columns(const Scenario& scenario, bool angles) {
  refuse_lone(scenario);
  const RecordLayout layout = *scenario.reading_layout();
  std::vector<std::string> names = {layout.time_column};
  if (angles)
    for (const std::string* c :
         {&layout.main_angle_column, &layout.counter_angle_column, &layout.position_angle_column})
      if (!c->empty()) names.push_back(*c);
  for (const OutputColumn& o : layout.outputs) names.push_back(o.column);
  return names;
}

/// The reader of an IMU's record held in arrays (`columns`, named `names` as imu_columns gives them): the
/// arrays, checked as a dict's columns are (check_columns), written as CSV text in the shortest form that
/// reads back as the same doubles, and read through the scenario's layout, with a comma, '#' comments, no
/// preamble or units row and a decimal point, and without the angle columns that `names` lacks. So every
/// conversion (units, scales, offsets, an increment divided by its interval) and every refusal is the
/// reader's, as for a file. `name` stands for the record in messages.
RecordReader imu_arrays_reader(const std::vector<Column>& columns, const std::vector<std::string>& names,
                               const Scenario& scenario, const std::string& name) {
  std::vector<const Column*> pointers;
  for (const Column& c : columns) pointers.push_back(&c);
  if (pointers.empty() || pointers.size() != names.size())
    throw Error(fmt::format("{}: {} columns given for the {} an IMU's record is read with.", name,
                            pointers.size(), names.size()));
  check_columns(pointers, names, name);
  RecordLayout layout = *scenario.reading_layout();
  layout.delimiter = ',';
  layout.comment = "#";
  layout.skip_rows = 0;
  layout.units_row = false;
  layout.decimal = '.';
  const auto named = [&names](const std::string& c) {
    return std::find(names.begin(), names.end(), c) != names.end();
  };
  for (std::string* c :
       {&layout.main_angle_column, &layout.counter_angle_column, &layout.position_angle_column})
    if (!named(*c)) c->clear();
  fmt::memory_buffer text;
  for (std::size_t c = 0; c < names.size(); ++c)
    fmt::format_to(std::back_inserter(text), "{}{}", c ? "," : "", names[c]);
  text.push_back('\n');
  const py::ssize_t rows = columns.front().size();
  for (py::ssize_t i = 0; i < rows; ++i) {
    for (std::size_t c = 0; c < columns.size(); ++c)
      fmt::format_to(std::back_inserter(text), "{}{}", c ? "," : "", columns[c].data()[i]);
    text.push_back('\n');
  }
  return RecordReader::from_string(fmt::to_string(text), layout, name);
}

py::object calibrate_imu_path_py(const std::string& path, const Scenario& scenario, const std::string& method,
                                 const std::string& compensation, const std::string& reduction,
                                 const std::optional<std::vector<std::string>>& estimate,
                                 const std::string& gyro_model) {
  refuse_lone(scenario);
  const CalibrationOptions options =
      python_calibration_options(scenario, method, compensation, reduction, estimate, gyro_model);
  nlohmann::ordered_json j;
  {
    py::gil_scoped_release release;
    // As `gyrocal calibrate` of an IMU: every channel's column in one pass, one joint solve.
    RecordReader reader(path, scenario.reading_layout());
    j = imu_calibration_to_json(
        calibrate_imu_record(reader, scenario.channels(), scenario.model(), scenario.test, options));
  }
  j["record"] = path;
  return json_to_python(j);
}

py::object calibrate_imu_arrays_py(const std::vector<Column>& columns, const std::vector<std::string>& names,
                                   const Scenario& scenario, const std::string& method,
                                   const std::string& compensation, const std::string& reduction,
                                   const std::optional<std::vector<std::string>>& estimate,
                                   const std::string& gyro_model, const std::string& name) {
  refuse_lone(scenario);
  const CalibrationOptions options =
      python_calibration_options(scenario, method, compensation, reduction, estimate, gyro_model);
  nlohmann::ordered_json j;
  RecordReader reader = imu_arrays_reader(columns, names, scenario, name);
  {
    py::gil_scoped_release release;
    j = imu_calibration_to_json(
        calibrate_imu_record(reader, scenario.channels(), scenario.model(), scenario.test, options));
  }
  j["record"] = name;
  return json_to_python(j);
}

py::object noise_imu_path_py(const std::string& path, const Scenario& scenario) {
  refuse_lone(scenario);
  nlohmann::ordered_json j;
  {
    py::gil_scoped_release release;
    j = imu_noise_to_json(
        characterise_imu_record_noise(path, scenario.channels(), *scenario.reading_layout()));
  }
  return json_to_python(j);
}

py::object noise_imu_arrays_py(const std::vector<Column>& columns, const std::vector<std::string>& names,
                               const Scenario& scenario, const std::string& name) {
  refuse_lone(scenario);
  nlohmann::ordered_json j;
  RecordReader reader = imu_arrays_reader(columns, names, scenario, name);
  {
    py::gil_scoped_release release;
    j = imu_noise_to_json(characterise_imu_record_noise(reader, scenario.channels()));
  }
  return json_to_python(j);
}

/// Refuses, as the command line does, a record whose output column is the other sensor's.
void check_output_column_py(const std::string& column, const Scenario& scenario, const std::string& name) {
  require_output_column_for_sensor(column, scenario.sensor_kind, name, kScenarioName);
}

/// `gyrocal history show --unit UNIT --db DB --json` as a dict (without the file's marker), read by the same
/// library function (history::read_unit_history, refusing as the command line does), with each quantity's
/// runs also as arrays beside its "runs": "values" and "stds" (float64, the quantity's unit), "days"
/// (float64, days since 1970-01-01 UTC) and "run_ids" (int64), in date order.
py::object history_py(const std::string& db, const std::string& unit) {
  history::HistorySummary summary;
  nlohmann::ordered_json j;
  {
    py::gil_scoped_release release;
    summary = history::read_unit_history(db, unit);
    j = history_to_json(summary);
  }
  py::dict out = json_to_python(j);
  const auto add_arrays = [](py::dict entry, const history::QuantityHistory& q) {
    const auto n = static_cast<py::ssize_t>(q.values.size());
    py::array_t<double> values(n), stds(n), days(n);
    py::array_t<std::int64_t> ids(n);
    for (py::ssize_t i = 0; i < n; ++i) {
      const RunValue& v = q.values[static_cast<std::size_t>(i)];
      values.mutable_at(i) = v.value;
      stds.mutable_at(i) = v.std;
      days.mutable_at(i) = v.day;
      ids.mutable_at(i) = v.run_id;
    }
    entry["values"] = values;
    entry["stds"] = stds;
    entry["days"] = days;
    entry["run_ids"] = ids;
  };
  py::dict channels = out["channels"];
  for (const history::QuantityHistory& q : summary.coefficients)
    add_arrays(channels[py::str(q.channel)].cast<py::dict>()[py::str(q.name)].cast<py::dict>(), q);
  py::dict machine = out["machine_errors"];
  for (const history::QuantityHistory& q : summary.machine_errors)
    add_arrays(machine[py::str(q.name)].cast<py::dict>(), q);
  return out;
}

}  // namespace
}  // namespace gyrocal

PYBIND11_MODULE(_gyrocal, m) {
  using namespace gyrocal;
  m.doc() = "Compiled part of gyrocal; use the package gyrocal (docs/python.md).";

  // Every gyrocal::Error is a ValueError with the command line's sentence.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });

  py::class_<Scenario>(m, "Scenario",
                       "A scenario: everything a configuration file describes. Scenario() is the default "
                       "scenario; Scenario.load(path) reads a configuration (TOML).")
      .def(py::init(&default_scenario))
      // Scenario.load and Scenario.parse are these, with their arguments checked
      // (python/gyrocal/__init__.py).
      .def_static(
          "_load", [](const std::string& path) { return load_scenario(path); }, py::arg("path"),
          "Read the configuration file (TOML) at path, as --config does.")
      .def_static(
          "_parse",
          [](const std::string& text, const std::string& name) {
            // The rule load_scenario applies to a file: not empty, not beyond the configuration's limit.
            check_configuration_text(text, "Configuration " + name,
                                     "for the default scenario call gyrocal.Scenario() (a configuration of "
                                     "comments alone also gives it)");
            return parse_scenario(text, name);
          },
          py::arg("text"), py::arg("name") = "<string>",
          "Parse a configuration given as TOML text; name stands for the file in messages.")
      .def("to_toml", &scenario_to_toml,
           "The scenario as a commented configuration file (TOML), as init writes.")
      .def_property_readonly("rate_rad_s", [](const Scenario& s) { return s.centrifuge.rate_rad_s; })
      .def_property_readonly("sample_rate_hz", [](const Scenario& s) { return s.test.sample_rate_hz; })
      .def_property_readonly("seed", [](const Scenario& s) { return s.test.seed; })
      .def_property_readonly(
          "sensor_kind",
          [](const Scenario& s) {
            return s.is_imu() ? std::string("imu") : std::string(to_string(s.sensor_kind));
          },
          "[sensor] kind: \"gyro\", \"accelerometer\" or \"imu\".")
      .def_property_readonly(
          "output_column", [](const Scenario& s) { return native_output_column(s.sensor_kind); },
          "gyrocal's own output column of the scenario's sensor: gyro_deg_h (deg/h) or accel_g (g).");

  m.def("_exact_inputs", &exact_inputs_py, py::arg("scenario"), py::arg("time_s"), py::arg("beta_deg"));
  m.def("_simulate", &simulate_py, py::arg("scenario"), py::arg("seed"));
  m.def("_calibrate_path", &calibrate_path_py);
  m.def("_calibrate_arrays", &calibrate_arrays_py);
  m.def("_noise_path", &noise_path_py);
  m.def("_noise_arrays", &noise_arrays_py);
  m.def("_check_output_column", &check_output_column_py);
  m.def("_imu_columns", &imu_columns, py::arg("scenario"), py::arg("angles"));
  m.def("_calibrate_imu_path", &calibrate_imu_path_py);
  m.def("_calibrate_imu_arrays", &calibrate_imu_arrays_py);
  m.def("_noise_imu_path", &noise_imu_path_py);
  m.def("_noise_imu_arrays", &noise_imu_arrays_py);
  m.def("_history", &history_py, py::arg("db"), py::arg("unit"));
  // The functions that do not serve an IMU configuration yet refuse one with the command line's sentence.
  m.def("_refuse_imu", &refuse_imu, py::arg("scenario"), py::arg("function"));
}
