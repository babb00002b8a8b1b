// The three reductions of a dwell (reduce/dwell_reduction.hpp), each on its own against an independent route:
// the harmonic fit against a direct least-squares solve (Householder QR of the design matrix, harmonics from
// std::cos(k g)), the window means against plain means of the samples in each window, the static mean against
// the mean; and the factory's choice of type.
#include <cmath>
#include <cstddef>
#include <random>
#include <variant>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "gyrocal/core/units.hpp"
#include "gyrocal/reduce/dwell_accumulator.hpp"
#include "gyrocal/reduce/dwell_reduction.hpp"

namespace gyrocal {
namespace {

struct Sample {
  double t_scaled, gamma_rad;
  std::vector<double> values;
};

/// A dwell's samples: gamma turning `turns` times from gamma0 with uneven steps (a rig's jitter), time
/// scaled to [-0.5, 0.5], and `columns` values of harmonics of gamma, a drift in time and noise.
std::vector<Sample> spinning_samples(double turns, std::size_t n, int columns, unsigned seed,
                                     double gamma0 = 0.3) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(0.6, 1.4);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<double> steps(n - 1);
  double total = 0.0;
  for (double& s : steps) total += (s = jitter(rng));
  std::vector<Sample> out;
  double progress = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) progress += steps[i - 1] / total;
    Sample s;
    s.t_scaled = progress - 0.5;
    s.gamma_rad = gamma0 + 2.0 * kPi * turns * progress;
    for (int c = 0; c < columns; ++c) {
      const double g = s.gamma_rad;
      s.values.push_back(1.0 + c + (0.7 - 0.2 * c) * std::cos(g) + 0.4 * std::sin(2.0 * g + c) +
                         0.1 * std::cos(3.0 * g) + 0.3 * s.t_scaled + noise(rng));
    }
    out.push_back(s);
  }
  return out;
}

template <class M>
void feed(M& method, const std::vector<Sample>& samples) {
  for (const Sample& s : samples) method.add(s.t_scaled, s.gamma_rad, s.values.data());
}

DwellValues values_of(const DwellReductionMethod auto& method, std::size_t ng, int column, double t_mid) {
  DwellValues out;
  out.value.assign(ng, std::nan(""));
  out.std_err.assign(ng, std::nan(""));
  out.samples.assign(ng, 0);
  method.values(column, t_mid, out);
  return out;
}

/// The harmonic fit's design row, built independently: std::cos(k g), std::sin(k g), then t.
Eigen::RowVectorXd design_row(double gamma, double t, int order, bool drift) {
  Eigen::RowVectorXd r(2 * order + 1 + (drift ? 1 : 0));
  r[0] = 1.0;
  for (int k = 1; k <= order; ++k) {
    r[2 * k - 1] = std::cos(k * gamma);
    r[2 * k] = std::sin(k * gamma);
  }
  if (drift) r[2 * order + 1] = t;
  return r;
}

const std::vector<double> kGammas = {0.0, 0.5 * kPi, kPi, 1.5 * kPi};

TEST(DwellReduction, FactoryPicksTheTypeFromStaticAndMethod) {
  ReduceOptions harmonic;
  harmonic.method = ReduceOptions::Method::kHarmonicFit;
  ReduceOptions window;
  window.method = ReduceOptions::Method::kWindowMean;
  // A static hold is reduced by its mean whichever method the options name.
  EXPECT_TRUE(std::holds_alternative<StaticMean>(make_dwell_reduction(harmonic, {0.0}, true, 1, true)));
  EXPECT_TRUE(std::holds_alternative<StaticMean>(make_dwell_reduction(window, {0.0}, true, 1, true)));
  EXPECT_TRUE(std::holds_alternative<HarmonicFit>(make_dwell_reduction(harmonic, kGammas, false, 1, true)));
  EXPECT_TRUE(std::holds_alternative<WindowMean>(make_dwell_reduction(window, kGammas, false, 1, true)));
  // The accumulator holds the factory's choice.
  EXPECT_TRUE(std::holds_alternative<WindowMean>(
      DwellAccumulator(window, kGammas, false, 1, 10.0, true).reduction()));
  EXPECT_TRUE(
      std::holds_alternative<StaticMean>(DwellAccumulator(window, {0.0}, true, 1, 10.0, true).reduction()));
}

TEST(DwellReduction, HarmonicFitEqualsADirectLeastSquaresSolve) {
  for (const bool drift : {true, false}) {
    for (const int order : {0, 2, 3, 5}) {
      SCOPED_TRACE(::testing::Message() << "order " << order << ", drift " << drift);
      constexpr int kColumns = 3;
      const auto samples = spinning_samples(7.37, 800, kColumns, 11U + static_cast<unsigned>(order));
      HarmonicFit fit(kGammas, order, drift, kColumns, false);
      feed(fit, samples);
      EXPECT_EQ(fit.samples(), samples.size());
      EXPECT_EQ(fit.fits_drift(), drift);

      const auto n = static_cast<Eigen::Index>(samples.size());
      Eigen::MatrixXd phi(n, 2 * order + 1 + (drift ? 1 : 0));
      for (Eigen::Index i = 0; i < n; ++i) {
        const Sample& s = samples[static_cast<std::size_t>(i)];
        phi.row(i) = design_row(s.gamma_rad, s.t_scaled, order, drift);
      }
      const auto qr = phi.colPivHouseholderQr();
      const double t_mid = 0.013;
      Eigen::MatrixXd b(phi.cols(), 4);
      for (Eigen::Index k = 0; k < 4; ++k)
        b.col(k) = design_row(kGammas[static_cast<std::size_t>(k)], t_mid, order, drift).transpose();
      for (int c = 0; c < kColumns; ++c) {
        Eigen::VectorXd y(n);
        for (Eigen::Index i = 0; i < n; ++i) y[i] = samples[static_cast<std::size_t>(i)].values[c];
        const Eigen::VectorXd expected = b.transpose() * qr.solve(y);
        const DwellValues got = values_of(fit, 4, c, t_mid);
        for (std::size_t k = 0; k < 4; ++k) {
          EXPECT_NEAR(got.value[k], expected[static_cast<Eigen::Index>(k)], 1e-11);
          EXPECT_EQ(got.samples[k], samples.size());
        }
      }
      // White noise: the values are a = B' Phi^+ y, so their covariance per unit variance is A A'.
      const Eigen::MatrixXd a = b.transpose() * qr.solve(Eigen::MatrixXd::Identity(n, n));
      const Eigen::MatrixXd expected_cov = a * a.transpose();
      const Eigen::MatrixXd cov = fit.white_noise_covariance(t_mid);
      EXPECT_LT((cov - expected_cov).cwiseAbs().maxCoeff(), 1e-13);
      const std::vector<double> gain = fit.white_noise_gain(t_mid);
      for (Eigen::Index k = 0; k < 4; ++k)
        EXPECT_NEAR(gain[static_cast<std::size_t>(k)], expected_cov(k, k), 1e-13);
    }
  }
}

TEST(DwellReduction, HarmonicMomentsGiveTheSumsOfTheBasisOuterProducts) {
  // The outlier rule's sums of b b' from the harmonics' moments (products of harmonics as harmonics of the
  // sum and difference) against the products of the basis from std::cos(k g) and std::sin(k g).
  for (const int order : {0, 1, 3, 5, HarmonicMoments::kMaxOrder}) {
    SCOPED_TRACE(::testing::Message() << "order " << order);
    const auto samples = spinning_samples(3.61, 700, 1, 31U + static_cast<unsigned>(order));
    const int p = 2 * order + 2;
    HarmonicMoments moments(order);
    Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(p, p);
    std::vector<double> b(static_cast<std::size_t>(p));
    for (const Sample& s : samples) {
      moments.add(std::cos(s.gamma_rad), std::sin(s.gamma_rad), s.t_scaled, b.data());
      const Eigen::RowVectorXd row = design_row(s.gamma_rad, s.t_scaled, order, true);
      for (int k = 0; k < p; ++k) EXPECT_NEAR(b[static_cast<std::size_t>(k)], row[k], 1e-13) << k;
      expected += row.transpose() * row;
    }
    EXPECT_EQ(moments.count(), static_cast<double>(samples.size()));
    Eigen::MatrixXd got = Eigen::MatrixXd::Zero(p, p);
    moments.lower(got.data());
    for (int j = 0; j < p; ++j)
      for (int i = j; i < p; ++i) EXPECT_NEAR(got(i, j), expected(i, j), 1e-11) << i << ", " << j;
  }
}

TEST(DwellReduction, HarmonicFitPerRevolutionIsTheFitWithoutDriftOfThatRevolution) {
  // One revolution, then a part of a second too short to fit (fewer than two samples per parameter).
  const int order = 3;
  const auto one = spinning_samples(1.0, 400, 1, 5U);
  HarmonicFit fit(kGammas, order, true, 1, true);
  feed(fit, one);
  RevolutionSums scatter;
  fit.close_period(scatter);
  ASSERT_EQ(scatter.n, 1.0);
  const auto n = static_cast<Eigen::Index>(one.size());
  Eigen::MatrixXd phi(n, 2 * order + 1);
  Eigen::VectorXd y(n);
  double t_sum = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Sample& s = one[static_cast<std::size_t>(i)];
    phi.row(i) = design_row(s.gamma_rad, 0.0, order, false);
    y[i] = s.values[0];
    t_sum += s.t_scaled;
  }
  const Eigen::VectorXd x = phi.colPivHouseholderQr().solve(y);
  for (Eigen::Index k = 0; k < 4; ++k)
    EXPECT_NEAR(scatter.v0[k], design_row(kGammas[static_cast<std::size_t>(k)], 0.0, order, false).dot(x),
                1e-11);
  EXPECT_NEAR(scatter.t, t_sum / static_cast<double>(n), 1e-15);  // at the revolution's mean time

  const auto part = spinning_samples(0.05, 2 * (2 * order + 1) - 1, 1, 6U);
  feed(fit, part);
  fit.close_period(scatter);
  EXPECT_EQ(scatter.n, 1.0);
  // The sums start again after each period: a whole revolution again counts.
  feed(fit, one);
  fit.discard_period();
  feed(fit, one);
  fit.close_period(scatter);
  EXPECT_EQ(scatter.n, 2.0);
  EXPECT_NEAR(scatter.v[0], 0.0, 1e-12);  // the same revolution twice: no deviation from the first
}

/// The samples within +-half of gamma_k, by an independent wrap (atan2 of the difference's sine and cosine).
std::vector<const Sample*> in_window(const std::vector<Sample>& samples, double gamma_k, double half_rad) {
  std::vector<const Sample*> out;
  for (const Sample& s : samples) {
    const double d = std::atan2(std::sin(s.gamma_rad - gamma_k), std::cos(s.gamma_rad - gamma_k));
    if (std::abs(d) <= half_rad) out.push_back(&s);
  }
  return out;
}

TEST(DwellReduction, WindowMeanIsThePlainMeanOfEachWindowsSamples) {
  constexpr int kColumns = 2;
  const double window_deg = 12.0, half = 0.5 * window_deg * kDegToRad;
  const auto samples = spinning_samples(6.61, 3000, kColumns, 21U, 0.011);
  const double t_mid = -0.021;
  for (const bool drift : {false, true}) {
    SCOPED_TRACE(::testing::Message() << "drift " << drift);
    WindowMean means(kGammas, window_deg, drift, kColumns, false);
    feed(means, samples);
    EXPECT_EQ(means.fits_drift(), drift);
    const std::vector<double> gain = means.white_noise_gain(t_mid);
    const Eigen::MatrixXd cov = means.white_noise_covariance(t_mid);
    for (std::size_t k = 0; k < kGammas.size(); ++k) {
      const auto in = in_window(samples, kGammas[k], half);
      ASSERT_GT(in.size(), 10U);
      const auto m = static_cast<Eigen::Index>(in.size());
      // A straight line in time through the window's samples (a constant without drift), at t_mid.
      Eigen::MatrixXd design(m, drift ? 2 : 1);
      for (Eigen::Index i = 0; i < m; ++i) {
        design(i, 0) = 1.0;
        if (drift) design(i, 1) = in[static_cast<std::size_t>(i)]->t_scaled;
      }
      Eigen::RowVectorXd at(drift ? 2 : 1);
      at[0] = 1.0;
      if (drift) at[1] = t_mid;
      const Eigen::RowVectorXd weights =
          at * design.colPivHouseholderQr().solve(Eigen::MatrixXd::Identity(m, m));
      for (int c = 0; c < kColumns; ++c) {
        double sum = 0.0, weighted = 0.0;
        for (Eigen::Index i = 0; i < m; ++i) {
          sum += in[static_cast<std::size_t>(i)]->values[c];
          weighted += weights[i] * in[static_cast<std::size_t>(i)]->values[c];
        }
        const DwellValues got = values_of(means, kGammas.size(), c, t_mid);
        EXPECT_NEAR(got.value[k], drift ? weighted : sum / static_cast<double>(m), 1e-12);
        EXPECT_EQ(got.samples[k], in.size());
      }
      EXPECT_NEAR(gain[k], weights.squaredNorm(), 1e-14);
      if (!drift) {
        EXPECT_NEAR(gain[k], 1.0 / static_cast<double>(m), 1e-15);
      }
      for (std::size_t j = 0; j < kGammas.size(); ++j)
        EXPECT_EQ(cov(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j)), j == k ? gain[k] : 0.0);
    }
  }
}

TEST(DwellReduction, WindowMeanPerRevolutionNeedsEveryWindow) {
  const double window_deg = 10.0, half = 0.5 * window_deg * kDegToRad;
  const auto one = spinning_samples(1.0, 2000, 1, 31U, 0.02);
  WindowMean means(kGammas, window_deg, true, 1, true);
  feed(means, one);
  RevolutionSums scatter;
  means.close_period(scatter);
  ASSERT_EQ(scatter.n, 1.0);
  double t_sum = 0.0, n_sum = 0.0;
  for (std::size_t k = 0; k < kGammas.size(); ++k) {
    const auto in = in_window(one, kGammas[k], half);
    double sum = 0.0;
    for (const Sample* s : in) sum += s->values[0], t_sum += s->t_scaled;
    n_sum += static_cast<double>(in.size());
    EXPECT_NEAR(scatter.v0[static_cast<Eigen::Index>(k)], sum / static_cast<double>(in.size()), 1e-12);
  }
  EXPECT_NEAR(scatter.t, t_sum / n_sum, 1e-14);
  // Half a revolution misses two of the four windows: it does not count.
  feed(means, spinning_samples(0.5, 1000, 1, 32U, 0.5));
  means.close_period(scatter);
  EXPECT_EQ(scatter.n, 1.0);
}

TEST(DwellReduction, StaticMeanIsTheMeanAndItsBatchesTheirMeans) {
  std::mt19937 rng(41U);
  std::normal_distribution<double> noise(3.0, 0.5);
  StaticMean mean(1, 2, true);
  RevolutionSums scatter;
  std::vector<double> batch_means;
  double sum0 = 0.0, sum1 = 0.0;
  std::size_t n = 0;
  for (int batch = 0; batch < 3; ++batch) {
    double batch_sum = 0.0;
    const int count = 50 + 17 * batch;
    for (int i = 0; i < count; ++i) {
      const double v[2] = {noise(rng), -2.0 * noise(rng)};
      mean.add(0.0, 0.7, v);
      batch_sum += v[0];
      sum0 += v[0];
      sum1 += v[1];
      ++n;
    }
    batch_means.push_back(batch_sum / count);
    mean.close_period(scatter);
  }
  mean.close_period(scatter);  // an empty batch adds nothing
  EXPECT_FALSE(mean.fits_drift());
  EXPECT_EQ(mean.samples(), n);
  EXPECT_NEAR(values_of(mean, 1, 0, 0.2).value[0], sum0 / static_cast<double>(n), 1e-13);
  EXPECT_NEAR(values_of(mean, 1, 1, 0.2).value[0], sum1 / static_cast<double>(n), 1e-13);
  EXPECT_EQ(values_of(mean, 1, 0, 0.2).samples[0], n);
  EXPECT_EQ(mean.white_noise_gain(0.2)[0], 1.0 / static_cast<double>(n));
  ASSERT_EQ(scatter.n, 3.0);
  // Sums of deviations from the first batch's mean.
  EXPECT_EQ(scatter.v0[0], batch_means[0]);
  EXPECT_NEAR(scatter.v[0], (batch_means[1] - batch_means[0]) + (batch_means[2] - batch_means[0]), 1e-13);
}

}  // namespace
}  // namespace gyrocal
