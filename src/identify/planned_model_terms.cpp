#include "gyrocal/identify/planned_model_terms.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>

#include "gyrocal/core/units.hpp"

namespace gyrocal {
namespace {

using Complex = std::complex<double>;

/// Grids of 16 .. 128 points per angle: harmonics up to 63 in each (the default machine's model terms need
/// 32).
constexpr int kFirstGrid = 16;
constexpr int kLastGrid = 128;
/// The M / 2 grid's values agree with the M grid's within this fraction of the model term's largest value on
/// the grid (beyond the evaluations' own rounding): then the M grid's are converged, every harmonic the M / 2
/// grid aliases being below it.
constexpr double kConverged = 1e-10;

/// One weighted sum over the samples: sum_i e^{j m gamma_i} i^p F(theta_i, psi_i).
struct WeightSet {
  int m = 0;
  int p = 0;
};

/// The quadrature's weights K_ab for grid size (mt, mh) (1 along an angle that does not turn): sum_i w_i F_i
/// = sum_ab K_ab G(2 pi a / mt, 2 pi b / mh) for every G below mt / 2 and mh / 2 harmonics, where G(u, v) =
/// F(theta0 + u, psi0 + v - u) is the model term as a function of the main angle and the platform's heading
/// (theta + psi) about their first sample's values. The samples advance u by main_step and v by
/// heading_step; gamma = -psi = -psi0 - v + u. So K_ab = e^{-j m psi0} / (mt mh) sum_k e^{-j k u_a} sum_l
/// e^{-j l v_b} S_p((k + m) main_step + (l - m) heading_step). A plan without heading drift (heading_step 0)
/// visits one heading only, and so does the grid.
std::vector<Complex> quadrature_weights(const WeightSet& w, int mt, int mh, double n, double psi0,
                                        double main_step, double heading_step) {
  const auto roots = [](int size) {
    std::vector<Complex> r(static_cast<std::size_t>(size));
    for (int i = 0; i < size; ++i) r[static_cast<std::size_t>(i)] = std::polar(1.0, -2.0 * kPi * i / size);
    return r;
  };
  const std::vector<Complex> rt = roots(mt), rh = roots(mh);
  const auto harmonic = [](int index, int size) { return index - size / 2; };  // -size/2 .. size/2 - 1
  const auto root = [](const std::vector<Complex>& r, int k, int a) {
    const int size = static_cast<int>(r.size());
    return r[static_cast<std::size_t>(((k * a) % size + size) % size)];
  };
  // H(k, b) = sum_l e^{-j l v_b} S_p(k, l - m).
  std::vector<Complex> h(static_cast<std::size_t>(mt * mh), 0.0);
  for (int ki = 0; ki < mt; ++ki) {
    const int k = harmonic(ki, mt);
    for (int li = 0; li < mh; ++li) {
      const int l = harmonic(li, mh);
      const double x = static_cast<double>(k + w.m) * main_step + static_cast<double>(l - w.m) * heading_step;
      const auto [s0, s1] = geometric_power_sums(x, n);
      const Complex g = w.p == 0 ? s0 : s1;
      for (int b = 0; b < mh; ++b)
        h[static_cast<std::size_t>(ki * mh + b)] += root(rh, harmonic(li, mh), b) * g;
    }
  }
  const Complex scale = std::polar(1.0 / (mt * mh), -w.m * psi0);
  std::vector<Complex> k_ab(static_cast<std::size_t>(mt * mh), 0.0);
  for (int a = 0; a < mt; ++a)
    for (int ki = 0; ki < mt; ++ki) {
      const Complex e = root(rt, harmonic(ki, mt), a) * scale;
      for (int b = 0; b < mh; ++b)
        k_ab[static_cast<std::size_t>(a * mh + b)] += e * h[static_cast<std::size_t>(ki * mh + b)];
    }
  return k_ab;
}

}  // namespace

std::pair<Complex, Complex> geometric_power_sums(double x, double n) {
  // x modulo 2 pi, 2 pi taken in two parts (Cody and Waite): the double nearest 2 pi is 2.4e-16 short, which
  // n = 1e8 samples would turn into a phase error of 2e-8 rad per period removed.
  constexpr double kTwoPiHigh = 2.0 * kPi, kTwoPiLow = 2.4492935982947064e-16;
  const double periods = std::nearbyint(x / kTwoPiHigh);
  x = (x - periods * kTwoPiHigh) - periods * kTwoPiLow;
  const double nx = n * x;
  double a = 0.0, da = 0.0;  // A = sin(n x / 2) / sin(x / 2) and dA/dx
  if (std::abs(nx) < 0.05) {
    // sin(n u) / sin(u) = n (1 - (n^2 - 1) u^2 / 6 + (3 n^4 - 10 n^2 + 7) u^4 / 360 - (3 n^6 - 21 n^4 + 49
    // n^2
    // - 31) u^6 / 15120 + ...), u = x / 2: the closed form's difference of nearly equal terms is avoided; the
    // next term is below 1e-14 of A and of A' here.
    const double n2 = n * n, x2 = x * x;
    const double c2 = (n2 - 1.0) / 24.0, c4 = (3.0 * n2 * n2 - 10.0 * n2 + 7.0) / 5760.0;
    const double c6 = (((3.0 * n2 - 21.0) * n2 + 49.0) * n2 - 31.0) / 967680.0;
    a = n * (1.0 - x2 * (c2 - x2 * (c4 - x2 * c6)));
    da = n * x * (-2.0 * c2 + x2 * (4.0 * c4 - 6.0 * c6 * x2));
  } else {
    const double s = std::sin(0.5 * x), c = std::cos(0.5 * x);
    const double sn = std::sin(0.5 * nx), cn = std::cos(0.5 * nx);
    a = sn / s;
    da = (0.5 * n * cn * s - 0.5 * sn * c) / (s * s);
  }
  // sum e^{j x i} = e^{j phi} A, sum i e^{j x i} = -j d/dx = e^{j phi} ((n - 1) / 2 A - j A'), phi = (n-1)
  // x/2.
  const Complex rotation = std::polar(1.0, 0.5 * (n - 1.0) * x);
  return {rotation * a, rotation * Complex(0.5 * (n - 1.0) * a, -da)};
}

bool planned_dwell_model_terms(const Dwell& d, const ReduceOptions& options, int columns,
                               const ModelTermsFunction& evaluate, std::vector<DwellValues>& out) {
  if (d.samples == 0 || !d.stretches.empty() || columns < 1) return false;
  const bool spinning = !d.is_static;
  if (spinning && (options.method != ReduceOptions::Method::kHarmonicFit || d.counter.rate_rad_s == 0.0))
    return false;
  const int order = spinning ? options.harmonic_order : 0;
  const bool drift = spinning && options.linear_drift;
  const double n = static_cast<double>(d.samples), dt = d.sample_interval_s;
  const double theta0 = d.main.at_first_rad, psi0 = d.counter.at_first_rad;
  // Per sample: the main angle's step and the heading's (theta + psi: zero but for the platform's rate
  // mismatch or a counter rate offset), the counter angle's step being their difference.
  const double main_step = d.main.rate_rad_s * dt;
  const double heading_step = (d.main.rate_rad_s + d.counter.rate_rad_s) * dt;

  // The weighted sums the reduction needs: e^{j m gamma} for m = 0 .. order, and i (the drift) for m = 0.
  std::vector<WeightSet> sets;
  for (int m = 0; m <= order; ++m) sets.push_back({m, 0});
  if (drift) sets.push_back({0, 1});
  const auto ns = static_cast<int>(sets.size());

  // The fit's normal matrix (basis 1, cos h gamma, sin h gamma, [t scaled]) from sum_i e^{j m gamma_i} and
  // sum_i i e^{j m gamma_i}, m = 0 .. 2 order, gamma_i = -psi0 + (main_step - heading_step) i.
  const int harmonics = 2 * order + 1, size = harmonics + (drift ? 1 : 0);
  const double alpha = dt / d.planned_duration_s, t_mid = alpha * 0.5 * (n - 1.0) - 0.5;
  Eigen::MatrixXd normal(size, size);
  {
    std::vector<Complex> e0(static_cast<std::size_t>(2 * order + 1)), e1(e0.size());
    for (int m = 0; m <= 2 * order; ++m) {
      const auto [s0, s1] = geometric_power_sums(m * main_step - m * heading_step, n);
      const Complex phase = std::polar(1.0, -m * psi0);
      e0[static_cast<std::size_t>(m)] = phase * s0;
      e1[static_cast<std::size_t>(m)] = phase * s1;
    }
    const auto sum = [](const std::vector<Complex>& e, int m) {
      return m >= 0 ? e[static_cast<std::size_t>(m)] : std::conj(e[static_cast<std::size_t>(-m)]);
    };
    const auto harmonic = [](int j) { return (j + 1) / 2; };
    const auto is_sine = [](int j) { return j > 0 && j % 2 == 0; };
    for (int a = 0; a < harmonics; ++a)
      for (int b = 0; b < harmonics; ++b) {
        const Complex diff = sum(e0, harmonic(a) - harmonic(b)), plus = sum(e0, harmonic(a) + harmonic(b));
        normal(a, b) = !is_sine(a) && !is_sine(b) ? 0.5 * (diff + plus).real()
                       : is_sine(a) && is_sine(b) ? 0.5 * (diff - plus).real()
                       : is_sine(a)               ? 0.5 * (plus + diff).imag()
                                                  : 0.5 * (plus - diff).imag();
      }
    if (drift) {
      const int t = harmonics;
      for (int a = 0; a < harmonics; ++a) {
        const Complex v = alpha * sum(e1, harmonic(a)) - 0.5 * sum(e0, harmonic(a));
        normal(a, t) = normal(t, a) = is_sine(a) ? v.imag() : v.real();
      }
      const double si = 0.5 * n * (n - 1.0), sii = (n - 1.0) * n * (2.0 * n - 1.0) / 6.0;
      normal(t, t) = alpha * alpha * sii - alpha * si + 0.25 * n;
    }
  }
  const auto ldlt = normal.ldlt();
  const auto ng = static_cast<Eigen::Index>(d.gammas_rad.size());
  Eigen::MatrixXd basis(size, ng);
  for (Eigen::Index g = 0; g < ng; ++g) {
    harmonic_basis(d.gammas_rad[static_cast<std::size_t>(g)], order, basis.col(g).data());
    if (drift) basis(harmonics, g) = t_mid;
  }

  // The reduced values of every column from sums[set][column].
  const auto reduce = [&](const std::vector<std::vector<Complex>>& sums) {
    Eigen::MatrixXd values(ng, columns);
    for (int c = 0; c < columns; ++c) {
      if (!spinning) {
        values.col(c).setConstant(sums[0][static_cast<std::size_t>(c)].real() / n);
        continue;
      }
      Eigen::VectorXd rhs(size);
      rhs[0] = sums[0][static_cast<std::size_t>(c)].real();
      for (int h = 1; h <= order; ++h) {
        rhs[2 * h - 1] = sums[static_cast<std::size_t>(h)][static_cast<std::size_t>(c)].real();
        rhs[2 * h] = sums[static_cast<std::size_t>(h)][static_cast<std::size_t>(c)].imag();
      }
      if (drift)
        rhs[harmonics] =
            alpha * sums[static_cast<std::size_t>(order + 1)][static_cast<std::size_t>(c)].real() -
            0.5 * rhs[0];
      values.col(c) = basis.transpose() * ldlt.solve(rhs);
    }
    return values;
  };

  // The model terms on a grid of M x M angles (1 along a joint that does not turn), then the weighted sums
  // on it and on its every other point; M doubles until the two agree.
  std::vector<double> f;
  for (int grid = kFirstGrid; grid <= kLastGrid; grid *= 2) {
    const int mt = main_step != 0.0 ? grid : 1, mh = heading_step != 0.0 ? grid : 1;
    f.assign(static_cast<std::size_t>(mt * mh * columns), 0.0);
    for (int a = 0; a < mt; ++a)
      for (int b = 0; b < mh; ++b)
        evaluate(theta0 + 2.0 * kPi * a / mt, psi0 + (2.0 * kPi * b / mh - 2.0 * kPi * a / mt),
                 &f[static_cast<std::size_t>((a * mh + b) * columns)]);
    // Each column's tolerance: kConverged of its largest value, plus eight times the rounding of its
    // evaluation, seen as the change of a value when both angles move by a whole turn (omega_O and omega_S
    // are differences of the main and counter rates, 2e6 deg/h each, which round at 1e-10 deg/h; at 1e7 rad
    // an angle itself rounds at 1e-9 rad).
    std::vector<double> tolerance(static_cast<std::size_t>(columns), 0.0), probe(tolerance);
    for (std::size_t i = 0; i < f.size(); ++i)
      tolerance[i % static_cast<std::size_t>(columns)] =
          std::max(tolerance[i % static_cast<std::size_t>(columns)], kConverged * std::abs(f[i]));
    for (int a = 0; a < mt; a += std::max(1, mt / 4)) {
      const int b = (a * 3) % mh;
      evaluate(theta0 + 2.0 * kPi * a / mt + 2.0 * kPi,
               psi0 + (2.0 * kPi * b / mh - 2.0 * kPi * a / mt) + 2.0 * kPi, probe.data());
      for (int c = 0; c < columns; ++c)
        tolerance[static_cast<std::size_t>(c)] +=
            8.0 * std::abs(probe[static_cast<std::size_t>(c)] -
                           f[static_cast<std::size_t>((a * mh + b) * columns + c)]);
    }
    // Sums on the full grid (step 1) and on the half grid (step 2 along each turning joint).
    Eigen::MatrixXd result[2];
    for (int half = 0; half < 2; ++half) {
      const int st = mt > 1 ? 1 + half : 1, sp = mh > 1 ? 1 + half : 1;
      const int gt = mt / st, gp = mh / sp;
      std::vector<std::vector<Complex>> sums(static_cast<std::size_t>(ns),
                                             std::vector<Complex>(static_cast<std::size_t>(columns), 0.0));
      for (int s = 0; s < ns; ++s) {
        const std::vector<Complex> k =
            quadrature_weights(sets[static_cast<std::size_t>(s)], gt, gp, n, psi0, main_step, heading_step);
        for (int a = 0; a < gt; ++a)
          for (int b = 0; b < gp; ++b) {
            const Complex kw = k[static_cast<std::size_t>(a * gp + b)];
            const double* fv = &f[static_cast<std::size_t>(((a * st) * mh + b * sp) * columns)];
            for (int c = 0; c < columns; ++c)
              sums[static_cast<std::size_t>(s)][static_cast<std::size_t>(c)] += kw * fv[c];
          }
      }
      result[half] = reduce(sums);
    }
    bool converged = result[0].allFinite();
    for (int c = 0; c < columns && converged; ++c)
      converged = (result[0].col(c) - result[1].col(c)).cwiseAbs().maxCoeff() <=
                  tolerance[static_cast<std::size_t>(c)];
    if (!converged && (mt > 1 || mh > 1)) continue;
    out.assign(static_cast<std::size_t>(columns), DwellValues{});
    for (int c = 0; c < columns; ++c) {
      DwellValues& v = out[static_cast<std::size_t>(c)];
      v.value.assign(d.gammas_rad.size(), 0.0);
      v.std_err.assign(d.gammas_rad.size(), std::numeric_limits<double>::quiet_NaN());
      v.samples.assign(d.gammas_rad.size(), d.samples);
      for (Eigen::Index g = 0; g < ng; ++g) v.value[static_cast<std::size_t>(g)] = result[0](g, c);
    }
    return true;
  }
  return false;
}

}  // namespace gyrocal
