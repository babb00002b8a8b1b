#pragma once
// A reproducible random source: the same seed gives the same sequence bit for bit on any platform and
// compiler (docs/noise.md, "Reproducibility").
//
// - Generator: xoshiro256** 1.0 (Blackman & Vigna 2018), its 256-bit state filled by splitmix64 from a
//   64-bit seed, as the authors recommend. Both are integer arithmetic, hence exact everywhere.
// - Streams: derive_stream_seed(seed, k) hashes (seed, k) with splitmix64's finaliser, so that Monte Carlo
//   trial k or noise term k draws from its own stream whatever the number of threads or the order of work.
// - Normal deviates: Marsaglia's polar method (Marsaglia & Bray 1964), not std::normal_distribution, whose
//   algorithm is implementation-defined. It needs only +, -, *, /, sqrt (correctly rounded by IEEE 754) and
//   a logarithm; portable_log below is built from those operations alone, since std::log may differ in the
//   last bit between C libraries. The implementation files forbid floating-point contraction (FMA), which
//   would otherwise change the rounding on some targets; do not build with -ffast-math.
#include <array>
#include <cstdint>

namespace gyrocal {

/// One step of splitmix64 (Steele, Lea & Flood 2014; Vigna's reference code): advances `state` by the golden
/// gamma 0x9E3779B97F4A7C15 and returns the mixed value of the new state.
std::uint64_t splitmix64_next(std::uint64_t& state);

/// The seed of stream `stream` of `seed`: mix(mix(seed) + (stream + 1) * gamma) with splitmix64's finaliser
/// `mix`. Distinct streams of one seed give distinct seeds (mix is a bijection and gamma is odd).
std::uint64_t derive_stream_seed(std::uint64_t seed, std::uint64_t stream);

/// Natural logarithm of x > 0 (finite, normal or subnormal) from +, -, *, / alone, so the same bits
/// everywhere; within 2 ulp of the true value. NaN for x <= 0 or NaN, +inf for +inf.
double portable_log(double x);

/// e^x from +, -, * and exact scaling by powers of two, so the same bits everywhere; within 2 ulp of the true
/// value for -708 < x < 709. 0 below -745.2, +inf above 709.8, NaN for NaN.
double portable_exp(double x);

/// xoshiro256** seeded through derive_stream_seed(seed, stream) and splitmix64.
class RandomSource {
 public:
  /// seed: any 64-bit value; stream: index of an independent stream of that seed (e.g. a Monte Carlo trial).
  explicit RandomSource(std::uint64_t seed, std::uint64_t stream = 0);

  /// The next 64 random bits (xoshiro256** 1.0).
  std::uint64_t next_u64() {
    const std::uint64_t result = rotl(state_[1] * 5u, 7) * 9u;
    const std::uint64_t t = state_[1] << 17;
    state_[2] ^= state_[0];
    state_[3] ^= state_[1];
    state_[1] ^= state_[2];
    state_[0] ^= state_[3];
    state_[2] ^= t;
    state_[3] = rotl(state_[3], 45);
    return result;
  }

  /// Uniform on [0, 1): the top 53 bits of next_u64() times 2^-53 (exact).
  double uniform() { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }

  /// Standard normal deviate (mean 0, variance 1), Marsaglia's polar method: draws u, v uniform on [-1, 1)
  /// until 0 < s = u^2 + v^2 < 1, then returns u*sqrt(-2 ln s / s) and keeps v*sqrt(-2 ln s / s) for the next
  /// call.
  double normal();

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

  std::array<std::uint64_t, 4> state_{};
  double spare_normal_ = 0.0;
  bool has_spare_normal_ = false;
};

}  // namespace gyrocal
