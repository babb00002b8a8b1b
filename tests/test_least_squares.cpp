// The least-squares core (docs/physics.md section 9): NIST StRD linear regression sets graded by LRE,
// rank deficiency found with its null direction and estimable combinations, honest uncertainty
// (z-scores of known truth), and bad inputs refused with their message.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "gyrocal/core/error.hpp"
#include "gyrocal/solve/least_squares.hpp"

namespace gyrocal {
namespace {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

// ---------------------------------------------------------------------------------------------------
// NIST StRD

struct Certified {
  std::string text;  // as printed, to count its significant digits
  double value = 0.0;
};

struct NistSet {
  std::string name;
  std::string model;
  LeastSquaresProblem problem;
  std::vector<Certified> estimate, sd;
  double residual_sd = std::numeric_limits<double>::quiet_NaN();  // only where NIST certifies it
};

// Significant digits of a certified number as printed ("0.107938612033077E-03" has 15).
int significant_digits(const std::string& text) {
  int digits = 0;
  bool started = false;
  for (char ch : text) {
    if (ch == 'E' || ch == 'e') break;
    if (ch < '0' || ch > '9') continue;
    if (ch != '0') started = true;
    if (started) ++digits;
  }
  return digits;
}

// Log relative error (the README's grading), absolute where the certified value is 0. NIST prints
// 15 significant digits: an estimate that rounds to the printed value has every certified digit right,
// and is credited with that many digits (a correct double of NoInt1's 251/121 = 2.0743801652892562 is
// 1.8e-15 away from the printed 2.07438016528926, an LRE of 14.74 that no double can beat).
double raw_lre(double estimate, double certified) {
  const double e =
      certified == 0.0 ? std::abs(estimate) : std::abs(estimate - certified) / std::abs(certified);
  return e == 0.0 ? 99.0 : -std::log10(e);
}

double lre(double estimate, const Certified& certified) {
  if (!std::isfinite(estimate)) return 0.0;
  // A certified 0 ("0.000000000000000") is graded absolutely, to the 15 printed decimals.
  const int digits = certified.value == 0.0 ? 15 : significant_digits(certified.text);
  if (certified.value == 0.0) {
    const double e = std::abs(estimate);
    return e == 0.0 ? static_cast<double>(digits) : std::min(static_cast<double>(digits), -std::log10(e));
  }
  char rounded[64];
  std::snprintf(rounded, sizeof rounded, "%.*e", digits - 1, estimate);
  if (std::stod(rounded) == certified.value) return static_cast<double>(digits);
  const double e = std::abs(estimate - certified.value) / std::abs(certified.value);
  return e == 0.0 ? static_cast<double>(digits) : std::min(static_cast<double>(digits), -std::log10(e));
}

// Reads a set and builds its design from the "# model:" line:
//   "y = B0 + B1*x + ... + Bk*x^k"  polynomial of degree k (the largest power written) with intercept;
//   "y = B0 + B1*x1 + ... + B6*x6"  Longley: the data columns x1..x6 and an intercept;
//   "y = B1*x (no intercept)"       NoInt1: x alone.
// Powers are computed in long double and rounded once, so that the design is the data's best double.
NistSet load_nist(const std::string& name) {
  NistSet set;
  set.name = name;
  const std::string path = std::string(GYROCAL_TEST_DATA_DIR) + "/nist-strd/" + name + ".txt";
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    if (line[0] == '#') {
      std::istringstream words(line.substr(1));
      std::string tag;
      words >> tag;
      if (tag == "model:") {
        set.model = line.substr(line.find("model:") + 6);
      } else if (tag == "residual_standard_deviation") {
        words >> set.residual_sd;
      } else if (tag.size() > 1 && tag[0] == 'B' && std::isdigit(static_cast<unsigned char>(tag[1]))) {
        Certified e, s;
        words >> e.text >> s.text;
        e.value = std::stod(e.text);
        s.value = std::stod(s.text);
        set.estimate.push_back(e);
        set.sd.push_back(s);
      }
      continue;
    }
    std::istringstream words(line);
    std::vector<double> row;
    std::string word;
    while (words >> word) row.push_back(std::stod(word));
    rows.push_back(row);
  }
  const bool intercept = set.model.find("B0") != std::string::npos;
  const bool multiple = set.model.find("x1") != std::string::npos;
  int degree = 1;
  for (size_t at = set.model.find("x^"); at != std::string::npos; at = set.model.find("x^", at + 2)) {
    degree = std::max(degree, std::stoi(set.model.substr(at + 2)));
  }
  const Index m = static_cast<Index>(rows.size());
  const Index predictors = multiple ? static_cast<Index>(rows[0].size()) - 1 : degree;
  const Index n = predictors + (intercept ? 1 : 0);
  if (n != static_cast<Index>(set.estimate.size()))
    throw std::runtime_error(name + ": model and certificate differ");
  set.problem.design.resize(m, n);
  set.problem.observations.resize(m);
  for (Index i = 0; i < m; ++i) {
    const auto& row = rows[static_cast<size_t>(i)];
    set.problem.observations(i) = row[0];
    Index c = 0;
    if (intercept) set.problem.design(i, c++) = 1.0;
    for (Index k = 1; k <= predictors; ++k) {
      set.problem.design(i, c++) =
          multiple ? row[static_cast<size_t>(k)]
                   : static_cast<double>(std::pow(static_cast<long double>(row[1]), static_cast<int>(k)));
    }
  }
  for (Index j = 0; j < n; ++j) set.problem.names.push_back("B" + std::to_string(j + (intercept ? 0 : 1)));
  return set;
}

struct NistCase {
  const char* name;
  double required_estimate_lre;  // the figures (LAPACK's SVD on column-scaled data)
  double required_sd_lre;        // ours: at least this many digits of each certified standard deviation
};

class NistStrd : public ::testing::TestWithParam<NistCase> {};

TEST_P(NistStrd, CertifiedDigitsOrAnIllConditionedWarning) {
  const NistCase& c = GetParam();
  const NistSet set = load_nist(c.name);
  const LeastSquaresSolution sol = solve_least_squares(set.problem);
  ASSERT_EQ(sol.rank, static_cast<int>(set.estimate.size())) << sol.FullReport();

  double min_estimate_lre = 99, min_sd_lre = 99, min_raw_estimate = 99, min_raw_sd = 99;
  for (size_t j = 0; j < set.estimate.size(); ++j) {
    const Index k = static_cast<Index>(j);
    min_estimate_lre = std::min(min_estimate_lre, lre(sol.estimate(k), set.estimate[j]));
    min_sd_lre = std::min(min_sd_lre, lre(sol.std(k), set.sd[j]));
    min_raw_estimate = std::min(min_raw_estimate, raw_lre(sol.estimate(k), set.estimate[j].value));
    min_raw_sd = std::min(min_raw_sd, raw_lre(sol.std(k), set.sd[j].value));
    EXPECT_TRUE(sol.identifiable[j]);
  }
  // The table of docs/least_squares.md: graded LRE (raw formula in parentheses).
  std::printf("%-9s cond %9.3g  min LRE estimate %5.2f (%5.2f, required %4.1f)  sd %5.2f (%5.2f)  steps %d\n",
              c.name, sol.condition_number, min_estimate_lre, min_raw_estimate, c.required_estimate_lre,
              min_sd_lre, min_raw_sd, sol.refinement_steps);

  // For the record: what the refinement adds over the bare SVD solve.
  LeastSquaresOptions bare;
  bare.refinement_iterations = 0;
  const LeastSquaresSolution unrefined = solve_least_squares(set.problem, bare);
  double min_unrefined = 99;
  for (size_t j = 0; j < set.estimate.size(); ++j) {
    min_unrefined =
        std::min(min_unrefined, raw_lre(unrefined.estimate(static_cast<Index>(j)), set.estimate[j].value));
  }
  std::printf("%-9s without refinement: min raw LRE estimate %5.2f\n", c.name, min_unrefined);

  bool warned_ill_conditioned = false;
  for (const std::string& w : sol.warnings)
    warned_ill_conditioned |= w.find("Ill-conditioned") != std::string::npos;
  if (min_estimate_lre < c.required_estimate_lre) {
    EXPECT_TRUE(warned_ill_conditioned) << "fewer digits than required and no warning:\n" << sol.FullReport();
  }
  // We reach the required digits on every set; a regression should fail here, not hide behind the warning.
  EXPECT_GE(min_estimate_lre, c.required_estimate_lre) << sol.FullReport();
  EXPECT_GE(min_sd_lre, c.required_sd_lre) << sol.FullReport();
  if (std::isfinite(set.residual_sd)) {
    EXPECT_GE(lre(sol.residual_sigma, Certified{"304.854073561965", set.residual_sd}), 13.0)
        << sol.residual_sigma;
  }
}

INSTANTIATE_TEST_SUITE_P(LinearRegression, NistStrd,
                         ::testing::Values(NistCase{"Filip", 7.4, 6.5}, NistCase{"Longley", 10.6, 12.0},
                                           NistCase{"Pontius", 13.5, 13.0}, NistCase{"Wampler1", 9.8, 13.0},
                                           NistCase{"Wampler2", 12.6, 13.0}, NistCase{"Wampler3", 9.2, 12.0},
                                           NistCase{"Wampler4", 7.7, 12.0}, NistCase{"Wampler5", 5.7, 12.0},
                                           NistCase{"NoInt1", 14.8, 14.0}),
                         [](const auto& param_info) { return std::string(param_info.param.name); });

TEST(NistStrdExtra, FilipIsReportedIllConditioned) {
  const LeastSquaresSolution sol = solve_least_squares(load_nist("Filip").problem);
  bool warned = false;
  for (const std::string& w : sol.warnings) warned |= w.find("Ill-conditioned") != std::string::npos;
  EXPECT_TRUE(warned) << sol.FullReport();
  EXPECT_GT(sol.condition_number, 1e9);
}

TEST(NistStrdExtra, NoInt1MatchesTheExactRationalSolution) {
  // y = x + 70 for x = 60..70 through the origin: B1 = sum(x y)/sum(x^2) = 251/121; sd = 2/121.
  const LeastSquaresSolution sol = solve_least_squares(load_nist("NoInt1").problem);
  EXPECT_NEAR(sol.estimate(0), 251.0 / 121.0, 4e-16 * 251.0 / 121.0);
  EXPECT_NEAR(sol.std(0), 2.0 / 121.0, 1e-14 * 2.0 / 121.0);
}

TEST(NistStrdExtra, Wampler1FitsExactlyAndSaysSo) {
  const LeastSquaresSolution sol = solve_least_squares(load_nist("Wampler1").problem);
  EXPECT_LT(sol.residual_sigma, 1e-9);
  for (Index j = 0; j < 6; ++j) EXPECT_LT(sol.std(j), 1e-12);
}

// ---------------------------------------------------------------------------------------------------
// Rank deficiency

// Straight-line data y = 2 + 3 t + noise over t in [0, 2].
LeastSquaresProblem line_problem(int m, unsigned seed, double sigma) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  LeastSquaresProblem p;
  p.design.resize(m, 2);
  p.observations.resize(m);
  for (int i = 0; i < m; ++i) {
    const double t = 2.0 * i / (m - 1);
    p.design(i, 0) = 1.0;
    p.design(i, 1) = t;
    p.observations(i) = 2.0 + 3.0 * t + noise(rng);
  }
  return p;
}

bool has_warning(const LeastSquaresSolution& sol, const std::string& text) {
  for (const std::string& w : sol.warnings) {
    if (w.find(text) != std::string::npos) return true;
  }
  return false;
}

TEST(RankDeficient, TwoIdenticalColumnsGiveTheirDifferenceAsNullDirection) {
  const LeastSquaresProblem base = line_problem(30, 1, 0.1);
  const LeastSquaresSolution reference = solve_least_squares(base);
  LeastSquaresProblem p = base;
  p.design.conservativeResize(Eigen::NoChange, 3);
  p.design.col(2) = p.design.col(1);
  p.names = {"offset", "slope_a", "slope_b"};
  const LeastSquaresSolution sol = solve_least_squares(p);

  EXPECT_EQ(sol.rank, 2);
  ASSERT_EQ(sol.null_space.cols(), 1);
  const Eigen::Vector3d expected(0.0, std::sqrt(0.5), -std::sqrt(0.5));
  EXPECT_NEAR(std::abs(sol.null_space.col(0).dot(expected)), 1.0, 1e-12) << sol.null_space;
  EXPECT_TRUE(sol.identifiable[0]);
  EXPECT_FALSE(sol.identifiable[1]);
  EXPECT_FALSE(sol.identifiable[2]);
  EXPECT_TRUE(std::isinf(sol.std(1)));
  EXPECT_TRUE(has_warning(sol, "Unidentifiable direction")) << sol.FullReport();
  EXPECT_TRUE(has_warning(sol, "slope_a, slope_b")) << sol.FullReport();
  // Minimum norm splits the slope evenly.
  EXPECT_NEAR(sol.estimate(1), sol.estimate(2), 1e-12);

  // The identifiable combination is the slope of the two-parameter fit, with its uncertainty.
  const IdentifiableCombination sum = evaluate_combination(sol, Eigen::Vector3d(0, 1, 1));
  EXPECT_TRUE(sum.identifiable);
  EXPECT_NEAR(sum.value, reference.estimate(1), 1e-12);
  EXPECT_NEAR(sum.std, reference.std(1), 1e-12);
  EXPECT_EQ(sum.name, "+1 slope_a +1 slope_b");
  EXPECT_NEAR(sol.estimate(0), reference.estimate(0), 1e-12);
  EXPECT_NEAR(sol.std(0), reference.std(0), 1e-12);
  EXPECT_EQ(sol.dof, reference.dof);

  const IdentifiableCombination difference = evaluate_combination(sol, Eigen::Vector3d(0, 1, -1));
  EXPECT_FALSE(difference.identifiable);
  EXPECT_TRUE(std::isinf(difference.std));
}

TEST(RankDeficient, ColumnCombinationOfOthersIsFoundWithItsCoefficients) {
  // Columns 1, t, t^2 and c3 = 2 - 3 t + 0.5 t^2 (in other units: times 1000): null direction
  // proportional to (2, -3, 0.5, -1/1000).
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  const int m = 40;
  LeastSquaresProblem full, reduced;
  full.design.resize(m, 4);
  full.observations.resize(m);
  for (int i = 0; i < m; ++i) {
    const double t = -1.0 + 4.0 * i / (m - 1);
    full.design.row(i) << 1.0, t, t * t, 1000.0 * (2.0 - 3.0 * t + 0.5 * t * t);
    full.observations(i) = 1.0 - 0.5 * t + 0.25 * t * t + noise(rng);
  }
  full.weights = VectorXd::Constant(m, 1.0 / (0.05 * 0.05));
  full.names = {"c0", "c1", "c2", "c3"};
  reduced.design = full.design.leftCols(3);
  reduced.observations = full.observations;
  reduced.weights = full.weights;
  const LeastSquaresSolution ref = solve_least_squares(reduced);
  const LeastSquaresSolution sol = solve_least_squares(full);

  EXPECT_EQ(sol.rank, 3);
  ASSERT_EQ(sol.null_space.cols(), 1);
  const Eigen::Vector4d direction = Eigen::Vector4d(2.0, -3.0, 0.5, -1e-3).normalized();
  EXPECT_NEAR(std::abs(sol.null_space.col(0).dot(direction)), 1.0, 1e-12) << sol.null_space;
  for (size_t j = 0; j < 4; ++j) EXPECT_FALSE(sol.identifiable[j]);

  // Fitted function coefficients: c0 + 2000 c3, c1 - 3000 c3, c2 + 500 c3 equal the reduced fit's.
  const Eigen::Vector4d combos[3] = {{1, 0, 0, 2000}, {0, 1, 0, -3000}, {0, 0, 1, 500}};
  for (int k = 0; k < 3; ++k) {
    const IdentifiableCombination c = evaluate_combination(sol, combos[k]);
    EXPECT_TRUE(c.identifiable) << k;
    EXPECT_NEAR(c.value, ref.estimate(k), 1e-10) << k;
    EXPECT_NEAR(c.std, ref.std(k), 1e-10 * ref.std(k) + 1e-14) << k;
  }
  EXPECT_NEAR(sol.chi2, ref.chi2, 1e-9 * ref.chi2);
  EXPECT_FALSE(evaluate_combination(sol, Eigen::Vector4d(1, 0, 0, 0)).identifiable);
}

TEST(RankDeficient, NearlyDependentDirectionJudgedAgainstItsPredictedUncertainty) {
  // Column 2 = column 1 + 1e-7 * wiggle: numerically full rank, but with noise 0.01 the difference
  // of the two is determined only to ~1e4, far beyond a parameter scale of 1.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.01);
  const int m = 50;
  LeastSquaresProblem p;
  p.design.resize(m, 3);
  p.observations.resize(m);
  for (int i = 0; i < m; ++i) {
    const double t = static_cast<double>(i) / (m - 1);
    p.design.row(i) << 1.0, t, t + 1e-7 * std::sin(9.0 * t);
    p.observations(i) = 0.3 + 0.7 * t + noise(rng);
  }
  p.weights = VectorXd::Constant(m, 1e4);
  const LeastSquaresSolution kept = solve_least_squares(p);
  EXPECT_EQ(kept.rank, 3);
  EXPECT_GT(kept.std(1), 1e3);  // honest: huge, but finite

  p.parameter_scales = Eigen::Vector3d(1.0, 1.0, 1.0);
  const LeastSquaresSolution judged = solve_least_squares(p);
  EXPECT_EQ(judged.rank, 2);
  EXPECT_TRUE(has_warning(judged, "max_relative_std")) << judged.FullReport();
  const IdentifiableCombination slope = evaluate_combination(judged, Eigen::Vector3d(0, 1, 1));
  EXPECT_TRUE(slope.identifiable);
  EXPECT_NEAR(slope.value, 0.7, 5 * slope.std);
  EXPECT_LT(slope.std, 0.02);
}

TEST(RankDeficient, ZeroColumnIsUnidentifiable) {
  LeastSquaresProblem p = line_problem(10, 2, 0.1);
  p.design.conservativeResize(Eigen::NoChange, 3);
  p.design.col(2).setZero();
  const LeastSquaresSolution sol = solve_least_squares(p);
  EXPECT_EQ(sol.rank, 2);
  EXPECT_FALSE(sol.identifiable[2]);
  EXPECT_TRUE(sol.identifiable[0] && sol.identifiable[1]);
  EXPECT_EQ(sol.estimate(2), 0.0);
}

// ---------------------------------------------------------------------------------------------------
// Honest uncertainty

// Correlated, unevenly scaled design with a known truth and per-row noise.
void z_score_trial(bool give_weights) {
  const int trials = 400, m = 30, n = 4;
  std::mt19937_64 rng(give_weights ? 11 : 12);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  MatrixXd a(m, n);
  VectorXd sigma(m);
  for (int i = 0; i < m; ++i) {
    const double t = uniform(rng);
    a.row(i) << 1.0, 100.0 * t, 1e-3 * (t * t + 0.1 * unit(rng)), std::cos(3.0 * t) + 0.2 * unit(rng);
    sigma(i) = give_weights ? 0.05 + 0.3 * uniform(rng) : 0.2;
  }
  const Eigen::Vector4d truth(1.5, -0.02, 300.0, 0.7);
  std::vector<std::vector<double>> z(n);
  for (int trial = 0; trial < trials; ++trial) {
    LeastSquaresProblem p;
    p.design = a;
    p.observations = a * truth;
    for (int i = 0; i < m; ++i) p.observations(i) += sigma(i) * unit(rng);
    if (give_weights) p.weights = sigma.cwiseAbs2().cwiseInverse();
    const LeastSquaresSolution sol = solve_least_squares(p);
    ASSERT_EQ(sol.rank, n);
    for (int j = 0; j < n; ++j)
      z[static_cast<size_t>(j)].push_back((sol.estimate(j) - truth(j)) / sol.std(j));
  }
  for (int j = 0; j < n; ++j) {
    double mean = 0, square = 0;
    for (double v : z[static_cast<size_t>(j)]) mean += v / trials;
    for (double v : z[static_cast<size_t>(j)]) square += (v - mean) * (v - mean) / (trials - 1);
    const double sd = std::sqrt(square);
    EXPECT_GE(sd, 0.85) << "parameter " << j;
    EXPECT_LE(sd, 1.15) << "parameter " << j;
    EXPECT_LT(std::abs(mean), 0.2) << "parameter " << j;
  }
}

TEST(HonestUncertainty, ZScoresHaveUnitSpreadWithKnownWeights) {
  z_score_trial(true);
}
TEST(HonestUncertainty, ZScoresHaveUnitSpreadWithNoiseFromResiduals) {
  z_score_trial(false);
}

TEST(HonestUncertainty, Chi2WarnsWhenWeightsUnderstateTheNoise) {
  LeastSquaresProblem p = line_problem(50, 5, 0.1);
  p.weights = VectorXd::Constant(50, 1.0 / (0.01 * 0.01));  // claims sigma 0.01, truth 0.1
  const LeastSquaresSolution sol = solve_least_squares(p);
  EXPECT_TRUE(has_warning(sol, "larger than the weights imply")) << sol.FullReport();
  EXPECT_NEAR(sol.residual_sigma, 10.0, 3.0);
  EXPECT_NEAR(sol.std_from_residuals(1) / sol.std(1), sol.residual_sigma, 1e-12);

  p.weights = VectorXd::Constant(50, 1.0 / (0.1 * 0.1));
  EXPECT_FALSE(has_warning(solve_least_squares(p), "chi2"));
}

TEST(HonestUncertainty, ExactlyDeterminedWithoutWeightsHasUnknownStd) {
  LeastSquaresProblem p = line_problem(2, 9, 0.1);
  const LeastSquaresSolution sol = solve_least_squares(p);
  EXPECT_EQ(sol.dof, 0);
  EXPECT_TRUE(std::isnan(sol.std(0)));
  EXPECT_TRUE(has_warning(sol, "No degree of freedom"));
}

TEST(Reports, NameRankConditionAndWarnings) {
  LeastSquaresProblem p = line_problem(10, 4, 0.1);
  p.names = {"offset", "slope"};
  const LeastSquaresSolution sol = solve_least_squares(p);
  EXPECT_NE(sol.BriefReport().find("rank 2"), std::string::npos) << sol.BriefReport();
  EXPECT_NE(sol.FullReport().find("slope"), std::string::npos) << sol.FullReport();
}

// ---------------------------------------------------------------------------------------------------
// Bad inputs

void expect_refused(const LeastSquaresProblem& p, const std::string& message_part,
                    const LeastSquaresOptions& options = {}) {
  try {
    solve_least_squares(p, options);
    ADD_FAILURE() << "accepted; expected an error containing \"" << message_part << "\"";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(message_part), std::string::npos) << e.what();
  }
}

TEST(BadInput, RefusedWithAClearMessage) {
  expect_refused(LeastSquaresProblem{}, "empty");
  const LeastSquaresProblem good = line_problem(5, 1, 0.1);

  LeastSquaresProblem p = good;
  p.observations.resize(4);
  expect_refused(p, "4 observations for a design matrix of 5 rows");

  p = good;
  p.weights = VectorXd::Ones(3);
  expect_refused(p, "3 weights for 5 observations");
  p = good;
  p.names = {"only one"};
  expect_refused(p, "1 parameter names for 2 parameters");
  p = good;
  p.parameter_scales = VectorXd::Ones(2) * -1.0;
  expect_refused(p, "scale of parameter 0");

  p = good;
  p.design(3, 1) = std::numeric_limits<double>::quiet_NaN();
  expect_refused(p, "non-finite value (nan) in row 3, column 1");
  p = good;
  p.observations(2) = std::numeric_limits<double>::infinity();
  expect_refused(p, "Observation 2 is not finite");

  p = good;
  p.weights = VectorXd::Ones(5);
  p.weights(4) = -1.0;
  expect_refused(p, "weight of observation 4 is -1");
  p.weights(4) = 0.0;
  expect_refused(p, "weight of observation 4 is 0");

  p = good;
  p.design = MatrixXd::Ones(1, 2);
  p.observations = VectorXd::Ones(1);
  expect_refused(p, "1 observations for 2 parameters");

  LeastSquaresOptions bad;
  bad.rank_tolerance = -1.0;
  expect_refused(good, "rank_tolerance", bad);
  std::string why;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("rank_tolerance"), std::string::npos);
  EXPECT_TRUE(LeastSquaresOptions{}.IsValid(nullptr));

  const LeastSquaresSolution sol = solve_least_squares(good);
  EXPECT_THROW(evaluate_combination(sol, VectorXd::Ones(3)), Error);
}

}  // namespace
}  // namespace gyrocal
