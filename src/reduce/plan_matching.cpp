#include "gyrocal/reduce/reducer.hpp"

// Plan matching: a steady run's measured rates and angles matched to a position of the plan (match_to_plan).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "gyrocal/core/units.hpp"
#include "gyrocal/plan/positions.hpp"
#include "gyrocal/reduce/feasibility.hpp"

namespace gyrocal {

PlanMatch match_to_plan(const TestSpec& plan, const ReduceOptions& options, double main_rate_rad_s,
                        double counter_rate_rad_s, double beta_deg, double gamma_deg) {
  PlanMatch m;
  const double tol0 = options.static_rate_tolerance_rad_s;
  m.is_static = std::abs(main_rate_rad_s) < tol0 && std::abs(counter_rate_rad_s) < tol0;
  // docs/physics.md section 15: the platform's heading (theta + psi_r) turns at the counter rate offset; a
  // plain test has the single offset 0.
  const double heading_rate = main_rate_rad_s + counter_rate_rad_s;
  bool has_offset = false;
  for (double o : plan.counter_rate_offsets_rad_s)
    if (o != 0.0) has_offset = true;
  const bool has_static =
      std::find(plan.rates_rad_s.begin(), plan.rates_rad_s.end(), 0.0) != plan.rates_rad_s.end() &&
      std::find(plan.counter_rate_offsets_rad_s.begin(), plan.counter_rate_offsets_rad_s.end(), 0.0) !=
          plan.counter_rate_offsets_rad_s.end();
  if (m.is_static) {
    if (!has_static) m.why_not = "the machine stands still and the plan has no static hold";
  } else if (std::abs(main_rate_rad_s) < tol0) {
    // At main rate 0 the counter platform turns at the offset alone: a plain rate table.
    double best = 0.0, best_rel = std::numeric_limits<double>::infinity();
    const bool has_zero_rate =
        std::find(plan.rates_rad_s.begin(), plan.rates_rad_s.end(), 0.0) != plan.rates_rad_s.end();
    if (has_zero_rate)
      for (double o : plan.counter_rate_offsets_rad_s) {
        if (o == 0.0) continue;
        const double rel = std::abs(heading_rate - o) / std::abs(o);
        if (rel < best_rel) best_rel = rel, best = o;
      }
    if (best_rel == std::numeric_limits<double>::infinity())
      m.why_not = fmt::format("the main axis stands still while the counter platform turns at {:.6g} rad/s",
                              counter_rate_rad_s);
    else if (best_rel > options.rate_tolerance)
      m.why_not = fmt::format(
          "the main axis stands still and the counter platform turns at {:.6g} rad/s, {:.2e} (relative) from "
          "the planned counter rate offset {} rad/s (rate_tolerance {:.0e})",
          counter_rate_rad_s, best_rel, best, options.rate_tolerance);
    m.planned_rate_rad_s = 0.0;
    m.planned_counter_rate_offset_rad_s = best;
  } else {
    double best = -1.0, best_rel = std::numeric_limits<double>::infinity();
    for (double r : plan.rates_rad_s) {
      if (r == 0.0) continue;
      const double rel = std::abs(main_rate_rad_s - r) / std::abs(r);
      if (rel < best_rel) best_rel = rel, best = r;
    }
    if (best < 0.0 && best_rel == std::numeric_limits<double>::infinity()) {
      m.why_not = "the main axis turns and the plan has no spinning rate";
    } else if (best_rel > options.rate_tolerance) {
      m.why_not = fmt::format(
          "the main axis turns at {:.6g} rad/s, {:.2e} (relative) from the planned {} rad/s "
          "(rate_tolerance {:.0e})",
          main_rate_rad_s, best_rel, best, options.rate_tolerance);
    } else {
      // The planned offset nearest the heading's rate, within rate_tolerance of the larger of |rate| and
      // |offset| (docs/rate_platform.md).
      double best_o = 0.0, best_d = std::numeric_limits<double>::infinity();
      for (double o : plan.counter_rate_offsets_rad_s) {
        const double d = std::abs(heading_rate - o) / std::max(std::abs(best), std::abs(o));
        if (d < best_d) best_d = d, best_o = o;
      }
      if (best_d > options.rate_tolerance) {
        if (!has_offset)
          m.why_not = fmt::format(
              "the counter platform turns at {:.6g} rad/s, not at minus the main rate {:.6g} rad/s",
              counter_rate_rad_s, main_rate_rad_s);
        else
          m.why_not = fmt::format(
              "the counter platform turns at {:.6g} rad/s, {:.6g} rad/s relative to minus the main rate "
              "{:.6g} rad/s, which matches no planned counter rate offset",
              counter_rate_rad_s, heading_rate, main_rate_rad_s);
      }
      m.planned_counter_rate_offset_rad_s = best_o;
    }
    m.planned_rate_rad_s = best;
  }
  if (!m.why_not.empty()) return m;
  const auto nearest = [](const std::vector<double>& planned_rad, double deg, double& best_deg) {
    double best = std::numeric_limits<double>::infinity();
    for (double p : planned_rad) {
      const double d = std::abs(wrap_deg_quick(deg - p * kRadToDeg));
      if (d < best) best = d, best_deg = p;
    }
    return best;
  };
  double b = 0.0;
  const double db = nearest(plan.beta_rad, beta_deg, b);
  if (db > options.beta_tolerance_deg) {
    m.why_not = fmt::format(
        "beta reads {:.3f} deg, {:.3f} deg from the nearest planned beta {:.3f} deg "
        "(beta_tolerance_deg {})",
        beta_deg, db, b * kRadToDeg, options.beta_tolerance_deg);
    return m;
  }
  m.beta_rad = b;
  if (m.is_static) {
    double g = 0.0;
    const double dg = nearest(plan.gamma_rad, gamma_deg, g);
    if (dg > options.beta_tolerance_deg) {
      m.why_not = fmt::format(
          "the static hold's gamma reads {:.3f} deg, {:.3f} deg from the nearest planned "
          "gamma {:.3f} deg (beta_tolerance_deg {})",
          gamma_deg, dg, g * kRadToDeg, options.beta_tolerance_deg);
      return m;
    }
    m.gamma_rad = g;
  }
  return m;
}

}  // namespace gyrocal
