// The accelerometer on the centrifuge (docs/accelerometer.md): the IEEE 1293
// output equation, the harmonic content of a revolution against the exact chain, why four gamma alias K3
// onto the scale (and the radius), the recovery of the eleven coefficients from their products, the delta
// method, and what one speed cannot separate.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"
#include "gyrocal/core/random.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/sensor/sensor.hpp"
#include "gyrocal/simulate/accelerometer_noise.hpp"
#include "gyrocal/solve/least_squares.hpp"

namespace gyrocal {
namespace {

constexpr double kUg = 1e-6;  // one ug (or urad, or ug/g^n) in g (rad, 1/g^n)
constexpr std::size_t kK1 = static_cast<std::size_t>(AccelCoefficient::K1);

/// The default accelerometer truth, in g and rad (the table's micro-units times 1e-6), by name.
struct Truth {
  double K0, K1, K2, K3, Kip, Kio, Kpo, Kpp, Koo, dp, d_o;
};
Truth truth_of(const Accelerometer& a) {
  const auto& v = a.coefficients.values;
  return {v[0] * kUg, v[1],       v[2] * kUg, v[3] * kUg, v[4] * kUg, v[5] * kUg,
          v[6] * kUg, v[7] * kUg, v[8] * kUg, v[9] * kUg, v[10] * kUg};
}

/// A perfect machine at the default site (Earth rate and gravity as configured), or with no Earth rate.
CentrifugeModel perfect_machine(bool earth_rate) {
  Site site;
  if (!earth_rate) site.earth_rate_rad_s = 0.0;
  return CentrifugeModel(site, CentrifugeGeometry{}, CentrifugeErrors{});
}

/// The radial level of docs/physics.md section 5, written here from the physics: omega R0 (omega + 2 we sin
/// lat) / g, the centripetal force and the radial Coriolis force of the arm's velocity.
double radial_level(const CentrifugeModel& m, double rate) {
  return rate * m.geometry().radius_m *
         (rate + 2.0 * m.site().earth_rate_rad_s * std::sin(m.site().latitude_rad)) / (m.site().gravity_m_s2);
}

/// The seven numbers of a revolution's harmonic content (DC, cos g, sin g, cos 2g, sin 2g, cos 3g, sin 3g)
/// of f over n equally spaced samples of one revolution of gamma: a discrete Fourier projection, exact for a
/// trigonometric polynomial of order < n/2.
constexpr int kHarmonicRows = 7;
template <class F>
std::array<double, kHarmonicRows> harmonic_content(const CentrifugeModel& m, double rate, double beta, int n,
                                                   F f) {
  std::array<double, kHarmonicRows> h{};
  const double period = 2.0 * std::numbers::pi / std::abs(rate);
  for (int k = 0; k < n; ++k) {
    const JointState j = spinning_joint_state(m, rate, beta, period * k / n);
    const double value = f(exact_inputs(m, j));
    const double g = j.gamma_rad();
    h[0] += value / n;
    for (int order = 1; order <= 3; ++order) {
      h[2 * order - 1] += 2.0 * value * std::cos(order * g) / n;
      h[2 * order] += 2.0 * value * std::sin(order * g) / n;
    }
  }
  return h;
}

/// Stacked rows of least squares: each row the sensor's design row reduced, and the output reduced by the
/// same operator.
struct Rows {
  std::vector<std::array<double, kNumAccelCoefficients + 2>>
      design;  // 11 products, then radius error, stretch
  std::vector<double> observed;
};

LeastSquaresProblem problem_of(const Rows& rows, std::size_t columns, double sigma) {
  LeastSquaresProblem p;
  const auto m = static_cast<Eigen::Index>(rows.observed.size());
  p.design.resize(m, static_cast<Eigen::Index>(columns));
  p.observations.resize(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    for (std::size_t j = 0; j < columns; ++j) p.design(i, static_cast<Eigen::Index>(j)) = rows.design[i][j];
    p.observations(i) = rows.observed[i];
  }
  if (sigma > 0.0) p.weights = Eigen::VectorXd::Constant(m, 1.0 / (sigma * sigma));
  for (std::size_t j = 0; j < columns; ++j) {
    p.names.emplace_back(j < kNumAccelCoefficients
                             ? std::string(kAccelerometerParameters[j].name)
                             : (j == kNumAccelCoefficients ? "radius_error" : "stretch"));
  }
  return p;
}

/// The test plan of docs/accelerometer.md: for each rate (0 = the static set: main axis stopped, the
/// platform indexed to each gamma) and each beta, either the output at each of `gammas` on one revolution
/// (values at gamma), or (harmonic = true) each spinning dwell's harmonic content from 64 samples.
/// With radius = true, two more columns: d output / d radius_error (m) and d output / d radius_stretch
/// (m/(rad/s)^2), by central differences of the exact chain.
Rows plan_rows(const Scenario& s, const Accelerometer& sensor, const std::vector<double>& rates,
               const std::vector<double>& betas_deg, const std::vector<double>& gammas_deg, bool harmonic,
               bool radius) {
  const CentrifugeModel m = s.model();
  auto shifted = [&s](double radius_error, double stretch) {
    CentrifugeErrors e = s.errors;
    e.radius_error_m += radius_error;
    e.radius_stretch_m_per_rad2_s2 += stretch;
    return CentrifugeModel(s.site, s.centrifuge, e);
  };
  constexpr double kStepR = 1e-4, kStepS = 1e-6;
  const CentrifugeModel r_plus = shifted(kStepR, 0), r_minus = shifted(-kStepR, 0);
  const CentrifugeModel s_plus = shifted(0, kStepS), s_minus = shifted(0, -kStepS);
  Rows rows;
  auto add = [&](auto evaluate) {  // evaluate(model, column) -> value of one reduced number
    std::array<double, kNumAccelCoefficients + 2> row{};
    for (std::size_t j = 0; j < kNumAccelCoefficients; ++j) row[j] = evaluate(m, static_cast<int>(j));
    if (radius) {
      row[kNumAccelCoefficients] = (evaluate(r_plus, -1) - evaluate(r_minus, -1)) / (2 * kStepR);
      row[kNumAccelCoefficients + 1] = (evaluate(s_plus, -1) - evaluate(s_minus, -1)) / (2 * kStepS);
    }
    rows.design.push_back(row);
    rows.observed.push_back(evaluate(m, -1));
  };
  // column -1: the sensor's output; column j: the j-th regressor of its design row.
  auto channel = [&sensor](const SensorInputs& in, int column) {
    return column < 0 ? sensor.output(in)
                      : sensor.design_row(in).regressors[static_cast<std::size_t>(column)];
  };
  for (double rate : rates) {
    for (double beta_deg : betas_deg) {
      const double beta = beta_deg * kDegToRad;
      if (rate == 0.0 || !harmonic) {
        for (double gamma_deg : gammas_deg) {
          const double gamma = gamma_deg * kDegToRad;
          add([&](const CentrifugeModel& mm, int column) {
            const JointState j =
                rate == 0.0 ? static_joint_state(mm, beta, gamma)
                            : spinning_joint_state(mm, rate, beta, time_at_gamma(mm, rate, gamma, 0));
            return channel(exact_inputs(mm, j), column);
          });
        }
        continue;
      }
      for (int h = 0; h < kHarmonicRows; ++h) {
        add([&](const CentrifugeModel& mm, int column) {
          return harmonic_content(mm, rate, beta, 64, [&](const SensorInputs& in) {
            return channel(in, column);
          })[static_cast<std::size_t>(h)];
        });
      }
    }
  }
  return rows;
}

std::vector<double> evenly(int n) {
  std::vector<double> g;
  for (int k = 0; k < n; ++k) g.push_back(360.0 * k / n);
  return g;
}

const std::vector<double> kFourBetas = {0.0, 180.0, 90.0, 270.0};

// ---------------------------------------------------------------------------------------------------------

TEST(Accelerometer, OutputIsIeee1293EquationAndLinearInTheProducts) {
  Accelerometer a;
  a.coefficients[AccelCoefficient::K1] = 2.5;
  const Truth t = truth_of(a);
  const Eigen::Vector3d f(-7.3, 2.1, 0.6);
  const double ai = f.x(), ap = f.y(), ao = f.z();
  const double expected =
      t.K1 * (t.K0 + ai + t.K2 * ai * ai + t.K3 * ai * ai * ai + t.Kip * ai * ap + t.Kio * ai * ao +
              t.Kpo * ap * ao + t.Kpp * ap * ap + t.Koo * ao * ao + t.dp * ap + t.d_o * ao);
  SensorInputs in;
  in.specific_force_g = f;
  EXPECT_NEAR(a.output(in), expected, 1e-15 * std::abs(expected));
  const DesignRow row = a.design_row(in);
  ASSERT_EQ(row.size, kNumAccelCoefficients);
  const Eigen::VectorXd u = a.products();
  double linear = row.known;
  for (std::size_t j = 0; j < row.size; ++j) linear += row.regressors[j] * u(static_cast<Eigen::Index>(j));
  EXPECT_NEAR(linear, expected, 1e-14 * std::abs(expected));
  EXPECT_EQ(std::string(a.unknown_names()[0]), "K1*K0");
  EXPECT_EQ(std::string(a.unknown_names()[kK1]), "K1");
}

// docs/accelerometer.md's table of a revolution's harmonic content, against the exact chain. With no
// Earth rate the table is exact (to rounding); with the Earth rate as configured, Ar carries the radial
// Coriolis term, and the vertical Coriolis force c cos(gamma), c = 2 omega R0 we cos(lat) / g (1.1e-4 g at
// 9.9 rad/s), adds c times d(E/K1)/d(a_up) to the first harmonic: the table's Ar alone would miss it by far
// more than the tolerance, which covers c's products with the coefficients (below 1e-8 g).
void check_harmonic_content(double beta_deg, bool earth_rate) {
  const CentrifugeModel m = perfect_machine(earth_rate);
  Accelerometer a;
  const Truth t = truth_of(a);
  const double rate = 9.9;
  const double ar = radial_level(m, rate);
  const double c = 2.0 * rate * m.geometry().radius_m * m.site().earth_rate_rad_s *
                   std::cos(m.site().latitude_rad) / m.site().gravity_m_s2;
  const std::array<double, kHarmonicRows> h =
      harmonic_content(m, rate, beta_deg * kDegToRad, 64,
                       [&a](const SensorInputs& in) { return a.output(in) / a.coefficients.values[kK1]; });
  std::array<double, kHarmonicRows> expected{};
  const double ar2 = ar * ar, ar3 = ar2 * ar;
  if (beta_deg == 0.0) {  // a_i = -Ar cos g, a_p = -Ar sin g, a_o = 1 (+ c cos g)
    expected = {t.K0 + t.Koo + t.d_o + (t.K2 + t.Kpp) * ar2 / 2,
                -ar * (1 + t.Kio) - 0.75 * t.K3 * ar3 + c * (t.d_o + 2 * t.Koo),
                -ar * (t.Kpo + t.dp),
                (t.K2 - t.Kpp) * ar2 / 2,
                t.Kip * ar2 / 2,
                -t.K3 * ar3 / 4,
                0.0};
  } else {  // beta = 90: a_i = 1 (+ c cos g), a_p = -Ar sin g, a_o = Ar cos g
    expected = {t.K0 + 1 + t.K2 + t.K3 + (t.Kpp + t.Koo) * ar2 / 2,
                ar * (t.Kio + t.d_o) + c * (1 + 2 * t.K2 + 3 * t.K3),
                -ar * (t.Kip + t.dp),
                (t.Koo - t.Kpp) * ar2 / 2,
                -t.Kpo * ar2 / 2,
                0.0,
                0.0};
  }
  const double tolerance = earth_rate ? 1e-8 : 1e-12;
  if (earth_rate) {
    EXPECT_GT(c, 1e4 * tolerance);  // the vertical Coriolis term is real, and checked
  }
  const char* names[kHarmonicRows] = {"DC", "cos", "sin", "cos2", "sin2", "cos3", "sin3"};
  for (int k = 0; k < kHarmonicRows; ++k) {
    EXPECT_NEAR(h[static_cast<std::size_t>(k)], expected[static_cast<std::size_t>(k)], tolerance)
        << names[k] << " at beta " << beta_deg << (earth_rate ? " with" : " without") << " Earth rate";
  }
}

TEST(AccelerometerHarmonics, Beta0WithoutEarthRateIsTheTable) {
  check_harmonic_content(0.0, false);
}
TEST(AccelerometerHarmonics, Beta90WithoutEarthRateIsTheTable) {
  check_harmonic_content(90.0, false);
}
TEST(AccelerometerHarmonics, Beta0WithEarthRateAddsVerticalCoriolis) {
  check_harmonic_content(0.0, true);
}
TEST(AccelerometerHarmonics, Beta90WithEarthRateAddsVerticalCoriolis) {
  check_harmonic_content(90.0, true);
}

// cos^3 g = cos g at g = 0, 90, 180, 270 deg: at one g-level (the centrifuge positions beta = 0, 180 of one
// rate), the K3 column is Ar^2 times K1's: K3 alone is unidentifiable, only the scale at that g-level
// K1 + 1e-6 Ar^2 (K1 K3) is. Seven or eight gamma resolve the third harmonic and K3 with it.
TEST(AccelerometerAliasing, FourGammasFoldK3OntoTheScaleSevenDoNot) {
  Scenario s = default_scenario();
  s.errors = CentrifugeErrors{};
  s.site.earth_rate_rad_s = 0.0;
  const Accelerometer a;
  const double rate = 9.9;
  const double ar = radial_level(s.model(), rate);
  for (int n : {4, 7, 8}) {
    // Read on three revolutions (identical on a perfect machine), so that there are more rows than unknowns.
    std::vector<double> gammas;
    for (int revolution = 0; revolution < 3; ++revolution)
      for (double g : evenly(n)) gammas.push_back(g);
    const Rows rows = plan_rows(s, a, {rate}, {0.0, 180.0}, gammas, false, false);
    const LeastSquaresSolution sol = solve_least_squares(problem_of(rows, kNumAccelCoefficients, 0.0));
    Eigen::VectorXd k3 = Eigen::VectorXd::Zero(kNumAccelCoefficients);
    k3(static_cast<Eigen::Index>(AccelCoefficient::K3)) = 1.0;
    Eigen::VectorXd scale_at_level = Eigen::VectorXd::Zero(kNumAccelCoefficients);
    scale_at_level(static_cast<Eigen::Index>(kK1)) = 1.0;
    scale_at_level(static_cast<Eigen::Index>(AccelCoefficient::K3)) = kUg * ar * ar;
    // The columns themselves: K3's is 1e-6 Ar^2 times K1's at four gamma, far from it at seven or eight.
    double residual = 0.0, norm = 0.0;
    for (const auto& row : rows.design) {
      residual += std::pow(row[static_cast<std::size_t>(AccelCoefficient::K3)] - kUg * ar * ar * row[kK1], 2);
      norm += std::pow(row[static_cast<std::size_t>(AccelCoefficient::K3)], 2);
    }
    if (n == 4) {
      EXPECT_LT(std::sqrt(residual / norm), 1e-12);
    } else {
      EXPECT_GT(std::sqrt(residual / norm), 0.1) << n << " gammas";
    }
    EXPECT_EQ(evaluate_combination(sol, k3).identifiable, n != 4) << n << " gammas";
    EXPECT_TRUE(evaluate_combination(sol, scale_at_level).identifiable) << n << " gammas";
    EXPECT_EQ(evaluate_combination(sol, Eigen::VectorXd::Unit(kNumAccelCoefficients, kK1)).identifiable,
              n != 4)
        << n << " gammas";
  }
}

// docs/accelerometer.md, "Feasibility": static + 6 + 12 rad/s, beta of four angles, 2 ug per reduced
// value, the eleven products with the radius error and the arm's stretch. Values at four gamma keep every
// column (rank 13) but alias K3 with the scale and so with the radius: sigma(K3) 2.8 ug/g^3, sigma(radius)
// 150 um. Eight values per dwell (the harmonic content) give sigma(K3) 9e-4 ug/g^3, sigma(radius) 0.4 um,
// sigma(stretch) 0.002 um/(rad/s)^2.
TEST(AccelerometerAliasing, TheRadiusNeedsTheThirdHarmonic) {
  const Scenario s = default_scenario();
  const Accelerometer a;
  const double sigma = 2.0 * kUg;
  const std::size_t columns = kNumAccelCoefficients + 2;
  const std::size_t k3 = static_cast<std::size_t>(AccelCoefficient::K3);
  const auto solve = [&](int gammas) {
    const Rows rows = plan_rows(s, a, {0.0, 6.0, 12.0}, kFourBetas, evenly(gammas), false, true);
    return solve_least_squares(problem_of(rows, columns, sigma));
  };
  const LeastSquaresSolution four = solve(4), eight = solve(8);
  EXPECT_EQ(four.rank, 13);
  EXPECT_EQ(eight.rank, 13);
  const auto std_of = [](const LeastSquaresSolution& sol, std::size_t j) {
    return sol.std(static_cast<Eigen::Index>(j));
  };
  // K3's product in ug (K1 = 1), the radius in um, the stretch in um/(rad/s)^2.
  const double k3_four = std_of(four, k3), r_four = std_of(four, columns - 2) * 1e6;
  const double k3_eight = std_of(eight, k3), r_eight = std_of(eight, columns - 2) * 1e6;
  const double s_eight = std_of(eight, columns - 1) * 1e6;
  std::printf(
      "four gamma: sigma(K3) %.3g ug/g^3, sigma(radius) %.3g um; eight: %.3g ug/g^3, %.3g um, "
      "sigma(stretch) %.3g um/(rad/s)^2\n",
      k3_four, r_four, k3_eight, r_eight, s_eight);
  EXPECT_NEAR(k3_four, 2.8, 0.3);
  EXPECT_NEAR(r_four, 150.0, 15.0);
  EXPECT_NEAR(k3_eight, 9e-4, 1e-4);
  EXPECT_NEAR(r_eight, 0.4, 0.05);
  EXPECT_NEAR(s_eight, 0.002, 0.0005);
}

// Noise-free harmonic content of a static set and two speeds on the default machine (its wobbles and
// tilts included: the same reduction of data and model keeps the identification exact): the eleven
// coefficients come back from their products.
TEST(AccelerometerRecovery, ElevenCoefficientsFromTheHarmonicContent) {
  const Scenario s = default_scenario();
  Accelerometer a;
  a.coefficients[AccelCoefficient::K1] = 1.002;
  const Rows rows = plan_rows(s, a, {0.0, 6.0, 12.0}, kFourBetas, evenly(8), true, false);
  const LeastSquaresSolution sol = solve_least_squares(problem_of(rows, kNumAccelCoefficients, 0.0));
  ASSERT_EQ(sol.rank, static_cast<int>(kNumAccelCoefficients));
  const ParameterEstimates e = a.from_products(sol.estimate, sol.covariance, sol.identifiable);
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
    const double tolerance = k == kK1 ? 1e-9 : 1e-4;  // K1 per g; the others in ug, ug/g^n, urad
    EXPECT_NEAR(e.values(static_cast<Eigen::Index>(k)), a.coefficients.values[k], tolerance)
        << kAccelerometerParameters[k].name;
    EXPECT_TRUE(e.identifiable[k]) << kAccelerometerParameters[k].name;
  }
}

// The delta method's covariance of the coefficients against an independent route: the Jacobian of
// u -> (K1, u_x / K1) by central differences, and a Monte Carlo of the whole fit (400 trials: each sigma
// within 15 %, four of the standard error of a sample sigma).
TEST(AccelerometerRecovery, DeltaMethodAgreesWithFiniteDifferencesAndMonteCarlo) {
  const Scenario s = default_scenario();
  Accelerometer a;
  a.coefficients[AccelCoefficient::K1] = 2.5;  // output units per g: the division matters
  const double sigma = 2.0 * kUg * 2.5;        // 2 ug referred to the input
  const Rows rows = plan_rows(s, a, {0.0, 6.0, 12.0}, kFourBetas, evenly(8), true, false);
  LeastSquaresProblem problem = problem_of(rows, kNumAccelCoefficients, sigma);
  const LeastSquaresSolution sol = solve_least_squares(problem);
  const ParameterEstimates e = a.from_products(sol.estimate, sol.covariance, sol.identifiable);

  const auto n = static_cast<Eigen::Index>(kNumAccelCoefficients);
  const auto coefficients_of = [&](const Eigen::VectorXd& u) {
    Eigen::VectorXd k(n);
    for (Eigen::Index j = 0; j < n; ++j) k(j) = j == static_cast<Eigen::Index>(kK1) ? u(j) : u(j) / u(kK1);
    return k;
  };
  Eigen::MatrixXd jacobian(n, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const double h = 1e-6 * std::max(1.0, std::abs(sol.estimate(j)));
    Eigen::VectorXd up = sol.estimate, down = sol.estimate;
    up(j) += h;
    down(j) -= h;
    jacobian.col(j) = (coefficients_of(up) - coefficients_of(down)) / (2 * h);
  }
  const Eigen::MatrixXd covariance = jacobian * sol.covariance * jacobian.transpose();
  for (Eigen::Index k = 0; k < n; ++k) {
    EXPECT_NEAR(e.std(k), std::sqrt(covariance(k, k)), 1e-6 * e.std(k)) << kAccelerometerParameters[k].name;
  }
  const Eigen::Index k3 = static_cast<Eigen::Index>(AccelCoefficient::K3);
  const double correlation = covariance(kK1, k3) / std::sqrt(covariance(kK1, kK1) * covariance(k3, k3));
  EXPECT_NEAR(e.covariance(kK1, k3) / (e.std(kK1) * e.std(k3)), correlation, 1e-6);

  constexpr int kTrials = 400;
  RandomSource random(19);
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(n), sum2 = Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd clean = problem.observations;
  for (int trial = 0; trial < kTrials; ++trial) {
    for (Eigen::Index i = 0; i < clean.size(); ++i)
      problem.observations(i) = clean(i) + sigma * random.normal();
    const LeastSquaresSolution noisy = solve_least_squares(problem);
    const Eigen::VectorXd k = a.from_products(noisy.estimate, noisy.covariance, noisy.identifiable).values;
    sum += k;
    sum2 += k.cwiseProduct(k);
  }
  for (Eigen::Index k = 0; k < n; ++k) {
    const double mean = sum(k) / kTrials;
    const double sample_std = std::sqrt((sum2(k) - kTrials * mean * mean) / (kTrials - 1));
    EXPECT_NEAR(sample_std / e.std(k), 1.0, 0.15) << kAccelerometerParameters[k].name;
  }
}

// One speed: a_i^2 + a_p^2 + a_o^2 = 1 + Ar^2 at every position, so K0, K2, Kpp, Koo cannot be told apart
// (docs/accelerometer.md): they, and only they, are named unidentifiable, and the null space is the
// direction that adds c to K2, Kpp, Koo and subtracts (1 + Ar^2) c from K0.
TEST(AccelerometerIdentifiability, OneSpeedLeavesK0K2KppKooUnidentifiable) {
  const Scenario s = default_scenario();
  const Accelerometer a;
  const double rate = 9.9;
  const Rows rows = plan_rows(s, a, {rate}, kFourBetas, evenly(8), true, false);
  LeastSquaresProblem p = problem_of(rows, kNumAccelCoefficients, 2.0 * kUg);
  p.parameter_scales = Eigen::VectorXd::Constant(kNumAccelCoefficients, 1.0);  // 1 ug, 1 ug/g^n, 1 urad
  p.parameter_scales(static_cast<Eigen::Index>(kK1)) = 1e-6;                   // 1 ppm of scale
  const LeastSquaresSolution sol = solve_least_squares(p);
  const std::vector<std::string> expected_unidentifiable = {"K0", "K2", "Kpp", "Koo"};
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k) {
    const std::string name(kAccelerometerParameters[k].name);
    const bool expected = std::find(expected_unidentifiable.begin(), expected_unidentifiable.end(), name) ==
                          expected_unidentifiable.end();
    EXPECT_EQ(sol.identifiable[k], expected) << name;
  }
  ASSERT_EQ(sol.null_space.cols(), 1);
  const double ar = radial_level(s.model(), rate);
  Eigen::VectorXd direction = Eigen::VectorXd::Zero(kNumAccelCoefficients);
  direction(static_cast<Eigen::Index>(AccelCoefficient::K0)) = -(1.0 + ar * ar);
  direction(static_cast<Eigen::Index>(AccelCoefficient::K2)) = 1.0;
  direction(static_cast<Eigen::Index>(AccelCoefficient::Kpp)) = 1.0;
  direction(static_cast<Eigen::Index>(AccelCoefficient::Koo)) = 1.0;
  direction.normalize();
  const Eigen::VectorXd null = sol.null_space.col(0);
  EXPECT_GT(std::abs(null.dot(direction)), 1.0 - 1e-6) << null.transpose();
  // The products follow the coefficients: K0, K2, Kpp, Koo come back unidentifiable, the others with a std.
  const ParameterEstimates e = a.from_products(sol.estimate, sol.covariance, sol.identifiable);
  for (std::size_t k = 0; k < kNumAccelCoefficients; ++k)
    EXPECT_EQ(std::isfinite(e.std(static_cast<Eigen::Index>(k))), static_cast<bool>(e.identifiable[k]));
}

// The noise generator: white noise of density N ug/sqrt(Hz) gives a per-sample sigma N sqrt(fs) referred to
// the input, times K1 in output units; with no noise the output is the input, bit for bit.
TEST(AccelerometerNoise, WhiteNoiseDensityAndSilence) {
  AccelerometerNoise noise;
  noise.velocity_random_walk_ug_rt_hz = 10.0;
  const double fs = 200.0, k1 = 2.0, clean = 9.5;
  AccelerometerNoiseGenerator generator(noise, k1, fs, 7);
  constexpr int kSamples = 20000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < kSamples; ++i) {
    const double d = (generator.next(clean) - clean) / k1 / kUg;  // ug referred to the input
    sum += d;
    sum2 += d * d;
  }
  const double expected = 10.0 * std::sqrt(fs);
  const double sample_std = std::sqrt(sum2 / kSamples - (sum / kSamples) * (sum / kSamples));
  EXPECT_NEAR(sample_std / expected, 1.0, 4.0 / std::sqrt(2.0 * kSamples));
  AccelerometerNoiseGenerator silent(AccelerometerNoise{}, k1, fs, 7);
  EXPECT_EQ(silent.next(clean), clean);
  AccelerometerNoise bad;
  bad.bias_instability_ug = -1.0;
  try {
    AccelerometerNoiseGenerator refused(bad, k1, fs, 7);
    FAIL() << "a negative bias instability was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("accelerometer.noise.bias_instability_ug"), std::string::npos)
        << e.what();
  }
}

// The gyro behind the sensor concept is model/gyro.hpp's gyro: the same output as the simulator's formula,
// and under drift+rate the step back divides (1 + e) out of the misalignments' products.
TEST(GyroSensor, WrapsTheGyroModel) {
  const Scenario s = default_scenario();
  Gyro g;
  g.drift = s.gyro;
  g.rate.scale_factor_error_ppm = 200.0;
  g.rate.input_axis_misalignment_O_arcsec = 3.0;
  g.rate.input_axis_misalignment_S_arcsec = -2.0;
  const SensorInputs in = exact_inputs(s.model(), spinning_joint_state(s.model(), 9.9, 0.3, 1.234));
  EXPECT_EQ(g.output(in),
            sensed_rate_deg_h(g.rate, in.rate_rad_s) + drift_deg_h(g.drift, in.specific_force_g));
  EXPECT_EQ(g.num_unknowns(), kNumGyroCoefficients);
  g.model = GyroModel::kDriftRate;
  ASSERT_EQ(g.num_unknowns(), kNumGyroCoefficients + kNumRateTerms);
  EXPECT_TRUE(g.parameters()[kNumGyroCoefficients].identified);
  // The products of the truth reproduce the output through the design row.
  const double e = g.rate.scale_factor_error_ppm;
  Eigen::VectorXd u(static_cast<Eigen::Index>(g.num_unknowns()));
  for (std::size_t k = 0; k < kNumGyroCoefficients; ++k) u(static_cast<Eigen::Index>(k)) = g.drift.values[k];
  u(10) = e;
  u(11) = (1 + e * 1e-6) * g.rate.input_axis_misalignment_O_arcsec;
  u(12) = (1 + e * 1e-6) * g.rate.input_axis_misalignment_S_arcsec;
  const DesignRow row = g.design_row(in);
  double linear = row.known;
  for (std::size_t j = 0; j < row.size; ++j) linear += row.regressors[j] * u(static_cast<Eigen::Index>(j));
  EXPECT_NEAR(linear, g.output(in), 1e-9);
  const ParameterEstimates back =
      g.from_products(u, Eigen::MatrixXd::Identity(13, 13) * 1e-4, std::vector<bool>(13, true));
  EXPECT_NEAR(back.values(11), 3.0, 1e-12);
  EXPECT_NEAR(back.values(12), -2.0, 1e-12);
  // Sensor as a variant: the same output through std::visit.
  const Sensor sensor = g;
  EXPECT_EQ(sensor_output(sensor, in), g.output(in));
  EXPECT_EQ(kind_of(sensor), SensorKind::kGyro);
  EXPECT_EQ(parse_sensor_kind("accelerometer"), SensorKind::kAccelerometer);
  EXPECT_FALSE(parse_sensor_kind("magnetometer").has_value());
}

// ---------------------------------------------------------------------------------------------------------
// Configuration: [sensor] kind, [accelerometer], [accelerometer.noise] (docs/contract.md).

/// The message of the Error that parsing text throws (empty when it parses).
std::string refusal(const std::string& text) {
  try {
    parse_scenario(text, "accel.toml");
  } catch (const Error& e) {
    return e.what();
  }
  return {};
}

TEST(AccelerometerConfig, KeysAreReadAndWrittenBack) {
  const Scenario s = parse_scenario(
      "[sensor]\nkind = \"accelerometer\"\n[accelerometer]\nK0_ug = -20.0\nK1 = 1.5\nK3_ug_g3 = 2\n"
      "delta_o_urad = 12.5\n[accelerometer.noise]\nvelocity_random_walk_ug_rt_hz = 3.0\nquantization_ug = "
      "0.5\n",
      "accel.toml");
  EXPECT_EQ(s.sensor_kind, SensorKind::kAccelerometer);
  const AccelerometerCoefficients& c = s.accelerometer.coefficients;
  EXPECT_EQ(c[AccelCoefficient::K0], -20.0);
  EXPECT_EQ(c[AccelCoefficient::K1], 1.5);
  EXPECT_EQ(c[AccelCoefficient::K3], 2.0);
  EXPECT_EQ(c[AccelCoefficient::delta_o], 12.5);
  EXPECT_EQ(c[AccelCoefficient::Kip], 10.0);  // the contract's default where the file is silent
  EXPECT_EQ(s.accelerometer.noise.velocity_random_walk_ug_rt_hz, 3.0);
  EXPECT_EQ(s.accelerometer.noise.quantization_ug, 0.5);
  EXPECT_TRUE(std::holds_alternative<Accelerometer>(s.sensor()));

  const std::string text = scenario_to_toml(s);
  EXPECT_EQ(text.find("[gyro"), std::string::npos) << "an accelerometer file holds no gyro section";
  EXPECT_EQ(text.find("gyro_model"), std::string::npos);
  const Scenario back = parse_scenario(text, "written.toml");
  EXPECT_EQ(back.sensor_kind, SensorKind::kAccelerometer);
  EXPECT_EQ(back.accelerometer.coefficients.values, c.values);
  EXPECT_EQ(back.accelerometer.noise.quantization_ug, 0.5);

  // A gyro scenario is written as before: no [sensor] section, and it is a gyro.
  const Scenario gyro = default_scenario();
  EXPECT_EQ(gyro.sensor_kind, SensorKind::kGyro);
  EXPECT_EQ(scenario_to_toml(gyro).find("[sensor]"), std::string::npos);
  EXPECT_EQ(scenario_to_toml(gyro).find("[accelerometer"), std::string::npos);
  EXPECT_TRUE(std::holds_alternative<Gyro>(gyro.sensor()));
}

TEST(AccelerometerConfig, TheOtherSensorsKeysAreRefusedByName) {
  const std::string accel = "[sensor]\nkind = \"accelerometer\"\n";
  EXPECT_EQ(refusal(accel + "[gyro]\ndF = 1.0\n"),
            "accel.toml, line 4: gyro.dF is a gyro key, but sensor.kind is \"accelerometer\".");
  EXPECT_EQ(refusal(accel + "[gyro.noise]\nangle_random_walk_deg_rt_h = 0.1\n"),
            "accel.toml, line 4: gyro.noise.angle_random_walk_deg_rt_h is a gyro key, but sensor.kind is "
            "\"accelerometer\".");
  EXPECT_EQ(
      refusal(accel + "[calibration]\ngyro_model = \"drift\"\n"),
      "accel.toml, line 4: calibration.gyro_model is a gyro key, but sensor.kind is \"accelerometer\".");
  EXPECT_EQ(refusal("[accelerometer]\nK2_ug_g2 = 1.0\n"),
            "accel.toml, line 2: accelerometer.K2_ug_g2 is an accelerometer key, but the sensor is the gyro "
            "(sensor.kind absent or \"gyro\"): set [sensor] kind = \"accelerometer\" or remove the key.");
  EXPECT_NE(refusal("[sensor]\nkind = \"gyro\"\n[accelerometer.noise]\nquantization_ug = 1\n")
                .find("accelerometer.noise.quantization_ug is an accelerometer key"),
            std::string::npos);
  EXPECT_EQ(refusal("[sensor]\nkind = \"magnetometer\"\n"),
            "accel.toml, line 2: sensor.kind must be \"gyro\", \"accelerometer\" or \"imu\", not "
            "\"magnetometer\".");
  EXPECT_EQ(
      refusal(accel + "[accelerometer]\nK1 = 0\n"),
      "accel.toml, line 4: accelerometer.K1 must be a non-zero scale factor (output units per g), not 0.");
  EXPECT_NE(refusal(accel + "[accelerometer.noise]\nbias_instability_ug = -1\n")
                .find("accelerometer.noise.bias_instability_ug must be"),
            std::string::npos);
  EXPECT_NE(refusal(accel + "[accelerometer]\nK4_ug_g4 = 1\n").find("unknown key accelerometer.K4_ug_g4"),
            std::string::npos);
  EXPECT_EQ(refusal(accel + "[accelerometer]\nK0_ug = 1\n"), "");
}

}  // namespace
}  // namespace gyrocal
