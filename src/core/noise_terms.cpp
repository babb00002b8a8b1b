#include "gyrocal/core/noise_terms.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/special_functions.hpp"

namespace gyrocal {
namespace {

constexpr double kSecondsPerHour = 3600.0;
// A fitted term is kept when its coefficient is at least this many standard uncertainties above zero.
constexpr double kSignificance = 2.0;
// The fit treats the octave points as independent, but neighbouring clusters share samples, so the covariance
// of the fitted coefficients is too small: over 40 simulated records of white noise and rate random walk the
// scatter of the fitted terms was 1.4 (N) and 2.0 (K) times their independent-point uncertainty. The stated
// uncertainty is scaled by this factor (docs/noise.md); tests/test_noise_terms.cpp checks the z-scores.
constexpr double kCorrelationFactor = 2.0;

// The basis of sigma^2(tau) in (deg/h)^2 for tau in s, one function per NoiseTerm (physics.md section 13).
double basis(NoiseTerm term, double tau_s) {
  switch (term) {
    case NoiseTerm::AngleQuantization:
      return 1.0 / (tau_s * tau_s);
    case NoiseTerm::AngleRandomWalk:
      return 1.0 / tau_s;
    case NoiseTerm::BiasInstability:
      return 1.0;
    case NoiseTerm::RateRandomWalk:
      return tau_s;
    case NoiseTerm::RateRamp:
      return tau_s * tau_s;
  }
  return 0.0;
}

// The factor k with term value = k * sqrt(coefficient of basis(term)):
//   Q (deg):          sigma^2 = 3 Q^2 / tau_h^2       = 3 (3600 Q)^2 / tau_s^2
//   N (deg/sqrt h):   sigma^2 = N^2 / tau_h           = 3600 N^2 / tau_s
//   B (deg/h):        sigma^2 = (2 ln 2 / pi) B^2
//   K (deg/h/sqrt h): sigma^2 = K^2 tau_h / 3         = K^2 tau_s / (3 * 3600)
//   R (deg/h/h):      sigma^2 = R^2 tau_h^2 / 2       = R^2 tau_s^2 / (2 * 3600^2)
double value_per_sqrt_coefficient(NoiseTerm term) {
  switch (term) {
    case NoiseTerm::AngleQuantization:
      return 1.0 / (std::sqrt(3.0) * kSecondsPerHour);
    case NoiseTerm::AngleRandomWalk:
      return 1.0 / std::sqrt(kSecondsPerHour);
    case NoiseTerm::BiasInstability:
      return 1.0 / std::sqrt(2.0 * std::numbers::ln2 / std::numbers::pi);
    case NoiseTerm::RateRandomWalk:
      return std::sqrt(3.0 * kSecondsPerHour);
    case NoiseTerm::RateRamp:
      return std::sqrt(2.0) * kSecondsPerHour;
  }
  return 0.0;
}

constexpr std::array<NoiseTerm, kNoiseTermCount> kAllTerms = {
    NoiseTerm::AngleQuantization, NoiseTerm::AngleRandomWalk, NoiseTerm::BiasInstability,
    NoiseTerm::RateRandomWalk, NoiseTerm::RateRamp};

struct SubsetFit {
  double cost = std::numeric_limits<double>::infinity();
  Eigen::VectorXd coefficients;  // all five, zero where not in the subset
  Eigen::MatrixXd covariance;    // 5 x 5, zero outside the subset
};

// Weighted least squares of y on the columns of `design` named by `mask`, with every coefficient > 0; an
// infeasible subset has infinite cost. Columns are scaled to unit weighted norm before the QR factorisation,
// since the basis functions span many orders of magnitude.
SubsetFit fit_subset(const Eigen::MatrixXd& design, const Eigen::VectorXd& y, const Eigen::VectorXd& sqrt_w,
                     unsigned mask) {
  std::vector<int> columns;
  for (int j = 0; j < static_cast<int>(kNoiseTermCount); ++j) {
    if (mask & (1u << j)) columns.push_back(j);
  }
  SubsetFit fit;
  const auto rows = design.rows();
  const auto k = static_cast<Eigen::Index>(columns.size());
  if (k == 0 || k > rows) return fit;
  Eigen::MatrixXd a(rows, k);
  Eigen::VectorXd scale(k);
  for (Eigen::Index c = 0; c < k; ++c) {
    a.col(c) = design.col(columns[static_cast<std::size_t>(c)]).cwiseProduct(sqrt_w);
    scale(c) = a.col(c).norm();
    if (!(scale(c) > 0.0)) return fit;
    a.col(c) /= scale(c);
  }
  const Eigen::VectorXd b = y.cwiseProduct(sqrt_w);
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  if (qr.rank() < k) return fit;
  const Eigen::VectorXd scaled = qr.solve(b);
  const Eigen::VectorXd coefficients = scaled.cwiseQuotient(scale);
  const Eigen::MatrixXd ata_inverse = (a.transpose() * a).inverse();
  // Every term must be positive and supported by the record: at least kSignificance standard uncertainties
  // above zero. A spurious term would otherwise dominate a point's degrees of freedom or reach the user as a
  // value.
  for (Eigen::Index c = 0; c < k; ++c) {
    if (!(scaled(c) >= kSignificance * std::sqrt(ata_inverse(c, c)))) return fit;
  }
  fit.cost = (a * scaled - b).squaredNorm();
  fit.coefficients = Eigen::VectorXd::Zero(kNoiseTermCount);
  fit.covariance = Eigen::MatrixXd::Zero(kNoiseTermCount, kNoiseTermCount);
  for (Eigen::Index r = 0; r < k; ++r) {
    fit.coefficients(columns[static_cast<std::size_t>(r)]) = coefficients(r);
    for (Eigen::Index c = 0; c < k; ++c) {
      fit.covariance(columns[static_cast<std::size_t>(r)], columns[static_cast<std::size_t>(c)]) =
          ata_inverse(r, c) / (scale(r) * scale(c));
    }
  }
  return fit;
}

}  // namespace

std::string_view noise_term_key(NoiseTerm term) {
  switch (term) {
    case NoiseTerm::AngleQuantization:
      return "angle_quantization_deg";
    case NoiseTerm::AngleRandomWalk:
      return "angle_random_walk_deg_rt_h";
    case NoiseTerm::BiasInstability:
      return "bias_instability_deg_h";
    case NoiseTerm::RateRandomWalk:
      return "rate_random_walk_deg_h_rt_h";
    case NoiseTerm::RateRamp:
      return "rate_ramp_deg_h_per_h";
  }
  return "";
}

double allan_equivalent_dof(std::size_t rate_samples, std::size_t m, NoiseTerm term) {
  if (m < 1 || m > rate_samples / 2) {
    throw Error(fmt::format("Allan deviation: cluster size {} is out of range 1 to {} for {} samples.", m,
                            rate_samples / 2, rate_samples));
  }
  const double n = static_cast<double>(rate_samples) + 1.0;  // phase (angle) points
  const double md = static_cast<double>(m);
  double dof = 0.0;
  switch (term) {
    case NoiseTerm::AngleQuantization:  // white phase
      dof = (n + 1.0) * (n - 2.0 * md) / (2.0 * (n - md));
      break;
    case NoiseTerm::AngleRandomWalk:  // white frequency
      dof = (3.0 * (n - 1.0) / (2.0 * md) - 2.0 * (n - 2.0) / n) * (4.0 * md * md / (4.0 * md * md + 5.0));
      break;
    case NoiseTerm::BiasInstability:  // flicker frequency
      dof = m == 1 ? 2.0 * (n - 2.0) / (2.3 * n - 4.9) : 5.0 * n * n / (4.0 * md * (n + 3.0 * md));
      break;
    case NoiseTerm::RateRandomWalk:  // random-walk frequency
    case NoiseTerm::RateRamp:
      dof = (n - 2.0) / (md * (n - 3.0) * (n - 3.0)) *
            ((n - 1.0) * (n - 1.0) - 3.0 * md * (n - 1.0) + 4.0 * md * md);
      break;
  }
  // The formulas are approximations; at the ends of their range they can fall below one degree of freedom,
  // which no Allan variance of two or more clusters has.
  return std::max(dof, 1.0);
}

double chi_squared_quantile(double probability, double dof) {
  if (!(probability > 0.0 && probability < 1.0) || !(dof > 0.0) || !std::isfinite(dof)) {
    throw Error(fmt::format("chi-squared quantile: need 0 < probability < 1 and dof > 0, got {} and {}.",
                            probability, dof));
  }
  const double a = dof / 2.0;
  // Bracket, then bisect on the cumulative law (monotone), in the logarithm of x for the wide range of
  // scales.
  double low = 0.0;
  double high = std::max(1.0, dof);
  while (regularized_gamma_p(a, high / 2.0) < probability) high *= 2.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = low > 0.0 ? std::sqrt(low * high) : high / 2.0;
    if (mid <= low || mid >= high) break;
    if (regularized_gamma_p(a, mid / 2.0) < probability) {
      low = mid;
    } else {
      high = mid;
    }
    if (high - low <= 1e-15 * high) break;
  }
  return 0.5 * (low + high);
}

DeviationBounds deviation_confidence_bounds(double deviation, double dof, double confidence) {
  if (!(confidence > 0.0 && confidence < 1.0)) {
    throw Error(fmt::format("confidence bounds: the confidence must be in (0, 1), got {}.", confidence));
  }
  const double tail = (1.0 - confidence) / 2.0;
  return {deviation * std::sqrt(dof / chi_squared_quantile(1.0 - tail, dof)),
          deviation * std::sqrt(dof / chi_squared_quantile(tail, dof))};
}

std::optional<NoiseTerm> noise_term_from_key(std::string_view key) {
  for (NoiseTerm t : kAllTerms)
    if (noise_term_key(t) == key) return t;
  return std::nullopt;
}

double noise_term_deviation(NoiseTerm term, double value, double tau_s) {
  const double root = value / value_per_sqrt_coefficient(term);
  return std::sqrt(root * root * basis(term, tau_s));
}

double NoiseCharacterisation::model_deviation(double tau_s) const {
  double variance = 0.0;
  for (NoiseTerm t : kAllTerms) {
    const FittedNoiseTerm& fitted = term(t);
    if (!fitted.present) continue;
    const double sigma = noise_term_deviation(t, fitted.value, tau_s);
    variance += sigma * sigma;
  }
  return std::sqrt(variance);
}

NoiseCharacterisation characterise_noise(std::span<const double> rate_deg_h, double sample_rate_hz) {
  const std::size_t n = rate_deg_h.size();
  if (n < 16) {
    throw Error(fmt::format("Noise characterisation needs at least 16 samples, got {}.", n));
  }
  std::vector<std::size_t> sizes;
  for (std::size_t m = 1; m <= n / 4; m *= 2) sizes.push_back(m);

  NoiseCharacterisation result;
  result.allan = overlapping_allan_deviation(rate_deg_h, sample_rate_hz, sizes);
  const auto points = static_cast<Eigen::Index>(sizes.size());
  Eigen::MatrixXd design(points, static_cast<Eigen::Index>(kNoiseTermCount));
  Eigen::VectorXd y(points);
  for (Eigen::Index i = 0; i < points; ++i) {
    const double tau = result.allan.tau_s[static_cast<std::size_t>(i)];
    for (std::size_t j = 0; j < kNoiseTermCount; ++j)
      design(i, static_cast<Eigen::Index>(j)) = basis(kAllTerms[j], tau);
    const double adev = result.allan.deviation[static_cast<std::size_t>(i)];
    y(i) = adev * adev;
  }

  // Each subset of terms is fitted with its own weights, iterated to consistency: a point's weight comes from
  // the degrees of freedom of the term that dominates it in that subset's model, and from the model's
  // variance (the first pass takes white noise and the measured variance). Subsets are then compared by the
  // Gaussian likelihood of the points with Akaike's penalty: -2 ln L + 2 k = sum (y - v)^2 dof / (2 v^2) + 2
  // ln v + 2 k.
  struct Candidate {
    SubsetFit fit;
    std::vector<NoiseTerm> dominant;
    Eigen::VectorXd model_variance;
    double criterion = std::numeric_limits<double>::infinity();
  };
  auto dominant_terms = [&](const Eigen::VectorXd& coefficients) {
    std::vector<NoiseTerm> dominant(sizes.size());
    for (Eigen::Index i = 0; i < points; ++i) {
      Eigen::Index j = 0;
      (design.row(i).transpose().cwiseProduct(coefficients)).maxCoeff(&j);
      dominant[static_cast<std::size_t>(i)] = kAllTerms[static_cast<std::size_t>(j)];
    }
    return dominant;
  };
  auto point_dof = [&](const std::vector<NoiseTerm>& dominant, Eigen::Index i) {
    return allan_equivalent_dof(n, sizes[static_cast<std::size_t>(i)], dominant[static_cast<std::size_t>(i)]);
  };
  Candidate best;
  for (unsigned mask = 1; mask < (1u << kNoiseTermCount); ++mask) {
    Candidate candidate;
    candidate.dominant.assign(sizes.size(), NoiseTerm::AngleRandomWalk);
    candidate.model_variance = y;
    for (int iteration = 0; iteration < 8; ++iteration) {
      Eigen::VectorXd sqrt_w(points);
      for (Eigen::Index i = 0; i < points; ++i) {
        const double v = std::max(candidate.model_variance(i), std::numeric_limits<double>::min());
        sqrt_w(i) = std::sqrt(point_dof(candidate.dominant, i) / 2.0) / v;  // var(sigma^2) = 2 sigma^4 / dof
      }
      candidate.fit = fit_subset(design, y, sqrt_w, mask);
      if (!std::isfinite(candidate.fit.cost)) break;
      candidate.model_variance = design * candidate.fit.coefficients;
      std::vector<NoiseTerm> dominant = dominant_terms(candidate.fit.coefficients);
      const bool settled = iteration > 0 && dominant == candidate.dominant;
      candidate.dominant = std::move(dominant);
      if (settled) break;
    }
    if (!std::isfinite(candidate.fit.cost)) continue;
    // Quantization shows as the 1/tau^2 slope at the shortest tau; a quantization term that dominates no
    // point only absorbs the other terms' mismatch there (a bias instability whose Allan deviation falls
    // below its floor at short tau drew a spurious term and pulled the white noise 0.5 % low: docs/noise.md).
    if ((mask & 1u) != 0 && std::find(candidate.dominant.begin(), candidate.dominant.end(),
                                      NoiseTerm::AngleQuantization) == candidate.dominant.end())
      continue;
    candidate.criterion = 2.0 * std::popcount(mask);
    for (Eigen::Index i = 0; i < points; ++i) {
      const double v = candidate.model_variance(i);
      const double r = y(i) - v;
      candidate.criterion += r * r * point_dof(candidate.dominant, i) / (2.0 * v * v) + 2.0 * std::log(v);
    }
    if (candidate.criterion < best.criterion) best = std::move(candidate);
  }
  if (!std::isfinite(best.criterion)) {
    throw Error(
        "Noise characterisation: no combination of noise terms fits this record's Allan deviation "
        "(is the output constant?).");
  }
  result.dominant = best.dominant;

  const auto active = static_cast<double>((best.fit.coefficients.array() > 0.0).count());
  result.chi2_per_dof =
      static_cast<double>(points) > active ? best.fit.cost / (static_cast<double>(points) - active) : 0.0;
  for (std::size_t j = 0; j < kNoiseTermCount; ++j) {
    const double c = best.fit.coefficients(static_cast<Eigen::Index>(j));
    if (!(c > 0.0)) continue;
    const double k = value_per_sqrt_coefficient(kAllTerms[j]);
    const double c_std =
        std::sqrt(best.fit.covariance(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(j)));
    result.terms[j] = {k * std::sqrt(c), kCorrelationFactor * k * c_std / (2.0 * std::sqrt(c)), true};
  }
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    const double dof = allan_equivalent_dof(n, sizes[i], result.dominant[i]);
    result.dof.push_back(dof);
    const DeviationBounds bounds = deviation_confidence_bounds(result.allan.deviation[i], dof);
    result.adev_low.push_back(bounds.low);
    result.adev_high.push_back(bounds.high);
  }
  return result;
}

}  // namespace gyrocal
