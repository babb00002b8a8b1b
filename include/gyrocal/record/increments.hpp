#pragma once
// Increments (docs/records.md, "Increments"): an output column written as increments
// (OutputForm::kIncrement: an IMU's angle and velocity increments) holds, per row, the integral of the
// sensor's output over the interval that ends at the row's stamp. Divided by that interval it is the output's
// mean over the interval, not its value at the stamp. What the reader, the simulator and the model's side of
// a reduced position share about that interval: the Gauss-Legendre rule of the mean over it, the number of
// nodes a band-limited output needs, and the closed form of a harmonic's mean.
#include <complex>
#include <cstddef>
#include <vector>

namespace gyrocal {

/// Most Gauss-Legendre nodes an interval's mean is taken with: 16 nodes integrate a harmonic whose phase
/// turns by up to ~10 rad across the interval to 1e-13 (interval_nodes).
inline constexpr int kMaxIntervalNodes = 16;

/// The Gauss-Legendre rule for the mean over an interval [t - dt, t]: node k lies `back[k]` x dt before the
/// stamp t (0 < back < 1) and weighs `weight[k]` (the weights sum to 1), so that
///   mean = sum_k weight[k] f(t - back[k] dt),
/// exact for polynomials of degree < 2 x nodes.
struct IntervalRule {
  std::vector<double> back;
  std::vector<double> weight;
};

/// The `nodes`-point rule (1 to kMaxIntervalNodes; others throw gyrocal::Error): Legendre's roots by Newton's
/// iteration to a double's precision.
IntervalRule interval_rule(int nodes);

/// The fewest nodes (at most kMaxIntervalNodes) whose rule gives the mean of e^{j f s} over an interval
/// within 1e-13 (relative to the harmonic's amplitude) for every |f| dt <= max_phase_rad: the phase a
/// harmonic turns across the interval. Gauss-Legendre's remainder for the mean of e^{j a x} over [-1, 1] is
/// at most
///   2^(2n) (n!)^4 / ((2n + 1) ((2n)!)^3) a^(2n),  a = max_phase / 2.
/// 1 node for max_phase 0 (a constant).
int interval_nodes(double max_phase_rad);

/// The mean over [t - dt, t] of e^{j f s} divided by its value at the stamp t, for a harmonic of angular
/// frequency f (rad/s): sinc(f dt / 2) e^{-j f dt / 2}, sinc(x) = sin(x) / x (exact for a constant f). The
/// gain 1 - (f dt)^2 / 24 and the lag of half an interval of docs/records.md, "Increments".
std::complex<double> interval_mean_factor(double f_rad_s, double dt_s);

}  // namespace gyrocal
