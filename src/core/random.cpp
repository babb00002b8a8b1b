#include "gyrocal/core/random.hpp"

#include <bit>
#include <cmath>
#include <limits>

// Bit-for-bit reproducibility needs no fused multiply-add: the build sets -ffp-contract=off (CMakeLists.txt).

namespace gyrocal {

namespace {

constexpr std::uint64_t kGoldenGamma = 0x9E3779B97F4A7C15u;

// splitmix64's finaliser (a bijection of 64-bit words).
std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9u;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBu;
  return z ^ (z >> 31);
}

// ln 2 split so that k * kLn2Hi is exact for |k| < 2^20 (fdlibm's constants).
constexpr double kLn2Hi = 6.93147180369123816490e-01;
constexpr double kLn2Lo = 1.90821492927058770002e-10;
constexpr double kInvLn2 = 1.44269504088896338700e+00;

}  // namespace

std::uint64_t splitmix64_next(std::uint64_t& state) {
  state += kGoldenGamma;
  return mix64(state);
}

std::uint64_t derive_stream_seed(std::uint64_t seed, std::uint64_t stream) {
  return mix64(mix64(seed) + (stream + 1u) * kGoldenGamma);
}

double portable_log(double x) {
  if (std::isnan(x) || x <= 0.0) return std::numeric_limits<double>::quiet_NaN();
  if (std::isinf(x)) return x;
  // x = m * 2^e with m in [sqrt(1/2), sqrt(2)): read from the bits for normal x, frexp for subnormal x; both
  // exact.
  int e = 0;
  double m = 0.0;
  const auto bits = std::bit_cast<std::uint64_t>(x);
  const auto biased_exponent = static_cast<int>(bits >> 52);  // the sign bit is 0
  if (biased_exponent != 0) {
    e = biased_exponent - 1023;
    m = std::bit_cast<double>((bits & 0x000FFFFFFFFFFFFFu) | 0x3FF0000000000000u);  // [1, 2)
  } else {
    m = 2.0 * std::frexp(x, &e);
    --e;
  }
  if (m > 1.41421356237309504880) {
    m *= 0.5;
    ++e;
  }
  // ln m = 2 atanh(f) = 2 f (1 + s/3 + s^2/5 + ... + s^11/23), f = (m-1)/(m+1), s = f^2; |f| <= 0.1716 and
  // s <= 0.0295 leave a truncation below 1e-18 relative. The coefficients are folded at compile time to the
  // correctly rounded quotients that IEEE division gives at run time. Even and odd powers of s are summed in
  // two chains (in s^2) to halve the latency.
  const double f = (m - 1.0) / (m + 1.0);
  const double s = f * f;
  const double s2 = s * s;
  double even = 1.0 / 23.0;  // 1/3 + s^2/7 + ... + s^10/23, the coefficients of s^0, s^2, ...
  double odd = 1.0 / 21.0;   // 1/5 + s^2/9 + ... + s^8/21, those of s^1, s^3, ...
  even = 1.0 / 19.0 + s2 * even;
  odd = 1.0 / 17.0 + s2 * odd;
  even = 1.0 / 15.0 + s2 * even;
  odd = 1.0 / 13.0 + s2 * odd;
  even = 1.0 / 11.0 + s2 * even;
  odd = 1.0 / 9.0 + s2 * odd;
  even = 1.0 / 7.0 + s2 * even;
  odd = 1.0 / 5.0 + s2 * odd;
  even = 1.0 / 3.0 + s2 * even;
  const double series = even + s * odd;  // 1/3 + s/5 + s^2/7 + ...
  const double log_m = 2.0 * f + 2.0 * f * s * series;
  const double ed = static_cast<double>(e);
  return ed * kLn2Hi + (ed * kLn2Lo + log_m);
}

double portable_exp(double x) {
  if (std::isnan(x)) return x;
  if (x > 709.8) return std::numeric_limits<double>::infinity();
  if (x < -745.2) return 0.0;
  // x = k ln2 + r, |r| <= ln2/2 (std::round is exact); e^r by its Taylor series to r^16/16! (truncation <
  // 1e-19).
  const double k = std::round(x * kInvLn2);
  const double r = (x - k * kLn2Hi) - k * kLn2Lo;
  double p = 1.0 / 20922789888000.0;  // 1/16!
  double factorial = 20922789888000.0;
  for (int n = 16; n >= 1; --n) {
    factorial /= static_cast<double>(n);  // (n-1)!, exact: every factorial up to 16! is a double
    p = 1.0 / factorial + r * p;
  }
  return std::ldexp(p, static_cast<int>(k));
}

RandomSource::RandomSource(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t sm = derive_stream_seed(seed, stream);
  for (std::uint64_t& word : state_) word = splitmix64_next(sm);
  // splitmix64 outputs are a bijection of distinct states, so at most one word is zero: the state is never
  // all zero, the one state xoshiro256** must avoid.
}

double RandomSource::normal() {
  if (has_spare_normal_) {
    has_spare_normal_ = false;
    return spare_normal_;
  }
  double u = 0.0;
  double v = 0.0;
  double s = 0.0;
  do {
    u = 2.0 * uniform() - 1.0;
    v = 2.0 * uniform() - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double factor = std::sqrt(-2.0 * portable_log(s) / s);
  spare_normal_ = v * factor;
  has_spare_normal_ = true;
  return u * factor;
}

}  // namespace gyrocal
