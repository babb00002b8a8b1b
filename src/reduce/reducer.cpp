#include "gyrocal/reduce/reducer.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/plan/positions.hpp"
#include "gyrocal/reduce/feasibility.hpp"

namespace gyrocal {
namespace {

double wrap_deg(double a) {
  return std::remainder(a, 360.0);
}

/// Straight-line fit of y against t, streaming, on deviations from a planned line (well conditioned).
struct LineSums {
  double n = 0, t = 0, tt = 0, y = 0, ty = 0, yy = 0;
  void add(double ti, double yi) {
    n += 1;
    t += ti;
    tt += ti * ti;
    y += yi;
    ty += ti * yi;
    yy += yi * yi;
  }
  /// Intercept at t = 0, slope, RMS residual.
  void fit(double& intercept, double& slope, double& rms) const {
    const double tbar = t / n, ybar = y / n;
    const double stt = tt - n * tbar * tbar, sty = ty - n * tbar * ybar, syy = yy - n * ybar * ybar;
    slope = stt > 0 ? sty / stt : 0.0;
    intercept = ybar - slope * tbar;
    rms = std::sqrt(std::max(syy - slope * sty, 0.0) / n);
  }
};

/// The run in progress: consecutive samples at one steady state of the machine.
struct Run {
  bool is_static = false;
  double planned_rate = 0.0;    // rad/s
  double planned_offset = 0.0;  // counter rate offset, rad/s (docs/physics.md section 15)
  double beta0_deg = 0.0;       // encoder at the run's start
  double psi0_deg = 0.0;        // unwrapped counter encoder at the run's start (static holds)
  double t_start = 0.0;
  double planned_duration = 0.0;
  std::optional<DwellAccumulator> acc;
  // The measured part.
  bool measuring = false;
  double t_first = 0.0, theta_first_deg = 0.0, psi_first_deg = 0.0;
  LineSums theta, psi;
  double beta_sum = 0.0;
  std::size_t n = 0;
  double t_prev = 0.0;   // the previous measured sample
  std::size_t gaps = 0;  // intervals between measured samples longer than 1.5 planned sample intervals
};

/// The rate at which the platform's heading sweeps the Earth rate through a spinning dwell at a counter rate
/// offset (docs/physics.md section 15); 0 without an offset, and at rate 0, where the heading turns with
/// gamma.
double heading_sweep_rad_s(double rate_rad_s, double offset_rad_s) {
  return rate_rad_s != 0.0 ? offset_rad_s : 0.0;
}

}  // namespace

struct Reducer::State {
  TestSpec plan;
  ReduceOptions options;
  std::string source;
  double reference_rate;
  std::size_t samples = 0;
  double t_prev = 0.0, theta_raw_prev = 0.0, psi_raw_prev = 0.0;
  double theta_u = 0.0, psi_u = 0.0;  // unwrapped, deg
  std::optional<Run> run;
  std::vector<Dwell> dwells;
  std::vector<std::string> warnings;
  int short_runs = 0;

  double hold_duration() const { return plan.revolutions * 2.0 * kPi / std::abs(reference_rate); }

  std::string at(double t) const { return fmt::format("{}: at t = {:.6f} s", source, t); }

  /// The plan's (rate, counter rate offset) matching a sample-to-sample rate, if the machine is steady at
  /// one: the main axis at the rate, the platform's heading (theta + psi_r) turning at the offset
  /// (docs/physics.md section 15; at rate 0 and offset 0 both stopped).
  std::optional<std::pair<double, double>> steady_rate(double theta_rate, double psi_rate) const {
    const double tol0 = options.static_rate_tolerance_rad_s;
    for (double r : plan.rates_rad_s)
      for (double o : plan.counter_rate_offsets_rad_s) {
        if (r == 0.0 && o == 0.0) {
          if (std::abs(theta_rate) < tol0 && std::abs(psi_rate) < tol0) return std::make_pair(r, o);
        } else {
          const double tol = options.rate_tolerance * std::max(std::abs(r), std::abs(o));
          const bool main_steady = r == 0.0 ? std::abs(theta_rate) < tol0 : std::abs(theta_rate - r) <= tol;
          if (main_steady && std::abs(psi_rate + theta_rate - o) <= tol) return std::make_pair(r, o);
        }
      }
    return std::nullopt;
  }

  void start_run(std::pair<double, double> rate_offset, double t_start, double beta_deg) {
    const auto [rate, offset] = rate_offset;
    Run r;
    r.is_static = rate == 0.0 && offset == 0.0;
    r.planned_rate = rate;
    r.planned_offset = offset;
    r.beta0_deg = beta_deg;
    r.psi0_deg = psi_u;
    r.t_start = t_start;
    // A spinning dwell: whole revolutions of gamma, which turns at rate - offset (docs/physics.md section
    // 15).
    r.planned_duration =
        r.is_static ? hold_duration() : plan.revolutions * 2.0 * kPi / std::abs(rate - offset);
    r.acc.emplace(options, r.is_static ? std::vector<double>{0.0} : plan.gamma_rad, r.is_static, 1,
                  r.planned_duration, true, heading_sweep_rad_s(rate, offset));
    run = std::move(r);
  }

  void measure(const RecordSample& s) {
    Run& r = *run;
    if (s.time_s < r.t_start + plan.settle_s) return;
    // The plan says how long a dwell is: its measured part is [t_first, t_first + planned duration).
    if (r.measuring && s.time_s >= r.t_first + r.planned_duration - 1e-9) return;
    if (!r.measuring) {
      r.measuring = true;
      r.t_first = s.time_s;
      r.theta_first_deg = theta_u;
      r.psi_first_deg = psi_u;
    }
    const double tt = s.time_s - r.t_first;
    const double planned_turn_deg = r.planned_rate * kRadToDeg * tt;
    r.theta.add(tt, theta_u - r.theta_first_deg - planned_turn_deg);
    r.psi.add(tt, psi_u - r.psi_first_deg + planned_turn_deg - r.planned_offset * kRadToDeg * tt);
    r.beta_sum += s.position_angle_deg;
    if (r.n > 0 && (s.time_s - r.t_prev) * plan.sample_rate_hz > 1.5) ++r.gaps;
    r.t_prev = s.time_s;
    ++r.n;
    const double gamma = -psi_u * kDegToRad;
    r.acc->add(s.time_s, gamma, &s.gyro_deg_h);
  }

  void end_run() {
    if (!run) return;
    Run r = std::move(*run);
    run.reset();
    const bool long_enough =
        r.n >= 2 && (r.is_static ? r.n >= static_cast<std::size_t>(2 * options.static_batches)
                                 : r.acc->complete_revolutions() >= 1);
    if (!long_enough) {
      if (r.n > 0) ++short_runs;
      return;
    }
    Dwell d;
    d.is_static = r.is_static;
    d.planned_rate_rad_s = r.planned_rate;
    d.planned_counter_rate_offset_rad_s = r.planned_offset;
    d.measured_beta_rad = r.beta_sum / static_cast<double>(r.n) * kDegToRad;
    d.beta_rad = d.measured_beta_rad;
    d.first_time_s = r.acc->first_time_s();
    d.last_time_s = r.acc->last_time_s();
    d.samples = r.n;
    d.gaps = r.gaps;
    d.sample_interval_s = (d.last_time_s - d.first_time_s) / static_cast<double>(r.n - 1);
    d.planned_duration_s = r.planned_duration;
    double a, b, rms;
    r.theta.fit(a, b, rms);
    d.main = {(r.theta_first_deg + a) * kDegToRad, r.planned_rate + b * kDegToRad, rms * kDegToRad};
    r.psi.fit(a, b, rms);
    d.counter = {(r.psi_first_deg + a) * kDegToRad, -r.planned_rate + r.planned_offset + b * kDegToRad,
                 rms * kDegToRad};

    // Match to the plan.
    const double beta_deg = d.beta_rad * kRadToDeg;
    std::optional<double> beta_plan;
    for (double b_plan : plan.beta_rad)
      if (std::abs(wrap_deg(beta_deg - b_plan * kRadToDeg)) <= options.beta_tolerance_deg) beta_plan = b_plan;
    const std::string what =
        d.is_static
            ? fmt::format("static hold at beta {:.4f} deg, gamma {:.4f} deg", beta_deg, wrap_deg(-r.psi0_deg))
        : r.planned_offset != 0.0
            ? fmt::format("dwell at {} rad/s, counter rate offset {} rad/s, beta {:.4f} deg",
                          d.planned_rate_rad_s, r.planned_offset, beta_deg)
            : fmt::format("dwell at {} rad/s, beta {:.4f} deg", d.planned_rate_rad_s, beta_deg);
    if (!beta_plan) {
      warnings.push_back(fmt::format("{}: {} matches no planned beta; ignored.", at(d.first_time_s), what));
      return;
    }
    d.beta_rad = *beta_plan;
    if (d.is_static) {
      std::optional<double> gamma_plan;
      for (double g : plan.gamma_rad)
        if (std::abs(wrap_deg(-r.psi0_deg - g * kRadToDeg)) <= options.beta_tolerance_deg) gamma_plan = g;
      if (!gamma_plan) {
        warnings.push_back(
            fmt::format("{}: {} matches no planned gamma; ignored.", at(d.first_time_s), what));
        return;
      }
      d.gammas_rad = {*gamma_plan};
    } else {
      d.gammas_rad = plan.gamma_rad;
    }
    d.gyro = r.acc->finish(0);
    // docs/physics.md section 14: a dwell that loses many samples is warned about (1 % is far above the rate
    // at which clean noise reaches the rule's threshold).
    if (static_cast<double>(d.gyro.outliers) > 0.01 * static_cast<double>(d.samples))
      warnings.push_back(fmt::format(
          "{}: {}: {} of its {} samples ({:.1f} %) were rejected as outliers (beyond {} robust standard "
          "deviations of the dwell's fit) and replaced by the fit.",
          at(d.first_time_s), what, d.gyro.outliers, d.samples,
          100.0 * static_cast<double>(d.gyro.outliers) / static_cast<double>(d.samples),
          options.outlier_threshold));
    // Checks a test engineer wants to hear about.
    const double measured = d.last_time_s - d.first_time_s + d.sample_interval_s;
    if (measured < d.planned_duration_s - 2.0 * d.sample_interval_s) {
      warnings.push_back(fmt::format("{}: {} lasted {:.3f} s of the {:.3f} s planned ({} revolutions).",
                                     at(d.first_time_s), what, measured, d.planned_duration_s,
                                     plan.revolutions));
    }
    if (d.main.rms_residual_rad > 0.01 * kDegToRad || d.counter.rms_residual_rad > 0.01 * kDegToRad) {
      warnings.push_back(fmt::format(
          "{}: the rate wanders during the {}: encoder angles leave a constant-rate line by {:.4f} deg RMS.",
          at(d.first_time_s), what,
          std::max(d.main.rms_residual_rad, d.counter.rms_residual_rad) * kRadToDeg));
    }
    if (!d.is_static && d.planned_rate_rad_s != 0.0 &&
        std::abs(d.main.rate_rad_s - d.planned_rate_rad_s) >
            options.rate_tolerance * 0.1 * std::abs(d.planned_rate_rad_s)) {
      warnings.push_back(
          fmt::format("{}: {}: the main axis turned at {:.9f} rad/s, not the planned {} rad/s.",
                      at(d.first_time_s), what, d.main.rate_rad_s, d.planned_rate_rad_s));
    }
    dwells.push_back(std::move(d));
  }
};

Reducer::Reducer(const TestSpec& plan, const ReduceOptions& options, std::string source_name,
                 double reference_rate_rad_s)
    : state_(std::make_unique<State>()) {
  std::string error;
  if (!options.IsValid(&error)) throw Error("reduction options: " + error + ".");
  state_->plan = plan;
  state_->options = options;
  state_->source = std::move(source_name);
  state_->reference_rate = reference_rate_rad_s;
  for (double r : plan.rates_rad_s)
    if (r != 0.0) {
      state_->reference_rate = r;
      break;
    }
  if (state_->reference_rate == 0.0)
    throw Error("the plan has no non-zero rate and no reference rate to size the static holds.");
  check_test_feasible(plan, options, state_->reference_rate);
}

Reducer::~Reducer() = default;

void Reducer::push(const RecordSample& s) {
  State& st = *state_;
  if (st.samples == 0) {
    st.theta_raw_prev = s.main_angle_deg;
    st.psi_raw_prev = s.counter_angle_deg;
    st.theta_u = s.main_angle_deg;
    st.psi_u = s.counter_angle_deg;
    st.t_prev = s.time_s;
    ++st.samples;
    return;
  }
  const double dt = s.time_s - st.t_prev;
  const double dtheta = wrap_deg(s.main_angle_deg - st.theta_raw_prev);
  const double dpsi = wrap_deg(s.counter_angle_deg - st.psi_raw_prev);
  if (!(dt > 0.0)) throw Error(fmt::format("{}: time does not increase.", st.at(s.time_s)));
  st.theta_u += dtheta;
  st.psi_u += dpsi;
  st.theta_raw_prev = s.main_angle_deg;
  st.psi_raw_prev = s.counter_angle_deg;
  const double theta_rate = dtheta / dt * kDegToRad, psi_rate = dpsi / dt * kDegToRad;
  const std::optional<std::pair<double, double>> rate = st.steady_rate(theta_rate, psi_rate);

  if (st.run) {
    const Run& r = *st.run;
    const bool same =
        rate && rate->first == r.planned_rate && rate->second == r.planned_offset &&
        std::abs(wrap_deg(s.position_angle_deg - r.beta0_deg)) <= st.options.beta_tolerance_deg &&
        (!r.is_static || std::abs(st.psi_u - r.psi0_deg) <= st.options.beta_tolerance_deg);
    if (!same) st.end_run();
  }
  if (!st.run && rate) st.start_run(*rate, st.t_prev, s.position_angle_deg);
  if (st.run) st.measure(s);
  st.t_prev = s.time_s;
  ++st.samples;
}

Reduction Reducer::finish() {
  State& st = *state_;
  st.end_run();
  Reduction out;
  out.samples_read = st.samples;
  out.warnings = st.warnings;
  // One dwell per (rate, beta) or (0, beta, gamma): the longest if the record has several.
  // The key of a dwell: rate, counter rate offset (docs/physics.md section 15), beta and a hold's gamma.
  std::map<std::tuple<double, double, double, double>, int> chosen;
  for (std::size_t i = 0; i < st.dwells.size(); ++i) {
    const Dwell& d = st.dwells[i];
    const auto key = std::make_tuple(d.planned_rate_rad_s, d.planned_counter_rate_offset_rad_s, d.beta_rad,
                                     d.is_static ? d.gammas_rad[0] : 0.0);
    auto it = chosen.find(key);
    if (it == chosen.end()) {
      chosen[key] = static_cast<int>(i);
    } else {
      out.warnings.push_back(
          fmt::format("{}: the record repeats the dwell at {} rad/s, beta {:.4f} deg; the "
                      "longer one is used.",
                      st.source, d.planned_rate_rad_s, d.beta_rad * kRadToDeg));
      if (d.samples > st.dwells[it->second].samples) it->second = static_cast<int>(i);
    }
  }
  std::vector<int> in_time_order;
  for (const auto& [key, i] : chosen) in_time_order.push_back(i);
  std::sort(in_time_order.begin(), in_time_order.end());
  std::map<int, int> renumber;
  for (int i : in_time_order) {
    renumber[i] = static_cast<int>(out.dwells.size());
    out.dwells.push_back(st.dwells[static_cast<std::size_t>(i)]);
    out.samples_used += out.dwells.back().samples;
    out.outliers += out.dwells.back().gyro.outliers;
    out.gaps += out.dwells.back().gaps;
  }
  std::vector<std::string> missing;
  for (const Position& p : test_positions(st.plan)) {
    const bool is_static = p.rate_rad_s == 0.0 && p.counter_rate_offset_rad_s == 0.0;
    const auto key =
        std::make_tuple(p.rate_rad_s, p.counter_rate_offset_rad_s, p.beta_rad, is_static ? p.gamma_rad : 0.0);
    const auto it = chosen.find(key);
    if (it == chosen.end()) {
      missing.push_back(
          fmt::format("{} (rate {} rad/s, {}beta {} deg, gamma {} deg)", p.index, p.rate_rad_s,
                      p.counter_rate_offset_rad_s != 0.0
                          ? fmt::format("counter rate offset {} rad/s, ", p.counter_rate_offset_rad_s)
                          : std::string(),
                      p.beta_rad * kRadToDeg, p.gamma_rad * kRadToDeg));
      continue;
    }
    const int di = renumber[it->second];
    out.positions.push_back(reduced_position(p, out.dwells[static_cast<std::size_t>(di)], di));
  }
  if (!missing.empty()) {
    std::string list;
    for (std::size_t i = 0; i < missing.size() && i < 4; ++i) list += (i ? "; " : "") + missing[i];
    if (missing.size() > 4) list += fmt::format("; and {} more", missing.size() - 4);
    throw Error(fmt::format("{}: the record has no usable dwell for {} planned position{}: {}.", st.source,
                            missing.size(), missing.size() > 1 ? "s" : "", list));
  }
  if (st.short_runs > 0)
    out.warnings.push_back(
        fmt::format("{}: {} steady segment{} shorter than one revolution (or hold) were "
                    "skipped as transitions.",
                    st.source, st.short_runs, st.short_runs > 1 ? "s" : ""));
  // A standard error is the scatter between revolutions (or batches) about a line: without a degree of
  // freedom left there is no measurement of the noise, and no number may stand in for one
  // (docs/calibration.md, "Degrees of freedom").
  int zero = 0;
  for (const Dwell& d : out.dwells) {
    if (d.gyro.dof > 0.0) continue;
    // The scatter is about a mean (and a drift), and at a counter rate offset also the heading's sweep.
    const int needed =
        d.is_static
            ? 2
            : (st.options.linear_drift ? 3 : 2) +
                  (heading_sweep_rad_s(d.planned_rate_rad_s, d.planned_counter_rate_offset_rad_s) != 0.0 ? 2
                                                                                                         : 0);
    throw Error(fmt::format(
        "{}: at t = {:.6f} s the {} at {} rad/s, beta {:.4f} deg has {} complete {}, too few for a standard "
        "error from the scatter between them; it needs at least {}{}.",
        st.source, d.first_time_s, d.is_static ? "static hold" : "dwell", d.planned_rate_rad_s,
        d.beta_rad * kRadToDeg, d.gyro.revolutions, d.is_static ? "batches" : "revolutions", needed,
        d.is_static ? ""
        : st.options.method == ReduceOptions::Method::kWindowMean
            ? ": raise [test] revolutions (window means count a revolution only when it passes through every "
              "window, so a dwell's first or last may not count)"
            : fmt::format(" ([test] revolutions = {} or more)", needed)));
  }
  for (const ReducedPosition& p : out.positions)
    if (p.std_err_deg_h == 0.0) ++zero;
  if (zero > 0)
    out.warnings.push_back(
        fmt::format("{}: {} position{} show no scatter at all between revolutions: a "
                    "noise-free record, whose uncertainties mean nothing.",
                    st.source, zero, zero > 1 ? "s" : ""));
  return out;
}

ReducedPosition reduced_position(const Position& p, const Dwell& d, int dwell_index) {
  int slot = 0;
  for (std::size_t k = 0; k < d.gammas_rad.size(); ++k)
    if (d.gammas_rad[k] == p.gamma_rad) slot = static_cast<int>(k);
  const auto k = static_cast<std::size_t>(slot);
  ReducedPosition rp;
  rp.index = p.index;
  rp.rate_rad_s = p.rate_rad_s;
  rp.beta_rad = p.beta_rad;
  rp.gamma_rad = p.gamma_rad;
  rp.counter_rate_offset_rad_s = p.counter_rate_offset_rad_s;
  rp.mean_deg_h = d.gyro.value[k];
  rp.std_err_deg_h = d.gyro.std_err[k];
  rp.samples = d.gyro.samples[k];
  rp.outliers = d.gyro.outliers;
  rp.dwell = dwell_index;
  rp.gamma_slot = slot;
  return rp;
}

Reduction reduce_record(RecordReader& reader, const TestSpec& plan, const ReduceOptions& options,
                        double reference_rate_rad_s) {
  Reducer reducer(plan, options, reader.name(), reference_rate_rad_s);
  RecordSample s;
  while (reader.next(s)) reducer.push(s);
  return reducer.finish();
}

}  // namespace gyrocal
