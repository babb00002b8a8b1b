#pragma once
// The model terms of a planned dwell in closed form (issue 17, item 3): a cost independent of the number
// of revolutions. A planned dwell (no stretches) holds `samples` evenly spaced instants on the constant-rate
// lines theta_i = theta0 + omega dt i and psi_i = psi0 + psi' dt i, and every model term is a smooth function
// of the joint angles (the rates and beta are fixed over the dwell), 2 pi-periodic in the main angle theta
// and in the platform's heading theta + psi, which stays put but for the rate mismatch or a counter rate
// offset. The reduction's sums over the samples, sum_i e^{j m gamma_i} i^p F_i (gamma = -psi; p = 1 for the
// fit's linear drift), are then sums over the model term's Fourier terms of geometric series, which have
// closed forms. They are taken as a quadrature: sum_ab K_ab F on an M x M grid of main angle and heading (one
// heading where it does not move), with weights K exact for every model term whose harmonics lie below M / 2
// in each; M (16 .. 128) is doubled until the M / 2 grid's result agrees with the M grid's within 1e-10 of
// the model term's size plus its evaluation's rounding (docs/performance.md, "plan in closed form").
#include <complex>
#include <cstddef>
#include <functional>
#include <vector>

#include "gyrocal/reduce/dwell_accumulator.hpp"
#include "gyrocal/reduce/reducer.hpp"

namespace gyrocal {

/// sum_{i<n} e^{j x i} and sum_{i<n} i e^{j x i}, for any real x (the limit n, n(n-1)/2 at x = 0 mod
/// 2 pi), accurate to rounding also where n x is small (a series there).
std::pair<std::complex<double>, std::complex<double>> geometric_power_sums(double x, double n);

/// Evaluates the model terms (`columns` values into `values`) at main angle theta and counter angle psi
/// (rad).
using ModelTermsFunction = std::function<void(double main_rad, double counter_rad, double* values)>;

/// The reduced model terms of planned dwell `d` (stretches empty), one DwellValues per column with one value
/// per gamma (a static hold's mean, or the harmonic fit's values at the plan's gammas and mid-time), equal to
/// what DwellAccumulator gives on every sample to rounding, at the cost of O(M^2) evaluations. Returns false
/// (out untouched) where the closed form does not apply: the window mean, a dwell without samples, a spinning
/// dwell whose platform does not turn, or harmonics beyond the largest grid (256 per angle).
bool planned_dwell_model_terms(const Dwell& d, const ReduceOptions& options, int columns,
                               const ModelTermsFunction& evaluate, std::vector<DwellValues>& out);

}  // namespace gyrocal
