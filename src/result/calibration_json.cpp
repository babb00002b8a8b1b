#include "gyrocal/result/calibration_json.hpp"

#include <cmath>

#include "gyrocal/plan/positions.hpp"

#include "result_parts.hpp"

namespace gyrocal {
namespace {

nlohmann::ordered_json number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
}

/// {name, value, std, unit} and, for a combination, the coefficients on dF..dOS it was estimated with.
nlohmann::ordered_json named_estimate_to_json(const NamedEstimate& c) {
  nlohmann::ordered_json j = {
      {"name", c.name}, {"value", number_or_null(c.value)}, {"std", number_or_null(c.std)}, {"unit", c.unit}};
  if (!c.coefficients.empty()) j["coefficients"] = c.coefficients;
  return j;
}

}  // namespace

nlohmann::ordered_json coefficients_to_json(const std::vector<CoefficientEstimate>& estimates) {
  nlohmann::ordered_json coefficients = nlohmann::ordered_json::object();
  // The sensor's own table's coefficients (docs/contract.md, "Result" and "Accelerometers"): the gyro's ten,
  // with drift+rate its rate errors too (docs/physics.md section 15), each with the reason where it is not
  // identifiable; an accelerometer's K1 as fitted on the record's output, in its units per g.
  for (const CoefficientEstimate& c : estimates) {
    coefficients[c.name] = {
        {"value", c.identifiable ? number_or_null(c.value) : nlohmann::ordered_json(nullptr)},
        {"std", c.identifiable ? number_or_null(c.std) : nlohmann::ordered_json(nullptr)},
        {"unit", c.unit},
        {"identifiable", c.identifiable}};
    if (!c.identifiable && !c.reason.empty()) coefficients[c.name]["reason"] = c.reason;
  }
  return coefficients;
}

nlohmann::ordered_json positions_to_json(const std::vector<ReducedPosition>& positions,
                                         const std::vector<double>& residuals, SensorKind sensor,
                                         const std::string& channel) {
  // Positions keyed for any sensor (docs/contract.md, "Result"): mean, std_err and residual in `unit`, the
  // sensor's output unit as the reader gives it (deg/h, g). A lone gyro's also keep their earlier keys
  // mean_deg_h, std_err_deg_h and residual_deg_h for one version, for readers of older results.
  const bool gyro = sensor == SensorKind::kGyro;
  const bool old_keys = gyro && channel.empty();
  const std::string position_unit = gyro ? "deg/h" : std::string(Accelerometer::output_unit);
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const ReducedPosition& p = positions[i];
    nlohmann::ordered_json e;
    if (!channel.empty()) e["channel"] = channel;
    e["index"] = p.index;
    e["beta_deg"] = p.beta_rad * kRadToDeg;
    e["gamma_deg"] = p.gamma_rad * kRadToDeg;
    e["rate_rad_s"] = p.rate_rad_s;
    e["mean"] = p.mean;
    e["std_err"] = number_or_null(p.std_err);
    e["unit"] = position_unit;
    if (old_keys) {
      e["mean_deg_h"] = p.mean;
      e["std_err_deg_h"] = number_or_null(p.std_err);
    }
    e["samples"] = p.samples;
    e["outliers"] = p.outliers;
    if (p.counter_rate_offset_rad_s != 0.0) e["counter_rate_offset_rad_s"] = p.counter_rate_offset_rad_s;
    if (i < residuals.size()) {
      e["residual"] = number_or_null(residuals[i]);
      if (old_keys) e["residual_deg_h"] = number_or_null(residuals[i]);
    }
    out.push_back(e);
  }
  return out;
}

nlohmann::ordered_json misfit_to_json(const MisfitTest& misfit) {
  // The misfit test (docs/calibration.md, "When the residuals misfit"): std_scale multiplied every std.
  return {{"tested", misfit.tested},
          {"p_value", misfit.tested ? number_or_null(misfit.p_value) : nlohmann::ordered_json(nullptr)},
          {"weight_dof", number_or_null(misfit.weight_dof)},
          {"std_scale", misfit.scale}};
}

nlohmann::ordered_json data_quality_to_json(const DataQuality& q) {
  nlohmann::ordered_json j = {{"rows_read", q.rows_read},
                              {"rows_used", q.rows_used},
                              {"outliers", q.outliers},
                              {"gaps", q.gaps},
                              {"encoder_glitch_rows", q.encoder_glitch_rows}};
  // Only for a record with an increment column: a lone sensor's result stays as it was.
  if (q.increments_dropped) j["increments_dropped"] = *q.increments_dropped;
  nlohmann::ordered_json dwells = nlohmann::ordered_json::array(), rejected = nlohmann::ordered_json::array();
  for (const DataQuality::Dwell& d : q.dwells) {
    nlohmann::ordered_json j_d = {{"static", d.is_static},
                                  {"rate_rad_s", d.rate_rad_s},
                                  {"measured_rate_rad_s", d.measured_rate_rad_s},
                                  {"beta_deg", d.beta_deg},
                                  {"start_s", d.start_s},
                                  {"end_s", d.end_s},
                                  {"rows", d.rows},
                                  {"rows_used", d.rows_used},
                                  {"dropped",
                                   {{"settle", d.settle_rows},
                                    {"beyond_planned", d.beyond_planned_rows},
                                    {"encoder_glitches", d.encoder_glitch_rows},
                                    {"before_leaving", d.before_leaving_rows},
                                    {"outliers", d.outliers}}},
                                  {"gaps", d.gaps},
                                  {"ended", d.ended}};
    if (d.is_static) j_d["gamma_deg"] = d.gamma_deg;
    dwells.push_back(std::move(j_d));
  }
  for (const DataQuality::Rejected& x : q.rejected)
    rejected.push_back({{"start_s", x.start_s}, {"end_s", x.end_s}, {"reason", x.reason}});
  j["dwells"] = std::move(dwells);
  j["rejected"] = std::move(rejected);
  return j;
}

nlohmann::ordered_json machine_errors_to_json(const std::vector<MachineErrorEstimate>& estimates) {
  // The self-calibration's estimated machine errors (docs/contract.md, machine_errors).
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const MachineErrorEstimate& e : estimates) {
    nlohmann::ordered_json m = {
        {"error", e.error},
        {"harmonic", e.harmonic},
        {"value", e.identifiable ? number_or_null(e.value) : nlohmann::ordered_json(nullptr)},
        {"std", e.identifiable ? number_or_null(e.std) : nlohmann::ordered_json(nullptr)},
        {"unit", e.unit},
        {"configured", e.configured},
        {"identifiable", e.identifiable}};
    if (!e.part.empty()) m["part"] = e.part;
    if (!e.identifiable) m["reason"] = e.reason;
    nlohmann::ordered_json correlations = nlohmann::ordered_json::object();
    for (const auto& [name, r_value] : e.correlations)
      if (std::isfinite(r_value)) correlations[name] = r_value;
    m["correlations"] = correlations;
    out.push_back(m);
  }
  return out;
}

nlohmann::ordered_json calibration_to_json(const CalibrationResult& r) {
  nlohmann::ordered_json j;
  j["coefficients"] = coefficients_to_json(r.coefficients);
  j["combinations"] = nlohmann::ordered_json::array();
  for (const NamedEstimate& c : r.combinations) j["combinations"].push_back(named_estimate_to_json(c));
  j["alternatives"] = nlohmann::ordered_json::array();
  for (const NamedEstimate& c : r.alternatives) j["alternatives"].push_back(named_estimate_to_json(c));
  j["positions"] = positions_to_json(r.positions, r.residuals, r.sensor, "");
  j["method"] = to_string(r.method);
  j["compensation"] = to_string(r.compensation);
  if (r.sensor == SensorKind::kGyro)
    j["gyro_model"] = r.gyro_model == GyroModel::kDrift ? "drift" : "drift+rate";
  else
    j["sensor"] = std::string(to_string(r.sensor));
  j["g_level"] = r.g_level;
  j["warnings"] = r.warnings;
  j["rank"] = r.rank;
  j["condition_number"] = number_or_null(r.condition_number);
  if (r.method == Method::kClosedForm)
    j["uncertainty_amplification"] = number_or_null(r.uncertainty_amplification);
  j["chi2"] = number_or_null(r.chi2);
  j["dof"] = r.dof;
  j["misfit"] = misfit_to_json(r.misfit);
  // A record's (a prediction reads none).
  if (r.data_quality.rows_read > 0) j["data_quality"] = data_quality_to_json(r.data_quality);
  j["unidentifiable"] = r.unidentifiable;
  if (!r.machine_errors.empty()) {
    j["machine_errors"] = machine_errors_to_json(r.machine_errors);
    j["iterations"] = r.iterations;
  }
  return j;
}

nlohmann::ordered_json coefficients_to_json(const DriftCoefficients& c) {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) j[std::string(kCoefficientNames[k])] = c.values[k];
  return j;
}

nlohmann::json plan_to_json(const TestSpec& t) {
  const auto deg = [](const std::vector<double>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (double x : v) a.push_back(x * kRadToDeg);
    return a;
  };
  nlohmann::json positions = nlohmann::json::array();
  for (const Position& p : test_positions(t)) {
    nlohmann::json e = {{"index", p.index},
                        {"beta_deg", p.beta_rad * kRadToDeg},
                        {"gamma_deg", p.gamma_rad * kRadToDeg},
                        {"rate_rad_s", p.rate_rad_s}};
    if (p.counter_rate_offset_rad_s != 0.0) e["counter_rate_offset_rad_s"] = p.counter_rate_offset_rad_s;
    positions.push_back(e);
  }
  nlohmann::json j = {{"sample_rate_hz", t.sample_rate_hz},
                      {"revolutions", t.revolutions},
                      {"settle_s", t.settle_s},
                      {"beta_deg", deg(t.beta_rad)},
                      {"gamma_deg", deg(t.gamma_rad)},
                      {"rates_rad_s", t.rates_rad_s},
                      {"positions", positions}};
  if (t.counter_rate_offsets_rad_s != std::vector<double>{0.0})
    j["counter_rate_offsets_rad_s"] = t.counter_rate_offsets_rad_s;
  return j;
}

}  // namespace gyrocal
