#pragma once
// Noise characterisation from the overlapping Allan deviation (IEEE Std 952-1997, annex C; physics.md section
// 13; docs/noise.md "Noise terms"): the equivalent degrees of freedom of each point for a power-law
// noise, 68.3 % confidence bounds from the chi-squared law, and the fit of the IEEE 952 terms (angle
// quantization, angle random walk, bias instability, rate random walk, rate ramp) with non-negative
// coefficients and standard uncertainties. Rates are in deg/h and times in s throughout; the terms come out
// in the units of `[gyro.noise]`.
#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "gyrocal/core/allan.hpp"

namespace gyrocal {

/// The power-law noises of a rate signal, by the slope of their Allan deviation. The names are a gyro's (IEEE
/// 952); the frequency-stability names (NIST SP 1065) are those of the rate as "frequency" and the angle as
/// "phase".
enum class NoiseTerm {
  AngleQuantization,  ///< sigma ~ 1/tau    (white phase, alpha = +2)
  AngleRandomWalk,    ///< sigma ~ tau^-1/2 (white frequency, alpha = 0)
  BiasInstability,    ///< sigma flat       (flicker frequency, alpha = -1)
  RateRandomWalk,     ///< sigma ~ tau^1/2  (random-walk frequency, alpha = -2)
  RateRamp,           ///< sigma ~ tau      (a drift; no power law of its own: treated as alpha = -2)
};
inline constexpr std::size_t kNoiseTermCount = 5;

/// The name of a term as a `[gyro.noise]` key where one exists (angle_random_walk_deg_rt_h,
/// bias_instability_deg_h, rate_random_walk_deg_h_rt_h), else a name with its unit (angle_quantization_deg,
/// rate_ramp_deg_h_per_h).
std::string_view noise_term_key(NoiseTerm term);

/// The term whose noise_term_key() is `key`, or nothing.
std::optional<NoiseTerm> noise_term_from_key(std::string_view key);

/// The Allan deviation (deg/h) at tau_s (s) of the term `term` alone, of value `value` in its unit
/// (noise_term_key): physics.md section 13, e.g. 60 N/sqrt(tau_s) for the angle random walk N in deg/sqrt(h),
/// 0.6643 B for the bias instability, (K/60) sqrt(tau_s/3) for the rate random walk.
double noise_term_deviation(NoiseTerm term, double value, double tau_s);

/// Equivalent degrees of freedom of the overlapping Allan variance at cluster size m from rate_samples
/// samples when `term` dominates: NIST SP 1065 (2008) table 5 (after Stein 1985), with the phase-point count
/// N = samples + 1. Throws Error unless 1 <= m <= rate_samples / 2.
double allan_equivalent_dof(std::size_t rate_samples, std::size_t m, NoiseTerm term);

/// The quantile x of the chi-squared law with `dof` (> 0, not necessarily whole) degrees of freedom:
/// P(X <= x) = probability, 0 < probability < 1. Accurate to ~1e-12 relative.
double chi_squared_quantile(double probability, double dof);

/// The two-sided `confidence` (default 68.3 %, the normal law's one sigma) bounds of a deviation estimated
/// with `dof` degrees of freedom: sigma * sqrt(dof / chi2_{(1+c)/2}) and sigma * sqrt(dof / chi2_{(1-c)/2}).
struct DeviationBounds {
  double low = 0.0;
  double high = 0.0;
};
DeviationBounds deviation_confidence_bounds(double deviation, double dof,
                                            double confidence = 0.6826894921370859);

/// One fitted term: value in its unit (noise_term_key), standard uncertainty, and whether the fit kept it (a
/// term at the non-negativity bound has value 0 and std 0).
struct FittedNoiseTerm {
  double value = 0.0;
  double std = 0.0;
  bool present = false;
};

/// The result of characterising a rate record.
struct NoiseCharacterisation {
  AllanDeviation allan;             ///< the points fitted (octave cluster sizes)
  std::vector<NoiseTerm> dominant;  ///< per point: the fitted term that contributes most there
  std::vector<double> dof;          ///< per point: equivalent degrees of freedom of that term
  std::vector<double> adev_low;     ///< per point: 68.3 % lower bound, deg/h
  std::vector<double> adev_high;    ///< per point: 68.3 % upper bound, deg/h
  std::array<FittedNoiseTerm, kNoiseTermCount> terms{};  ///< indexed by NoiseTerm
  double chi2_per_dof = 0.0;  ///< weighted misfit of the fit per degree of freedom (about 1 when it fits)

  const FittedNoiseTerm& term(NoiseTerm t) const { return terms[static_cast<std::size_t>(t)]; }
  /// The model's Allan deviation at tau_s from the fitted terms, deg/h.
  double model_deviation(double tau_s) const;
};

/// Characterise a rate series (deg/h) sampled at sample_rate_hz: the overlapping Allan deviation at every
/// octave cluster size m = 1, 2, 4, ... <= N/4, the terms fitted by weighted non-negative least squares on
/// sigma^2 (each point weighted by its equivalent degrees of freedom under the term that dominates it in the
/// fit, iterated), and each point's confidence bounds. Needs at least 16 samples; throws Error otherwise or
/// on a non-finite sample.
NoiseCharacterisation characterise_noise(std::span<const double> rate_deg_h, double sample_rate_hz);

}  // namespace gyrocal
