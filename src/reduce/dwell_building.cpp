#include "reducer_state.hpp"

// Dwell building (reduce/reducer_state.hpp): a run ended into a dwell (its lines, phases, measured motion
// and the accumulator's values) or into a rejected run with its reason; a repeated dwell kept or replaced.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/plan/positions.hpp"
#include "gyrocal/reduce/feasibility.hpp"

namespace gyrocal {

void Reducer::State::reject(const Run& r, std::string reason) {
  RejectedRun x;
  x.start_s = r.start_s;
  x.end_s = r.end_s;
  x.main_rate_rad_s = r.rate_theta * kDegToRad;
  x.counter_rate_rad_s = r.rate_psi * kDegToRad;
  x.beta_deg = r.beta_deg;
  x.gamma_deg = r.gamma_deg;
  x.is_static = std::abs(r.rate_theta) * kDegToRad < options.static_rate_tolerance_rad_s &&
                std::abs(r.rate_psi) * kDegToRad < options.static_rate_tolerance_rad_s;
  x.reason = std::move(reason);
  rejected.push_back(std::move(x));
  if (rejected.size() > kRejectedKept) {
    const auto shortest = std::min_element(
        rejected.begin(), rejected.end(),
        [](const auto& a, const auto& b) { return a.end_s - a.start_s < b.end_s - b.start_s; });
    rejected.erase(shortest);
  }
}

void Reducer::State::finish_run(Run& r) {
  if (!r.decided) {
    if (r.end_s - r.start_s < plan.settle_s)
      reject(r, fmt::format("it lasted {:.3f} s, less than its settle time of {} s: {}", r.end_s - r.start_s,
                            plan.settle_s, r.quality.ended));
    else
      reject(r, fmt::format("its rate did not hold within rate_steadiness ({:.0e}) from one {} s window to "
                            "the next after its settle time of {} s: {}",
                            options.rate_steadiness, options.window_s, plan.settle_s, r.quality.ended));
    return;
  }
  if (!r.matched) {
    reject(r, fmt::format("{} (the run ended: {})", r.match.why_not, r.quality.ended));
    return;
  }
  const bool long_enough =
      r.n >= 2 && (r.match.is_static ? r.n >= static_cast<std::size_t>(2 * options.static_batches)
                                     : r.accs.front().complete_revolutions() >= 1);
  if (!long_enough) {
    reject(r, fmt::format("it measured only {:.3f} s of the {:.3f} s planned: {}",
                          r.measuring ? r.accs.front().last_time_s() - r.t_first : 0.0, r.planned_duration,
                          r.quality.ended));
    return;
  }
  Dwell d;
  d.is_static = r.match.is_static;
  d.planned_rate_rad_s = r.match.planned_rate_rad_s;
  d.planned_counter_rate_offset_rad_s = r.match.planned_counter_rate_offset_rad_s;
  d.measured_beta_rad = r.beta_sum / static_cast<double>(r.n) * kDegToRad;
  // The model terms take the plan's beta (and a static hold's gamma): an encoder's mean reading at rest is
  // biased by up to half a count (docs/calibration.md).
  d.beta_rad = r.match.beta_rad;
  d.gammas_rad = d.is_static ? std::vector<double>{r.match.gamma_rad} : spinning_gammas(plan);
  d.first_time_s = r.accs.front().first_time_s();
  d.last_time_s = r.accs.front().last_time_s();
  d.samples = r.n;
  d.gaps = r.gaps;
  d.planned_duration_s = r.planned_duration;
  d.quality = r.quality;
  // The encoders' lines: one rate over the dwell, an intercept per phase (a gap starts one).
  double sty_t = 0, stt_t = 0, sty_p = 0, stt_p = 0, res_t = 0, res_p = 0;
  for (std::size_t k = 0; k < r.phase_theta.size(); ++k) {
    sty_t += r.phase_theta[k].sty();
    stt_t += r.phase_theta[k].stt();
    sty_p += r.phase_psi[k].sty();
    stt_p += r.phase_psi[k].stt();
  }
  // The counter platform's rate relative to the arm's (psi_r + theta, a heading drift about Up) enters
  // omega_I whole. Fitted over a few seconds of encoders quantised to 0.1 deg it carries ~1e-5 rad/s
  // (2 deg/h) of quantisation error, so it is used only where it is resolved: beyond 3 of its standard
  // errors (a noise-free record always); otherwise the platform turns at exactly minus the main rate
  // (docs/calibration.md).
  (void)sty_p;
  (void)stt_p;
  double sty_r = 0, stt_r = 0, syy_r = 0, n_r = 0;
  for (const LineSums& x : r.phase_rel) sty_r += x.sty(), stt_r += x.stt(), syy_r += x.syy(), n_r += x.n;
  const double br = stt_r > 0 ? sty_r / stt_r : 0.0;
  const double dof_r = n_r - 1.0 - static_cast<double>(r.phase_rel.size());
  const double se_r =
      dof_r > 0 && stt_r > 0 ? std::sqrt(std::max(syy_r - br * sty_r, 0.0) / dof_r / stt_r) : 0.0;
  const double bt = stt_t > 0 ? sty_t / stt_t : 0.0, bp = -bt + (std::abs(br) > 3.0 * se_r ? br : 0.0);
  for (std::size_t k = 0; k < r.phase_theta.size(); ++k) {
    res_t += std::max(r.phase_theta[k].syy() - bt * r.phase_theta[k].sty(), 0.0);
    res_p += std::max(r.phase_psi[k].syy() - bp * r.phase_psi[k].sty(), 0.0);
  }
  const double planned_deg_s = r.match.planned_rate_rad_s * kRadToDeg;
  // The counter platform turns at -rate + offset relative to the arm (docs/physics.md section 15).
  const double planned_counter_deg_s = -planned_deg_s + r.match.planned_counter_rate_offset_rad_s * kRadToDeg;
  const auto intercept = [&](const LineSums& s, double b) { return (s.y - b * s.t) / s.n; };
  const double nd = static_cast<double>(r.n);
  d.main = {(r.theta_first + intercept(r.phase_theta[0], bt)) * kDegToRad, (planned_deg_s + bt) * kDegToRad,
            std::sqrt(res_t / nd) * kDegToRad};
  d.counter = {(r.psi_first + intercept(r.phase_psi[0], bp)) * kDegToRad,
               (planned_counter_deg_s + bp) * kDegToRad, std::sqrt(res_p / nd) * kDegToRad};
  double span = 0.0;
  std::size_t steps = 0;
  for (const StretchSums& st : r.stretches) {
    TimeStretch ts;
    ts.first_time_s = st.first;
    ts.count = st.count;
    ts.interval_s = st.count > 1 ? (st.last - st.first) / static_cast<double>(st.count - 1) : dt_planned;
    const double tt = st.first - r.t_first;
    ts.main_at_first_rad =
        (r.theta_first + intercept(r.phase_theta[st.phase], bt) + (planned_deg_s + bt) * tt) * kDegToRad;
    ts.counter_at_first_rad =
        (r.psi_first + intercept(r.phase_psi[st.phase], bp) + (planned_counter_deg_s + bp) * tt) * kDegToRad;
    d.stretches.push_back(ts);
    span += st.last - st.first;
    steps += st.count - 1;
  }
  d.sample_interval_s = steps > 0 ? span / static_cast<double>(steps) : dt_planned;
  if (r.motion) {
    d.measured = r.motion->finish();
    for (const StretchSums& st : r.stretches) d.measured.stretch_phase.push_back(st.phase);
    d.basis_angle = std::move(r.basis);
    d.basis_angle.shrink_to_fit();  // held to the end: its size, not the capacity its growth left
  }
  const double beta_deg = d.beta_rad * kRadToDeg;
  const std::string what =
      d.is_static ? fmt::format("static hold at beta {:.4f} deg, gamma {:.4f} deg", beta_deg,
                                d.gammas_rad[0] * kRadToDeg)
      : d.planned_counter_rate_offset_rad_s != 0.0
          ? fmt::format("dwell at {} rad/s, counter rate offset {} rad/s, beta {:.4f} deg",
                        d.planned_rate_rad_s, d.planned_counter_rate_offset_rad_s, beta_deg)
          : fmt::format("dwell at {} rad/s, beta {:.4f} deg", d.planned_rate_rad_s, beta_deg);
  // Each output column's values, from its own accumulator: its own outliers and standard errors.
  d.output = r.accs.front().finish(0);
  std::vector<DwellValues> more;
  more.reserve(r.accs.size() - 1);
  for (std::size_t k = 1; k < r.accs.size(); ++k) more.push_back(r.accs[k].finish(0));
  // docs/physics.md section 14: a dwell that loses many samples is warned about (1 % is far above the rate
  // at which clean noise reaches the rule's threshold).
  const std::string place = fmt::format("the {} at t = {:.3f} s", what, d.first_time_s);
  for (std::size_t k = 0; k < r.accs.size(); ++k) {
    const std::size_t outliers = k == 0 ? d.output.outliers : more[k - 1].outliers;
    if (static_cast<double>(outliers) <= 0.01 * static_cast<double>(d.samples)) continue;
    const std::string column = output_names.size() > k ? fmt::format(" (output {})", output_names[k]) : "";
    warnings.add("outliers",
                 fmt::format("{}: {}: {} of its {} samples{} ({:.1f} %) were rejected as outliers (beyond {} "
                             "robust standard deviations of the dwell's fit) and left out of it.",
                             at(d.first_time_s), what, outliers, d.samples, column,
                             100.0 * static_cast<double>(outliers) / static_cast<double>(d.samples),
                             options.outlier_threshold),
                 place);
  }
  // Checks a test engineer wants to hear about.
  const double measured = d.last_time_s - d.first_time_s + d.sample_interval_s;
  if (measured < d.planned_duration_s - 2.0 * d.sample_interval_s) {
    // A static hold is planned in seconds ([test] static_hold_s), a spinning dwell in revolutions.
    const std::string planned = d.is_static && plan.static_hold_s > 0.0
                                    ? std::string("[test] static_hold_s")
                                    : fmt::format("{} revolutions", plan.revolutions);
    warnings.add("short",
                 fmt::format("{}: {} lasted {:.3f} s of the {:.3f} s planned ({}): {}.", at(d.first_time_s),
                             what, measured, d.planned_duration_s, planned, r.quality.ended),
                 place);
  }
  // A rate that wanders: the main encoder's scatter about its line beyond its white part (half the mean
  // square of successive differences: quantisation and stamp jitter), which the model terms' constant-rate
  // line does not follow.
  const double white2 =
      r.diff_n > 0 ? 0.5 * (r.diff_yy - 2.0 * bt * r.diff_yt + bt * bt * r.diff_tt) / r.diff_n : 0.0;
  const double wander_deg = std::sqrt(std::max(res_t / nd - white2, 0.0));
  if (wander_deg > options.wander_warning_deg) {
    warnings.add("wander",
                 fmt::format("{}: the rate wanders during the {}: the main encoder leaves a constant-rate "
                             "line by {:.4f} deg RMS beyond its sample-to-sample scatter.",
                             at(d.first_time_s), what, wander_deg),
                 place);
  }
  if (!d.is_static && d.planned_rate_rad_s != 0.0) {
    const double rel = std::abs(d.main.rate_rad_s - d.planned_rate_rad_s) / std::abs(d.planned_rate_rad_s);
    if (rel > 1e-4) {
      ++offset_dwells;
      worst_rate_offset = std::max(worst_rate_offset, rel);
    }
  }
  keep(std::move(d), std::move(more));
}

void Reducer::State::keep(Dwell d, std::vector<DwellValues> more) {
  const std::size_t serial = dwells_found++;
  const auto [it, first] = dwell_of_key.emplace(dwell_key(d), dwells.size());
  if (first) {
    dwells.push_back(std::move(d));
    more_outputs.push_back(std::move(more));
    dwell_serial.push_back(serial);
    return;
  }
  repeats.add("repeat",
              fmt::format("{}: the record repeats the dwell at {} rad/s, beta {:.4f} deg; the "
                          "longer one is used.",
                          source, d.planned_rate_rad_s, d.beta_rad * kRadToDeg),
              fmt::format("the dwell at {} rad/s, beta {:.4f} deg at t = {:.3f} s", d.planned_rate_rad_s,
                          d.beta_rad * kRadToDeg, d.first_time_s));
  if (d.samples > dwells[it->second].samples) {
    dwells[it->second] = std::move(d);
    more_outputs[it->second] = std::move(more);
    dwell_serial[it->second] = serial;
  }
}

std::string Reducer::State::why_missing(const Position& p) const {
  const RejectedRun* best = nullptr;
  int best_rank = 0;
  for (const RejectedRun& x : rejected) {
    const bool is_static = p.rate_rad_s == 0.0 && p.counter_rate_offset_rad_s == 0.0;
    if (x.is_static != is_static) continue;
    const double db = std::abs(wrap_deg_quick(x.beta_deg - p.beta_rad * kRadToDeg));
    // A rate table at main rate 0 (docs/physics.md section 15): the main axis' rate against the stopped
    // tolerance.
    const double dr = is_static ? 0.0
                      : p.rate_rad_s == 0.0
                          ? (std::abs(x.main_rate_rad_s) < options.static_rate_tolerance_rad_s ? 0.0 : 1.0)
                          : std::abs(x.main_rate_rad_s - p.rate_rad_s) / std::abs(p.rate_rad_s);
    const double dg = is_static ? std::abs(wrap_deg_quick(x.gamma_deg - p.gamma_rad * kRadToDeg)) : 0.0;
    if (db > 5.0 || dr > 0.05 || dg > 5.0) continue;
    const int rank = (db <= options.beta_tolerance_deg ? 2 : 0) + (dr <= options.rate_tolerance ? 1 : 0);
    if (!best || rank > best_rank ||
        (rank == best_rank && x.end_s - x.start_s > best->end_s - best->start_s)) {
      best = &x;
      best_rank = rank;
    }
  }
  if (!best) return "no steady run of the record comes near it";
  return fmt::format("the steady run at t = {:.3f} s to {:.3f} s gave no dwell: {}", best->start_s,
                     best->end_s, best->reason);
}

}  // namespace gyrocal
