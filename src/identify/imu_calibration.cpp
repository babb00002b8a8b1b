#include "gyrocal/identify/imu_calibration.hpp"

// An IMU's joint identification (docs/imu.md, "One joint solve"): each channel's reduced positions weighted
// by its own levels (weighted_positions.hpp), stacked into one least squares whose unknowns are every
// channel's products and the shared machine errors, Gauss-Newton on the exact model for the errors as a lone
// sensor's self-calibration (self_calibration.cpp), the uncertainties a sandwich of every channel's own
// levels, each channel's coefficients stepped back from its products by its sensor's from_products.
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/identify/dwell_model_route.hpp"
#include "gyrocal/identify/sensor_model_terms.hpp"
#include "gyrocal/model/nominal.hpp"

#include "closed_form_identify.hpp"
#include "imu_combinations.hpp"
#include "position_covariance.hpp"
#include "residual_levels.hpp"
#include "self_calibration.hpp"
#include "weighted_positions.hpp"

namespace gyrocal {
namespace {

using identify_detail::weigh_positions;
using identify_detail::WeightedPositions;
using identify_detail::with_errors;

std::size_t unknowns_of(const Sensor& s) {
  return std::visit([](const auto& x) { return x.num_unknowns(); }, s);
}

/// The output's noise-free level of a channel, in its unit (identify/misfit.hpp): a standard error at or
/// below it is rounding, not noise.
double noise_free_level(const SensorChannel& c) {
  return kind_of(c.sensor) == SensorKind::kGyro ? kGyroNoiseFreeDegH : kAccelerometerNoiseFreeRelative;
}

/// A channel that reads the same at every position is dead (or its column holds something else): gravity
/// turns an accelerometer's reading by 2 g over the positions and the earth's rate and gravity move a gyro's,
/// so the spread of its reduced outputs is far above its noise-free level. Refused naming the channel: its
/// coefficients would be fitted to nothing (a noise-free-looking record whose misfit is not tested).
void refuse_dead_channel(const Reduction& reduction, const SensorChannel& channel) {
  if (reduction.positions.empty()) return;
  double lo = reduction.positions.front().mean, hi = lo;
  for (const ReducedPosition& p : reduction.positions) {
    lo = std::min(lo, p.mean);
    hi = std::max(hi, p.mean);
  }
  if (hi - lo > 1e3 * noise_free_level(channel)) return;
  throw Error(fmt::format(
      "channel {} (column {}) reads {:.6g} {} at every position (spread {:.3g}): a dead channel, or a "
      "column that holds no sensor's output; check the record and the channel's column.",
      channel.name, channel.output.column, lo, channel.output.unit(), hi - lo));
}

/// What an IMU's calibration cannot do, refused before the record is read: the closed forms, a partial
/// compensation, the mount's misalignment beside the channels' tilts.
void refuse_imu_options(const CalibrationOptions& options) {
  if (options.method != Method::kLeastSquares)
    throw Error(
        "an IMU is calibrated by least squares (--method least-squares): the closed forms are the lone "
        "gyro's 16-position formulas.");
  if (options.compensation != Compensation::kFull)
    throw Error(
        "an IMU is calibrated with --compensation full: its channels' inputs are the exact model's "
        "(docs/imu.md).");
  for (const MachineErrorParameter& p : options.estimate)
    if (p.info().vector == &CentrifugeErrors::mount_misalignment_rad)
      throw Error(fmt::format(
          "--estimate {}: an IMU's mount misalignment cannot be estimated beside its channels' tilts: each "
          "channel's input-axis tilts are measured against the mount, which the lab's fixture defines, so "
          "the "
          "mount's own misalignment is zero by definition (docs/imu.md, \"The triad's geometry\").",
          p.error_name()));
}

/// Each channel's reduction, an accelerometer's whose model terms follow the measured motion (a rippling
/// drive) with its dwells' levels measured from the scatter between revolutions of its output less its model,
/// as a lone accelerometer's (residual_levels.hpp; docs/accelerometer_internals.md, "The drive's ripple"):
/// the ripple moves the centripetal input from one revolution to the next by far more than the noise, and
/// that motion is in the model. The model is the channel's design rows at the configured machine, at the
/// products of a first fit of the channel alone (what the shared errors change between revolutions is far
/// less).
std::vector<Reduction> releveled(const std::vector<Reduction>& reductions,
                                 const std::vector<SensorChannel>& channels, const CentrifugeModel& model,
                                 const CalibrationOptions& options) {
  std::vector<Reduction> out;
  out.reserve(reductions.size());
  for (std::size_t c = 0; c < reductions.size() && c < channels.size(); ++c) {
    std::optional<Reduction> own;
    // Only where a dwell follows its measured motion (else residual_levels has nothing to relevel, and its
    // model terms would be one more reduction of every dwell).
    const bool follows = std::any_of(reductions[c].dwells.begin(), reductions[c].dwells.end(),
                                     [&](const Dwell& d) { return follows_measured_rate(model, d); });
    if (follows && kind_of(channels[c].sensor) == SensorKind::kAccelerometer) {
      CalibrationOptions lone = options;
      lone.sensor = SensorKind::kAccelerometer;
      lone.estimate.clear();
      lone.test_misfit = false;  // the first fit only gives the model its products; the joint fit is tested
      const std::vector<PositionModelTerms> terms = reduce_sensor_model_terms(
          reductions[c], model, options.reduce, channels[c], options.max_model_samples_per_dwell);
      own = identify_detail::residual_levels(reductions[c], terms, model, lone);
    }
    out.push_back(own ? std::move(*own) : reductions[c]);
  }
  return out;
}

/// Everything the joint solve keeps of one channel at one Gauss-Newton step.
struct ChannelProblem {
  std::vector<PositionModelTerms> terms;  ///< its model terms at the current machine
  Eigen::MatrixXd error_columns;          ///< d(reduced model output)/d(error), output unit per error unit
  WeightedPositions weighted;             ///< its positions, weighted by its own levels
};

/// How one channel's reduced design rows move with each estimated error: per error, per position, the
/// forward difference of the known part and of each regressor from `at` (the rows at the configured
/// machine, already reduced for the first step), with the error's typical magnitude as the step, per unit of
/// the error. Taken once, at the configured machine: the rows are smooth in the errors (their curvature is of
/// relative order 1e-5 per typical magnitude), so the columns they give at any products are the Jacobian
/// Gauss-Newton needs, to ~1e-5 of themselves (a forward difference's error is half the curvature times the
/// step), while each step's residuals are those of the current machine: the solution is where those
/// residuals are least, whatever the Jacobian's last digits; its covariance moves by ~1e-5 of itself. One
/// reduction of the model terms per error (a central difference took two: the model terms are the
/// calibration's cost after the reading, issue 27's speed).
struct RowDerivatives {
  std::vector<std::vector<DesignRow>> per_error;  ///< [error][position]
};

RowDerivatives row_derivatives(const Reduction& reduction, const SensorChannel& channel,
                               const CentrifugeModel& model, const std::vector<MachineErrorParameter>& ps,
                               const std::vector<double>& values_si,
                               const std::vector<PositionModelTerms>& at, const CalibrationOptions& options) {
  RowDerivatives out;
  for (std::size_t a = 0; a < ps.size(); ++a) {
    const MachineErrorField& f = ps[a].info();
    const double h = f.typical_si;
    std::vector<double> plus = values_si;
    plus[a] += h;
    const auto up = reduce_sensor_model_terms(reduction, with_errors(model, ps, plus), options.reduce,
                                              channel, options.max_model_samples_per_dwell);
    std::vector<DesignRow> rows(up.size());
    const double per_unit = f.unit_to_si / h;
    for (std::size_t i = 0; i < up.size(); ++i) {
      const DesignRow& ru = up[i].sensor_exact;
      const DesignRow& rd = at[i].sensor_exact;
      rows[i].size = ru.size;
      rows[i].known = (ru.known - rd.known) * per_unit;
      for (std::size_t j = 0; j < ru.size; ++j)
        rows[i].regressors[j] = (ru.regressors[j] - rd.regressors[j]) * per_unit;
    }
    out.per_error.push_back(std::move(rows));
  }
  return out;
}

/// The columns of the estimated errors for one channel at its products u: d(known + sum_j u_j r_j)/d(error),
/// in the output's unit per the error's unit.
Eigen::MatrixXd error_columns(const RowDerivatives& d, const Eigen::VectorXd& u, Eigen::Index m) {
  Eigen::MatrixXd out(m, static_cast<Eigen::Index>(d.per_error.size()));
  for (std::size_t a = 0; a < d.per_error.size(); ++a)
    for (Eigen::Index i = 0; i < m; ++i)
      out(i, static_cast<Eigen::Index>(a)) = design_output(d.per_error[a][static_cast<std::size_t>(i)], u);
  return out;
}

/// One channel's positions weighted by its own levels, its design [regressors | error columns].
WeightedPositions weigh_channel(const Reduction& reduction, const SensorChannel& channel,
                                const std::vector<PositionModelTerms>& terms, const Eigen::MatrixXd& errors,
                                const std::vector<std::string>& names, const CalibrationOptions& options) {
  const auto m = static_cast<Eigen::Index>(reduction.positions.size());
  const auto nc = static_cast<Eigen::Index>(unknowns_of(channel.sensor));
  const Eigen::Index k = errors.cols();
  Eigen::MatrixXd design(m, nc + k);
  Eigen::VectorXd observations(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const DesignRow& row = terms[static_cast<std::size_t>(i)].sensor_exact;
    if (static_cast<Eigen::Index>(row.size) != nc)
      throw Error(fmt::format("channel {}: its model terms hold {} unknowns, its sensor {} (internal).",
                              channel.name, row.size, nc));
    for (Eigen::Index j = 0; j < nc; ++j) design(i, j) = row.regressors[static_cast<std::size_t>(j)];
    if (k > 0) design.row(i).tail(k) = errors.row(i);
    const double mean = reduction.positions[static_cast<std::size_t>(i)].mean;
    if (!std::isfinite(mean))
      throw Error(
          fmt::format("channel {}: a reduced output is not a finite number: its outputs are too large "
                      "to average; check its column {}.",
                      channel.name, channel.output.column));
    observations[i] = mean - row.known;
  }
  const bool gyro = kind_of(channel.sensor) == SensorKind::kGyro;
  return weigh_positions(reduction, std::move(design), std::move(observations), names, options.min_std_err,
                         options.reduce, gyro ? "deg/h" : "g",
                         fmt::format("channel {}'s outputs", channel.name));
}

/// The joint problem's solution at one step.
struct JointSolution {
  LeastSquaresSolution solution;
  Eigen::MatrixXd covariance;          ///< the sandwich of every channel's own levels
  std::vector<Eigen::MatrixXd> gains;  ///< per channel: G_c, n x m_c (x = sum_c G_c y_c)
};

/// Stacks every channel's whitened rows (its products' block, the shared errors' last columns) and solves.
JointSolution solve_joint(const std::vector<ChannelProblem>& problems,
                          const std::vector<Eigen::Index>& offsets, Eigen::Index n, Eigen::Index k,
                          const std::vector<std::string>& names, const CalibrationOptions& options) {
  Eigen::Index rows = 0;
  for (const ChannelProblem& p : problems) rows += p.weighted.whitened.design.rows();
  LeastSquaresProblem joint;
  joint.design = Eigen::MatrixXd::Zero(rows, n);
  joint.observations.resize(rows);
  joint.weights = Eigen::VectorXd::Ones(rows);
  joint.names = names;
  Eigen::Index at = 0;
  for (std::size_t c = 0; c < problems.size(); ++c) {
    const LeastSquaresProblem& w = problems[c].weighted.whitened;
    const Eigen::Index mc = w.design.rows(), nc = w.design.cols() - k;
    joint.design.block(at, offsets[c], mc, nc) = w.design.leftCols(nc);
    if (k > 0) joint.design.block(at, n - k, mc, k) = w.design.rightCols(k);
    joint.observations.segment(at, mc) = w.observations;
    at += mc;
  }
  LeastSquaresOptions lso = options.least_squares;
  lso.rank_tolerance = std::max(lso.rank_tolerance, 1.0 / options.max_uncertainty_ratio);
  JointSolution out;
  out.solution = solve_least_squares(joint, lso);
  // The sandwich: x = Cov X~' L^-1 y stacked by channel, so x = sum_c G_c y_c with G_c = Cov X~_c' L_c^-1,
  // and its covariance sum_c G_c C_c G_c' with C_c the channel's own levels (weighted_positions.hpp).
  out.covariance = Eigen::MatrixXd::Zero(n, n);
  at = 0;
  for (std::size_t c = 0; c < problems.size(); ++c) {
    const WeightedPositions& w = problems[c].weighted;
    const Eigen::Index mc = w.design.rows();
    const Eigen::MatrixXd xt = joint.design.middleRows(at, mc);  // X~_c in the joint columns
    const Eigen::MatrixXd g =
        (w.weighting.matrixU().solve(xt * out.solution.covariance)).transpose();  // (L_c^-T X~_c Cov)'
    out.covariance += g * w.covariance * g.transpose();
    out.gains.push_back(g);
    at += mc;
  }
  return out;
}

/// The factor widening the standard uncertainty of c'x for the degrees of freedom of the levels it rests on:
/// each channel's Student factor (position_covariance.hpp) weighted by the part of the variance it gives.
double student(const std::vector<Reduction>& reductions, const std::vector<ChannelProblem>& problems,
               const JointSolution& js, const Eigen::VectorXd& c) {
  double total = 0.0, widened = 0.0;
  for (std::size_t k = 0; k < problems.size(); ++k) {
    const Eigen::VectorXd g = js.gains[k].transpose() * c;
    const double v = g.dot(problems[k].weighted.covariance * g);
    if (!(v > 0.0)) continue;
    double nu = 0.0;
    const double f = identify_detail::student_factor(reductions[k], problems[k].weighted.covariance, g, &nu);
    total += v;
    widened += v * f * f;
  }
  return total > 0.0 ? std::sqrt(widened / total) : 1.0;
}

/// The step back of one channel from its products u (covariance cu) to its coefficients, by the delta method
/// with from_products' Jacobian by central differences (exact to rounding for the ratios it takes).
ParameterEstimates step_back(const Sensor& sensor, const Eigen::VectorXd& u, const Eigen::MatrixXd& cu,
                             Eigen::MatrixXd* jacobian) {
  const std::vector<bool> all(static_cast<std::size_t>(u.size()), true);
  const auto values = [&](const Eigen::VectorXd& x) {
    return std::visit([&](const auto& s) { return s.from_products(x, cu, all); }, sensor);
  };
  ParameterEstimates pe = values(u);
  jacobian->setZero(pe.values.size(), u.size());
  for (Eigen::Index j = 0; j < u.size(); ++j) {
    const double h = 1e-6 * std::max(std::abs(u[j]), 1e-3);
    Eigen::VectorXd up = u, down = u;
    up[j] += h;
    down[j] -= h;
    jacobian->col(j) = (values(up).values - values(down).values) / (2.0 * h);
  }
  return pe;
}

/// One channel's fitted input-axis tilts as rows of the joint unknowns: the tilt toward the second axis and
/// toward the third, in rad, each with its gradient with respect to every unknown (the delta method's row).
struct FittedTilts {
  std::size_t channel = 0;
  double toward_second = 0.0, toward_third = 0.0;  ///< rad
  Eigen::VectorXd grad_second, grad_third;         ///< rad per unit of each unknown
};

/// The angles between the fitted input axes of every two channels of one kind (InputAxisAngle), their std
/// from the tilts' joint covariance (every channel's and the errors' unknowns: the correlations the shared
/// unknowns create are in it) by a central difference of the angle in the four tilts.
std::vector<InputAxisAngle> input_axis_angles(const std::vector<SensorChannel>& channels,
                                              const std::vector<FittedTilts>& tilts,
                                              const Eigen::MatrixXd& covariance) {
  std::vector<InputAxisAngle> out;
  const auto axis = [&](const FittedTilts& t, double a, double b) {
    const Eigen::Matrix3d& m = channels[t.channel].axes;
    return Eigen::Vector3d(m.col(0) + a * m.col(1) + b * m.col(2)).normalized();
  };
  const auto angle = [](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
    return std::atan2(u.cross(v).norm(), u.dot(v));
  };
  for (std::size_t a = 0; a < tilts.size(); ++a)
    for (std::size_t b = a + 1; b < tilts.size(); ++b) {
      const FittedTilts& ta = tilts[a];
      const FittedTilts& tb = tilts[b];
      if (kind_of(channels[ta.channel].sensor) != kind_of(channels[tb.channel].sensor)) continue;
      const std::array<double, 4> x = {ta.toward_second, ta.toward_third, tb.toward_second, tb.toward_third};
      const auto at = [&](const std::array<double, 4>& v) {
        return angle(axis(ta, v[0], v[1]), axis(tb, v[2], v[3]));
      };
      Eigen::VectorXd grad = Eigen::VectorXd::Zero(covariance.rows());
      const std::array<const Eigen::VectorXd*, 4> rows = {&ta.grad_second, &ta.grad_third, &tb.grad_second,
                                                          &tb.grad_third};
      for (std::size_t q = 0; q < 4; ++q) {
        const double h = 1e-7;
        std::array<double, 4> up = x, down = x;
        up[q] += h;
        down[q] -= h;
        grad += (at(up) - at(down)) / (2.0 * h) * *rows[q];
      }
      InputAxisAngle e;
      e.first = channels[ta.channel].name;
      e.second = channels[tb.channel].name;
      const double value = at(x);
      const double nominal = angle(channels[ta.channel].axes.col(0), channels[tb.channel].axes.col(0));
      e.angle_deg = value * kRadToDeg;
      e.nominal_deg = nominal * kRadToDeg;
      e.deviation_urad = (value - nominal) * 1e6;
      e.std_urad = std::sqrt(std::max(0.0, grad.dot(covariance * grad))) * 1e6;
      out.push_back(std::move(e));
    }
  return out;
}

}  // namespace

/// A channel's combinations (identify_detail::channel_combinations) as estimates of its coefficients: a
/// gyro's products are its coefficients (a combination that takes a drift+rate gyro's (1 + e) dO or dS is not
/// stated: it is not one of its coefficients'); an accelerometer's (K1 K0, K1, K1 K2, ...) divided by its
/// fitted K1 (a combination that takes K1 itself is not stated), K1's own uncertainty (~1e-6 of it) left
/// out of the std. `coefficients`: the channel's table (names and units, in its products' order);
/// `std_of(row)`: the std of row' x over the joint unknowns. Each in its pivot coefficient's unit.
std::vector<NamedEstimate> stated_combinations(const SensorChannel& channel, const Eigen::VectorXd& u,
                                               const std::vector<CoefficientEstimate>& coefficients,
                                               const LeastSquaresSolution& sol, Eigen::Index offset,
                                               Eigen::Index nc,
                                               const std::function<double(const Eigen::VectorXd&)>& std_of) {
  std::vector<NamedEstimate> out;
  // The coefficients' names, in the products' order (a product K1 Kx named by its coefficient Kx).
  std::vector<std::string> names;
  for (const CoefficientEstimate& e : coefficients) names.push_back(e.name);
  if (static_cast<Eigen::Index>(names.size()) < nc) return out;
  const bool accelerometer = kind_of(channel.sensor) == SensorKind::kAccelerometer;
  const auto scale_at = static_cast<Eigen::Index>(AccelCoefficient::K1);
  for (const identify_detail::ChannelCombination& comb :
       identify_detail::channel_combinations(sol, offset, nc)) {
    const Eigen::VectorXd& w = comb.weights;
    const double largest = w.cwiseAbs().maxCoeff();
    if (accelerometer && std::abs(w[scale_at]) > 1e-12 * largest) continue;
    if (!accelerometer && nc > static_cast<Eigen::Index>(kNumGyroCoefficients) + 1 &&
        w.tail(2).cwiseAbs().maxCoeff() > 1e-12 * largest)
      continue;
    const double divisor = accelerometer ? u[scale_at] : 1.0;
    Eigen::VectorXd row = Eigen::VectorXd::Zero(sol.estimate.size());
    row.segment(offset, nc) = w / divisor;
    NamedEstimate e;
    e.name = identify_detail::combination_text(comb, names);
    e.unit = coefficients[static_cast<std::size_t>(comb.pivot)].unit;
    e.value = w.dot(u) / divisor;
    e.std = std_of(row);
    e.coefficients.assign(w.data(), w.data() + w.size());
    out.push_back(std::move(e));
  }
  return out;
}

const ImuChannelResult* ImuCalibrationResult::channel(std::string_view name) const {
  for (const ImuChannelResult& c : channels)
    if (c.name == name) return &c;
  return nullptr;
}

ImuCalibrationResult identify_imu(const std::vector<Reduction>& record_reductions,
                                  const std::vector<SensorChannel>& configured_channels,
                                  const CentrifugeModel& model, const CalibrationOptions& options,
                                  std::span<const OutputRange> ranges) {
  // Every gyro channel fits the options' gyro model (--gyro-model, else [calibration] gyro_model), as a lone
  // gyro's least squares does: the channels carry the one the configuration was loaded with.
  std::vector<SensorChannel> channels = configured_channels;
  for (SensorChannel& c : channels)
    if (auto* g = std::get_if<Gyro>(&c.sensor)) g->model = options.gyro_model;
  if (channels.empty() || record_reductions.size() != channels.size())
    throw Error(
        fmt::format("an IMU's calibration takes one reduction per channel: {} channels, {} reductions.",
                    channels.size(), record_reductions.size()));
  refuse_imu_options(options);
  const std::vector<MachineErrorParameter>& ps = options.estimate;
  const std::size_t nch = channels.size();
  for (std::size_t c = 0; c < nch; ++c) {
    refuse_dead_channel(record_reductions[c], channels[c]);
    if (c >= ranges.size() || !options.test_misfit) continue;
    const std::string flat = saturation_cause(record_reductions[c], ranges[c], channels[c].output.unit(),
                                              to_string(kind_of(channels[c].sensor)));
    if (!flat.empty())
      throw Error(
          fmt::format("channel {} (column {}): {}.", channels[c].name, channels[c].output.column, flat));
  }
  const std::vector<Reduction> reductions = releveled(record_reductions, channels, model, options);
  const auto k = static_cast<Eigen::Index>(ps.size());
  // The unknowns: each channel's products ("gx.dF"), then the errors.
  std::vector<Eigen::Index> offsets;
  std::vector<std::string> names;
  for (const SensorChannel& c : channels) {
    offsets.push_back(static_cast<Eigen::Index>(names.size()));
    const auto table = std::visit([](const auto& s) { return s.unknown_names(); }, c.sensor);
    for (std::string_view u : table) names.push_back(fmt::format("{}.{}", c.name, u));
  }
  for (const MachineErrorParameter& p : ps) names.push_back(p.label());
  const auto n = static_cast<Eigen::Index>(names.size());
  const Eigen::Index np = n - k;

  std::vector<double> configured(ps.size()), values(ps.size());
  for (std::size_t j = 0; j < ps.size(); ++j) values[j] = configured[j] = ps[j].get(model.errors());
  // The products the errors' columns are first taken at: a plain joint fit at the configured machine (an
  // accelerometer's output is all in its products, so zero products would leave its columns zero).
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  std::vector<ChannelProblem> problems(nch);
  std::vector<RowDerivatives> derivatives;  // per channel, at the configured machine
  std::vector<double> reduced_at;           // the errors' values the channels' model terms were reduced at
  JointSolution js;
  ImuCalibrationResult r;
  const auto channel_names = [&](std::size_t c, bool with_errors) {
    std::vector<std::string> out(
        names.begin() + offsets[c],
        names.begin() + offsets[c] + static_cast<Eigen::Index>(unknowns_of(channels[c].sensor)));
    if (with_errors) out.insert(out.end(), names.end() - k, names.end());
    return out;
  };
  for (int iteration = 0;; ++iteration) {
    const bool plain = iteration == 0 && k > 0;  // the start, without the errors' columns
    const CentrifugeModel current = with_errors(model, ps, values);
    // The plain start leaves the machine as configured: its model terms serve the first step as they are.
    const bool machine_moved = iteration == 0 || values != reduced_at;
    reduced_at = values;
    for (std::size_t c = 0; c < nch; ++c) {
      ChannelProblem& p = problems[c];
      if (machine_moved)
        p.terms = reduce_sensor_model_terms(reductions[c], current, options.reduce, channels[c],
                                            options.max_model_samples_per_dwell);
      const auto nc = static_cast<Eigen::Index>(unknowns_of(channels[c].sensor));
      const auto m = static_cast<Eigen::Index>(reductions[c].positions.size());
      if (!plain && k > 0 && derivatives.size() < nch)
        derivatives.push_back(
            row_derivatives(reductions[c], channels[c], current, ps, values, p.terms, options));
      p.error_columns = plain || k == 0 ? Eigen::MatrixXd(m, 0)
                                        : error_columns(derivatives[c], x.segment(offsets[c], nc), m);
      p.weighted = weigh_channel(reductions[c], channels[c], p.terms, p.error_columns,
                                 channel_names(c, !plain), options);
    }
    if (plain) {
      std::vector<std::string> product_names(names.begin(), names.end() - k);
      const JointSolution start = solve_joint(problems, offsets, np, 0, product_names, options);
      x.head(np) = start.solution.estimate;
      continue;
    }
    js = solve_joint(problems, offsets, n, k, names, options);
    const LeastSquaresSolution& sol = js.solution;
    r.iterations = iteration;
    if (k == 0) {
      x = sol.estimate;
      break;
    }
    bool converged = true;
    for (Eigen::Index a = 0; a < k; ++a) {
      const auto j = static_cast<std::size_t>(a);
      if (!sol.identifiable[static_cast<std::size_t>(np + a)])
        throw Error(fmt::format(
            "--estimate {}: this IMU's plan cannot separate it from the channels' coefficients and the other "
            "errors estimated (it is collinear with them); estimate fewer errors or add dwells "
            "(docs/imu.md, \"What one mounting identifies\").",
            ps[j].label()));
      const double step = sol.estimate[np + a];
      const double sd = std::sqrt(js.covariance(np + a, np + a));
      values[j] += step * ps[j].info().unit_to_si;
      const double typical = ps[j].info().typical_si / ps[j].info().unit_to_si;
      if (!(std::abs(step) <= options.convergence * sd || std::abs(step) <= 1e-9 * typical))
        converged = false;
    }
    for (Eigen::Index j = 0; j < np; ++j) {
      const double sd = std::sqrt(js.covariance(j, j));
      if (!(std::abs(sol.estimate[j] - x[j]) <= options.convergence * sd ||
            std::abs(sol.estimate[j] - x[j]) <= 1e-12 * std::max(1.0, std::abs(x[j]))))
        converged = false;
    }
    x.head(np) = sol.estimate.head(np);
    if (converged) break;
    if (iteration >= options.max_iterations)
      throw Error(fmt::format(
          "the IMU's self-calibration (--estimate) did not converge in {} Gauss-Newton iterations: the "
          "configured values are too far from the machine's, or the errors are barely identifiable.",
          options.max_iterations));
  }
  const LeastSquaresSolution& sol = js.solution;
  r.rank = sol.rank;
  r.unknowns = static_cast<int>(n);
  r.condition_number = sol.effective_condition_number;
  r.covariance = js.covariance;
  r.names = names;
  for (const std::string& w : sol.warnings)
    if (w.rfind("chi2 = ", 0) != 0) r.warnings.push_back("least squares: " + w);

  // Each channel: its residuals and misfit test, then its coefficients.
  double worst_scale = 1.0;
  std::vector<FittedTilts> tilts;
  for (std::size_t c = 0; c < nch; ++c) {
    const SensorChannel& ch = channels[c];
    const ChannelProblem& p = problems[c];
    const Reduction& red = reductions[c];
    const auto nc = static_cast<Eigen::Index>(unknowns_of(ch.sensor));
    ImuChannelResult out;
    out.name = ch.name;
    out.sensor = kind_of(ch.sensor);
    out.positions = red.positions;
    out.outliers = red.outliers;
    for (const std::string& w : red.warnings) out.warnings.push_back(w);
    const Eigen::Index mc = p.weighted.design.rows();
    Eigen::VectorXd xc(nc + k);
    xc << x.segment(offsets[c], nc), Eigen::VectorXd::Zero(k);  // the errors are in the model already
    const Eigen::VectorXd residuals = p.weighted.observations - p.weighted.design.leftCols(nc) * xc.head(nc);
    out.residuals.assign(residuals.data(), residuals.data() + residuals.size());
    // Its chi2 on its own whitened rows; its degrees of freedom its rows less its part of the hat matrix's
    // trace (what the joint fit spent on its rows).
    const Eigen::VectorXd wres = p.weighted.weighting.matrixL().solve(residuals);
    double spent = 0.0;
    for (Eigen::Index i = 0; i < mc; ++i) {
      Eigen::VectorXd xi = Eigen::VectorXd::Zero(n);
      xi.segment(offsets[c], nc) = p.weighted.whitened.design.row(i).head(nc).transpose();
      if (k > 0) xi.tail(k) = p.weighted.whitened.design.row(i).tail(k).transpose();
      spent += xi.dot(sol.covariance * xi);
    }
    const int dof = static_cast<int>(std::lround(static_cast<double>(mc) - spent));
    out.misfit = test_misfit(red, wres.squaredNorm(), dof, noise_free_level(ch));
    if (out.misfit.tested && out.misfit.p_value < options.misfit.p_min) {
      const double scale = std::sqrt(out.misfit.chi2 / std::max(1, out.misfit.dof));
      if (options.test_misfit && scale > options.misfit.max_scale)
        throw Error(fmt::format(
            "channel {} (column {}): its residuals are {:.3g} times its noise (chi2 {:.4g} on {} degrees of "
            "freedom, more than [calibration] misfit's {:g}): its output does not follow a {}'s model on its "
            "axes: a dead, clipped or sign-flipped channel, a wrong column, axis or output_scale.",
            ch.name, ch.output.column, scale, out.misfit.chi2, out.misfit.dof, options.misfit.max_scale,
            to_string(out.sensor)));
      out.misfit.scale = scale;
      worst_scale = std::max(worst_scale, scale);
      out.warnings.push_back(
          fmt::format("its residuals are {:.3g} times the noise its dwells show (chi2 {:.4g} on {} degrees "
                      "of freedom, p = "
                      "{:.2g}): every std of its coefficients is multiplied by that factor.",
                      scale, out.misfit.chi2, out.misfit.dof, out.misfit.p_value));
    }
    // Coefficients: the delta method on its products' block of the joint covariance.
    const Eigen::VectorXd u = x.segment(offsets[c], nc);
    const Eigen::MatrixXd cu = js.covariance.block(offsets[c], offsets[c], nc, nc);
    Eigen::MatrixXd jac;
    const ParameterEstimates pe = step_back(ch.sensor, u, cu, &jac);
    out.products.assign(u.data(), u.data() + u.size());
    const double output_scale = out.sensor == SensorKind::kAccelerometer ? ch.output.scale : 1.0;
    CalibrationOptions one = options;
    one.sensor = out.sensor;
    if (const auto* g = std::get_if<Gyro>(&ch.sensor)) one.gyro_model = g->model;
    one.output_unit = ch.output.column_unit();
    out.coefficients = unestimated_coefficients(one);
    for (Eigen::Index q = 0; q < pe.values.size() && q < static_cast<Eigen::Index>(out.coefficients.size());
         ++q) {
      CoefficientEstimate& e = out.coefficients[static_cast<std::size_t>(q)];
      Eigen::VectorXd row = Eigen::VectorXd::Zero(n);
      row.segment(offsets[c], nc) = jac.row(q).transpose();
      bool identifiable = true;
      for (Eigen::Index j = 0; j < nc; ++j)
        if (jac(q, j) != 0.0 && !sol.identifiable[static_cast<std::size_t>(offsets[c] + j)])
          identifiable = false;
      e.identifiable = identifiable;
      if (!identifiable) {
        e.reason = "not identifiable from this plan with the errors estimated (docs/imu.md)";
        continue;
      }
      const bool k1 = out.sensor == SensorKind::kAccelerometer && e.name == "K1";
      // An accelerometer's scale factor has the sign of its output_scale: a fitted ratio below zero is a
      // channel whose sign is flipped (a cable, a convention) against its configuration.
      if (k1 && options.test_misfit && pe.values[q] < 0.0)
        throw Error(fmt::format(
            "channel {} (column {}): its output falls where its input rises (the fitted scale is {:.6g} "
            "times "
            "its output_scale {:g}): a sign-flipped channel; if it is inverted by design, give it a negative "
            "output_scale.",
            ch.name, ch.output.column, pe.values[q], ch.output.scale));
      e.value = pe.values[q] * (k1 ? output_scale : 1.0);
      // The input axis' tilts (an accelerometer's delta_p, delta_o in urad; a drift+rate gyro's input-axis
      // misalignment about O and S in arcsec), in rad with their rows, for the triad's geometry.
      const bool toward_second = e.name == "delta_p" || e.name == "input_axis_misalignment_O_arcsec";
      const bool toward_third = e.name == "delta_o" || e.name == "input_axis_misalignment_S_arcsec";
      if (toward_second || toward_third) {
        const double to_rad = e.unit == "urad" ? 1e-6 : kArcsecToRad;
        if (tilts.empty() || tilts.back().channel != c) {
          tilts.push_back({});
          tilts.back().channel = c;
        }
        FittedTilts& t = tilts.back();
        (toward_second ? t.toward_second : t.toward_third) = e.value * to_rad;
        (toward_second ? t.grad_second : t.grad_third) = row * to_rad;
      }
      e.std = std::sqrt(row.dot(js.covariance * row)) * student(reductions, problems, js, row) *
              out.misfit.scale * (k1 ? std::abs(output_scale) : 1.0);
    }
    out.combinations =
        stated_combinations(ch, u, out.coefficients, sol, offsets[c], nc, [&](const Eigen::VectorXd& row) {
          return std::sqrt(row.dot(js.covariance * row)) * student(reductions, problems, js, row) *
                 out.misfit.scale;
        });
    r.channels.push_back(std::move(out));
  }
  // The triad's geometry, from the channels whose two tilts are both fitted.
  std::erase_if(tilts,
                [](const FittedTilts& t) { return t.grad_second.size() == 0 || t.grad_third.size() == 0; });
  r.input_axis_angles = input_axis_angles(channels, tilts, js.covariance);
  // The shared errors.
  for (std::size_t j = 0; j < ps.size(); ++j) {
    const auto a = static_cast<Eigen::Index>(j);
    const MachineErrorField& f = ps[j].info();
    MachineErrorEstimate e;
    e.parameter = ps[j];
    e.error = f.kind == MachineErrorKind::kSeries ? std::string(f.name) : ps[j].error_name();
    e.harmonic = ps[j].harmonic;
    e.part = ps[j].part == HarmonicPart::kCos ? "cos" : ps[j].part == HarmonicPart::kSin ? "sin" : "";
    e.unit = f.unit;
    e.configured = configured[j] / f.unit_to_si;
    e.identifiable = true;
    e.value = values[j] / f.unit_to_si;
    const Eigen::VectorXd unit = Eigen::VectorXd::Unit(n, np + a);
    e.std = std::sqrt(js.covariance(np + a, np + a)) * student(reductions, problems, js, unit) * worst_scale;
    r.machine_errors.push_back(std::move(e));
  }
  // The record's quality: its rows and gaps are every channel's; outliers summed.
  const Reduction& first = reductions.front();
  r.data_quality = data_quality_of(first);
  r.data_quality.outliers = 0;
  for (const Reduction& red : reductions) r.data_quality.outliers += red.outliers;
  r.warnings.insert(r.warnings.begin(), first.warnings.begin(), first.warnings.end());
  r.g_level = radial_level_g(model.site(), model.geometry().radius_m,
                             identify_detail::first_spinning_rate(first.positions));
  return r;
}

ImuCalibrationResult calibrate_imu_record(RecordReader& reader, const std::vector<SensorChannel>& channels,
                                          const CentrifugeModel& model, const TestSpec& plan,
                                          const CalibrationOptions& options) {
  refuse_imu_options(options);
  reader.require_angles();
  if (reader.output_count() != channels.size())
    throw Error(fmt::format("the record is read with {} output columns for an IMU of {} channels.",
                            reader.output_count(), channels.size()));
  const TestSpec reduce_plan = reduction_plan(plan, reduction_kind(channels), options.reduce);
  // Each channel's range, for a flat top (identify/misfit.hpp).
  std::vector<OutputRange> ranges(channels.size());
  const std::vector<Reduction> reductions =
      reduce_record_channels(reader, reduce_plan, options.reduce, model.geometry().rate_rad_s,
                             [&ranges](std::span<const RecordSample> rows) {
                               for (const RecordSample& s : rows)
                                 for (std::size_t c = 0; c < ranges.size(); ++c) ranges[c].push(s.outputs[c]);
                             });
  return identify_imu(reductions, channels, model, options, ranges);
}

}  // namespace gyrocal
