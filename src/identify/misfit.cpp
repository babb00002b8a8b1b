#include "gyrocal/identify/misfit.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/special_functions.hpp"
#include "gyrocal/core/units.hpp"

namespace gyrocal {
namespace {

/// The dwell's slot whose gamma is `gamma_rad` (modulo a turn, within 1e-6 deg), -1 if none.
int slot_of(const Dwell& d, double gamma_rad) {
  for (std::size_t k = 0; k < d.gammas_rad.size(); ++k)
    if (std::abs(wrap_deg((d.gammas_rad[k] - gamma_rad) * kRadToDeg)) < 1e-6) return static_cast<int>(k);
  return -1;
}

/// The position reduced from dwell `dwell`, slot `slot`; -1 if none.
int position_of(const Reduction& r, int dwell, int slot) {
  for (std::size_t i = 0; i < r.positions.size(); ++i)
    if (r.positions[i].dwell == dwell && r.positions[i].gamma_slot == slot) return static_cast<int>(i);
  return -1;
}

/// The reduction whose position (dwell d, slot k) holds what (dwell partner[d], slot slot_map[d][k]) held:
/// the values, standard errors and covariances moved with the outputs, the model's side (angles, rates) kept.
/// nullopt when a position has no partner, or when nothing moves.
std::optional<Reduction> permute_outputs(const Reduction& r, const std::vector<int>& partner,
                                         const std::vector<std::vector<int>>& slot_map) {
  bool moved = false;
  Reduction out = r;
  for (std::size_t d = 0; d < r.dwells.size(); ++d) {
    const int p = partner[d];
    if (p < 0) return std::nullopt;
    const DwellValues& from = r.dwells[static_cast<std::size_t>(p)].output;
    DwellValues& to = out.dwells[d].output;
    const std::vector<int>& map = slot_map[d];
    to = from;
    for (std::size_t k = 0; k < map.size(); ++k) {
      const auto m = static_cast<std::size_t>(map[k]);
      moved |= p != static_cast<int>(d) || m != k;
      if (m < from.value.size()) to.value[k] = from.value[m];
      if (m < from.std_err.size()) to.std_err[k] = from.std_err[m];
      if (static_cast<Eigen::Index>(m) < from.covariance.rows())
        for (std::size_t l = 0; l < map.size(); ++l)
          to.covariance(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(l)) =
              from.covariance(static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(map[l]));
    }
  }
  if (!moved) return std::nullopt;
  for (ReducedPosition& q : out.positions) {
    const auto d = static_cast<std::size_t>(q.dwell);
    const int src = position_of(r, partner[d], slot_map[d][static_cast<std::size_t>(q.gamma_slot)]);
    if (src < 0) return std::nullopt;
    const ReducedPosition& s = r.positions[static_cast<std::size_t>(src)];
    q.mean = s.mean;
    q.std_err = s.std_err;
    q.outliers = s.outliers;
  }
  return out;
}

/// The counter platform's angle counted the other way: the output measured at gamma belongs to -gamma.
std::optional<Reduction> mirror_gamma(const Reduction& r) {
  std::vector<int> partner(r.dwells.size());
  std::vector<std::vector<int>> slots(r.dwells.size());
  for (std::size_t d = 0; d < r.dwells.size(); ++d) {
    partner[d] = static_cast<int>(d);
    for (double g : r.dwells[d].gammas_rad) {
      const int k = slot_of(r.dwells[d], -g);
      if (k < 0) return std::nullopt;
      slots[d].push_back(k);
    }
  }
  return permute_outputs(r, partner, slots);
}

/// An accelerometer's counter platform angle counted the other way: the output at gamma belongs to -gamma in
/// each spinning dwell. A static hold is kept as it is: its gamma turns the sensor about the vertical, which
/// holds gravity, so no static output depends on it (and its -gamma partner reads the same).
std::optional<Reduction> mirror_spinning_gamma(const Reduction& r) {
  std::vector<int> partner(r.dwells.size());
  std::vector<std::vector<int>> slots(r.dwells.size());
  for (std::size_t d = 0; d < r.dwells.size(); ++d) {
    partner[d] = static_cast<int>(d);
    if (r.dwells[d].is_static) {
      for (std::size_t k = 0; k < r.dwells[d].gammas_rad.size(); ++k) slots[d].push_back(static_cast<int>(k));
      continue;
    }
    for (double g : r.dwells[d].gammas_rad) {
      const int k = slot_of(r.dwells[d], -g);
      if (k < 0) return std::nullopt;
      slots[d].push_back(k);
    }
  }
  return permute_outputs(r, partner, slots);
}

/// The position platform's angle counted the other way: the dwell measured at beta belongs to -beta.
std::optional<Reduction> mirror_beta(const Reduction& r) {
  std::vector<int> partner(r.dwells.size(), -1);
  std::vector<std::vector<int>> slots(r.dwells.size());
  for (std::size_t d = 0; d < r.dwells.size(); ++d) {
    const Dwell& a = r.dwells[d];
    for (std::size_t e = 0; e < r.dwells.size() && partner[d] < 0; ++e) {
      const Dwell& b = r.dwells[e];
      if (a.is_static != b.is_static || a.planned_rate_rad_s != b.planned_rate_rad_s ||
          a.planned_counter_rate_offset_rad_s != b.planned_counter_rate_offset_rad_s ||
          std::abs(wrap_deg((a.beta_rad + b.beta_rad) * kRadToDeg)) > 1e-6)
        continue;
      std::vector<int> map;
      for (double g : a.gammas_rad) map.push_back(slot_of(b, g));
      if (std::find(map.begin(), map.end(), -1) != map.end()) continue;
      partner[d] = static_cast<int>(e);
      slots[d] = map;
    }
  }
  return permute_outputs(r, partner, slots);
}

/// A standard error at or below `noise_free` (kGyroNoiseFreeDegH for the gyro; for an accelerometer
/// kAccelerometerNoiseFreeRelative of the record's own g) is a noise-free output's rounding, not noise.
bool without_noise(double std_err, double noise_free) {
  return !(std_err > noise_free);
}

std::string number(double v) {
  return fmt::format("{:.6g}", v);
}

}  // namespace

double misfit_p_value(double chi2, int dof, double weight_dof) {
  if (dof <= 0) return 1.0;
  if (!(chi2 >= 0.0)) return std::isnan(chi2) ? 0.0 : 1.0;
  if (std::isinf(chi2)) return 0.0;
  const double d1 = dof;
  if (!(weight_dof > 0.0) || weight_dof > 1e7) return regularized_gamma_q(0.5 * d1, 0.5 * chi2);
  const double f = chi2 / d1;
  return regularized_beta(0.5 * weight_dof, 0.5 * d1, weight_dof / (weight_dof + d1 * f));
}

double weight_dof(const Reduction& reduction) {
  double sum = 0.0;
  bool measured = false;
  for (const Dwell& d : reduction.dwells)
    if (std::isfinite(d.output.dof) && d.output.dof > 0.0) {
      sum += d.output.dof;
      measured = true;
    }
  return measured ? sum : std::numeric_limits<double>::infinity();
}

MisfitTest test_misfit(const Reduction& reduction, double chi2, int dof, double noise_free) {
  MisfitTest t;
  t.chi2 = chi2;
  t.dof = dof;
  t.weight_dof = weight_dof(reduction);
  const bool measured =
      std::any_of(reduction.positions.begin(), reduction.positions.end(),
                  [&](const ReducedPosition& p) { return !without_noise(p.std_err, noise_free); });
  // A prediction's covariance is known (its outputs are noise-free by construction): nothing to test.
  t.tested = measured && dof > 0 && std::isfinite(t.weight_dof);
  t.p_value = t.tested ? misfit_p_value(chi2, dof, t.weight_dof) : 1.0;
  return t;
}

Reduction scale_outputs(const Reduction& reduction, double factor) {
  Reduction out = reduction;
  const double a = std::abs(factor);
  for (ReducedPosition& p : out.positions) {
    p.mean *= factor;
    p.std_err *= a;
  }
  for (Dwell& d : out.dwells) {
    for (double& v : d.output.value) v *= factor;
    for (double& v : d.output.std_err) v *= a;
    d.output.covariance *= factor * factor;
    d.output.level *= factor * factor;
  }
  return out;
}

std::vector<MisfitCause> gyro_misfit_causes(const OutputConfiguration& output) {
  std::vector<MisfitCause> causes;
  const double s = output.scale;
  const std::string key = "[record] " + output.scale_key;
  // Each unit as output units per deg/h: a record written in it reads right with that scale.
  struct Unit {
    const char* name;
    double per_deg_h;
  };
  static const Unit kUnits[] = {
      {"deg/h", 1.0}, {"deg/s", 1.0 / 3600.0}, {"rad/s", kDegToRad / 3600.0}, {"rad/h", kDegToRad}};
  const auto same = [](double a, double b) { return std::abs(a - b) <= 1e-9 * std::abs(b); };
  const auto add = [&](std::string name, double scale, std::string what) {
    for (const MisfitCause& c : causes)
      if (c.name == name) return;
    const double k = s / scale;  // the reduced output times k is what the scale `scale` would have read
    causes.push_back({std::move(name),
                      [k](const Reduction& r) -> std::optional<Reduction> { return scale_outputs(r, k); },
                      fmt::format("{}: set {} = {} (it is {})", what, key, number(scale), number(s))});
  };
  add("sign", -s, "the output's sign is flipped (a cable, or the sensor's sign convention)");
  for (const Unit& u : kUnits)
    for (double sign : {1.0, -1.0}) {
      const double c = sign * u.per_deg_h;
      if (same(c, s) || same(c, -s)) continue;
      add(fmt::format("unit {}{}", sign < 0 ? "-" : "", u.name), c,
          fmt::format("the output is in {}{}, not in the unit the configuration says", u.name,
                      sign < 0 ? " with its sign flipped" : ""));
    }
  causes.push_back(
      {"gamma counted the other way", mirror_gamma,
       "the output at gamma belongs to -gamma: the counter platform's angle is counted the other "
       "way than gyrocal's (docs/physics.md section 2): negate the record's counter angle column "
       "([record] counter_angle_column), or check its wiring"});
  causes.push_back(
      {"beta counted the other way", mirror_beta,
       "the output at beta belongs to -beta: the position platform's angle is counted the other "
       "way than gyrocal's (docs/physics.md section 2): negate the record's position angle column "
       "([record] position_angle_column), or check its wiring"});
  return causes;
}

std::vector<MisfitCause> accelerometer_misfit_causes() {
  std::vector<MisfitCause> causes;
  for (MisfitCause& c : gyro_misfit_causes(OutputConfiguration{}))
    if (c.name.find("counted the other way") != std::string::npos) causes.push_back(std::move(c));
  // The static holds kept: each is a dwell of its own at one gamma, which the gyro's mirror cannot pair.
  causes.front().transform = mirror_spinning_gamma;
  return causes;
}

void refuse_constant_output(const Reduction& reduction, const OutputConfiguration& output, double noise_free,
                            SensorKind sensor) {
  if (reduction.positions.size() < 2) return;
  const double v0 = reduction.positions.front().mean;
  bool constant = true;
  double largest = 0.0;
  for (const ReducedPosition& p : reduction.positions) {
    if (!without_noise(p.std_err, noise_free)) return;
    // Constant relative to the values' own magnitude: outputs of 1e-299 deg/h that differ by a third between
    // positions vary (a scale wrong by 1e300), and were called constant against an absolute 1e-9.
    if (!(std::abs(p.mean - v0) <= 1e-9 * std::max(std::abs(v0), std::abs(p.mean)))) constant = false;
    largest = std::max(largest, std::abs(p.mean));
  }
  if (constant && sensor != SensorKind::kGyro)
    throw Error(fmt::format(
        "the {} output is the constant {} (as read: {} = {}) at every one of the {} positions, with no "
        "scatter at all: a dead or disconnected sensor (or a [record] output_column that names a column "
        "that does not change); nothing can be calibrated from it.",
        to_string(sensor), number(v0), output.scale_key, number(output.scale), reduction.positions.size()));
  if (constant)
    throw Error(fmt::format(
        "the gyro output is the constant {} deg/h at every one of the {} positions, with no scatter at all: "
        "a "
        "dead or disconnected sensor (or a [record] output_column that names a column that does not change; "
        "{} = {}); nothing can be calibrated from it.",
        number(v0), reduction.positions.size(), output.scale_key, number(output.scale)));
  // Outputs that vary, without scatter, all below 1e-150 deg/h: their squares (below 1e-300) leave a double's
  // range at its small end, so the scatter between revolutions reads 0; no gyro's output is that small.
  constexpr double kSquaresUnderflow = 1e-150;
  if (largest < kSquaresUnderflow)
    throw Error(
        fmt::format("the gyro output varies between the {} positions but never exceeds {} deg/h in "
                    "magnitude: its scatter "
                    "between revolutions underflows a double (its squares fall below 1e-300), and no gyro's "
                    "output is that "
                    "small; is the output's scale right ({} = {})?",
                    reduction.positions.size(), number(largest), output.scale_key, number(output.scale)));
}

void OutputRange::push(double value) {
  if (!std::isfinite(value)) return;
  ++count_;
  if (value > max_) max_ = value, at_max_ = 0;
  if (value < min_) min_ = value, at_min_ = 0;
  if (value == max_) ++at_max_;
  if (value == min_) ++at_min_;
}

std::string saturation_cause(const Reduction& reduction, const OutputRange& range, std::string_view unit,
                             std::string_view sensor) {
  const auto many = [&](std::size_t n) {
    return n >= 10 && static_cast<double>(n) > 0.005 * static_cast<double>(range.count());
  };
  if (range.count() > 0 && range.max() > range.min() && (many(range.at_max()) || many(range.at_min()))) {
    const bool top = range.at_max() >= range.at_min();
    const std::size_t n = top ? range.at_max() : range.at_min();
    return fmt::format(
        "{} of the record's {} samples ({:.1f} %) sit exactly at its {} output, {} {}, which noise never "
        "does: a saturated or clipped channel (a flat top); use a range of the {} and its acquisition that "
        "holds the largest output",
        n, range.count(), 100.0 * static_cast<double>(n) / static_cast<double>(range.count()),
        top ? "largest" : "smallest", number(top ? range.max() : range.min()), unit, sensor);
  }
  const auto where = [&](std::size_t d) {
    const Dwell& w = reduction.dwells[d];
    return fmt::format("the {} at {:g} rad/s, beta {:g} deg (record time {:g} s to {:g} s)",
                       w.is_static ? "static hold" : "dwell", w.planned_rate_rad_s, w.beta_rad * kRadToDeg,
                       w.first_time_s, w.last_time_s);
  };
  std::size_t worst = reduction.dwells.size();
  double worst_fraction = 0.05;
  for (std::size_t d = 0; d < reduction.dwells.size(); ++d) {
    const Dwell& w = reduction.dwells[d];
    if (w.samples == 0) continue;
    const double fraction = static_cast<double>(w.output.outliers) / static_cast<double>(w.samples);
    if (fraction > worst_fraction) worst = d, worst_fraction = fraction;
  }
  if (worst < reduction.dwells.size())
    return fmt::format(
        "{:.0f} % of the samples of {} were rejected as outliers, which spikes never do: a saturated or "
        "clipped channel (flat tops cut off the output); use a range of the {} and its acquisition that "
        "holds the largest output",
        100.0 * worst_fraction, where(worst), sensor);
  return {};
}

}  // namespace gyrocal
