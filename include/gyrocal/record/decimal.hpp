#pragma once
// The record reader's parser of short plain decimals ("357.1638594870602", "-0.005", "16645042"), the form
// nearly every field of a record has (docs/records.md, "Speed"). It gives exactly the double that
// fast_float::from_chars_advanced gives for the same text, or declines and leaves the text to fast_float:
//
// - It accepts only: an optional '-', then digits, an optional decimal mark and digits, at least one digit,
//   at most 16 before the mark, 16 after it and 19 in all, not followed by a digit, 'e' or 'E'. Anything
//   else (an exponent, a '+', "inf", "nan", more digits, no digit) is declined: the caller falls back to
//   fast_float.
// - For an accepted text both read the same digits w (< 10^19, so exact in 64 bits) and the same power of
//   ten q = -(digits after the mark), and both end at the same byte.
// - The value is w * 10^q correctly rounded (to nearest, ties to even) by the Eisel-Lemire routine of
//   fast_float itself (fast_float::compute_float), which decides every w < 2^64 for -27 <= q <= 55, so
//   it never reports the rare failure it can report beyond that range. fast_float reaches the same routine
//   for w > 2^53 and otherwise takes Clinger's shortcut (w and 10^-q exact doubles, one division): another
//   correctly rounded route to the same double. An integer of at most 15 digits (below 2^53) is converted
//   directly: it is a double exactly, so no rounding is involved. The sign is applied last; "-0" is -0.0.
// - Integer arithmetic and exact conversions only: the result does not depend on the floating-point
//   rounding mode (fast_float's result does not either).
// tests/test_decimal.cpp checks the result against glibc's strtod and against fast_float on many random and
// edge-case texts. It relies on fast_float's compute_float, adjusted_mantissa and binary_format (Debian's
// libfast-float-dev 3.9), which are in its headers but not its documented interface.
//
// To find the digits without a branch per byte, the parser reads up to kDecimalReadBefore bytes before
// `first` and kDecimalReadAfter bytes after `last`; the caller's buffer must hold them (their values do not
// matter: they are masked off).
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <fast_float/fast_float.h>

namespace gyrocal {

/// Bytes parse_short_decimal may read before `first` and after `last` (see the top of this header).
inline constexpr std::size_t kDecimalReadBefore = 16;
inline constexpr std::size_t kDecimalReadAfter = 64;

namespace short_decimal {

[[gnu::always_inline]] inline std::uint64_t load8(const char* p) {
  std::uint64_t v = 0;
  std::memcpy(&v, p, sizeof v);
  return v;
}

/// The 8 digit values of `v` (byte 0, the lowest address, the most significant; each 0..9) as an integer.
[[gnu::always_inline]] inline std::uint32_t eight_digits(std::uint64_t v) {
  constexpr std::uint64_t kMask = 0x000000FF000000FF;
  constexpr std::uint64_t kMul1 = 100 + (std::uint64_t{1000000} << 32);
  constexpr std::uint64_t kMul2 = 1 + (std::uint64_t{10000} << 32);
  v = v * 10 + (v >> 8);
  v = ((v & kMask) * kMul1 + ((v >> 16) & kMask) * kMul2) >> 32;
  return static_cast<std::uint32_t>(v);
}

/// Masks that keep the last n bytes of 8 (the n highest: little-endian), n = 0..8.
inline constexpr std::uint64_t kKeepLast[9] = {0,
                                               0xFF00000000000000,
                                               0xFFFF000000000000,
                                               0xFFFFFF0000000000,
                                               0xFFFFFFFF00000000,
                                               0xFFFFFFFFFF000000,
                                               0xFFFFFFFFFFFF0000,
                                               0xFFFFFFFFFFFFFF00,
                                               0xFFFFFFFFFFFFFFFF};
inline constexpr std::uint64_t kZeros = 0x3030303030303030;  // "00000000"

/// The value of the n <= 8 ASCII digits that end at `end`.
[[gnu::always_inline]] inline std::uint64_t up_to_8_digits(const char* end, unsigned n) {
  const std::uint64_t keep = kKeepLast[n];
  return eight_digits((load8(end - 8) & keep) - (kZeros & keep));  // no borrow: every kept byte is >= '0'
}

/// 16 zero bytes, then 16 bytes 0xFF: the 16 bytes from kSlide + n keep the last n of 16.
alignas(32) inline constexpr unsigned char kSlide[32] = {
    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,
    0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};

/// The value of the n <= 16 ASCII digits that end at `end`, without a branch on n: two octets of
/// up_to_8_digits.
[[gnu::always_inline]] inline std::uint64_t up_to_16_digits_portable(const char* end, unsigned n) {
  const unsigned low = n < 8 ? n : 8;
  const std::uint64_t keep_high = kKeepLast[n - low];
  const std::uint64_t high = eight_digits((load8(end - 16) & keep_high) - (kZeros & keep_high));
  return high * 100000000 + up_to_8_digits(end, low);
}

/// The same as up_to_16_digits_portable (tests/test_decimal.cpp compares them), with SSE2 where there is
/// SSE2.
[[gnu::always_inline]] inline std::uint64_t up_to_16_digits(const char* end, unsigned n) {
#if defined(__SSE2__)
  // The 16 bytes before `end`, less '0', all but the last n zeroed: 16 digit values d0..d15 (d0 the most
  // significant). Pairs, then quadruples, then octets by multiply-adds of 16-bit lanes.
  const __m128i zero = _mm_setzero_si128();
  __m128i x = _mm_sub_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(end - 16)), _mm_set1_epi8('0'));
  x = _mm_and_si128(x, _mm_loadu_si128(reinterpret_cast<const __m128i*>(kSlide + n)));
  const __m128i pairs_low =
      _mm_madd_epi16(_mm_unpacklo_epi8(x, zero), _mm_setr_epi16(10, 1, 10, 1, 10, 1, 10, 1));
  const __m128i pairs_high =
      _mm_madd_epi16(_mm_unpackhi_epi8(x, zero), _mm_setr_epi16(10, 1, 10, 1, 10, 1, 10, 1));
  __m128i v = _mm_packs_epi32(pairs_low, pairs_high);                     // 8 values <= 99
  v = _mm_madd_epi16(v, _mm_setr_epi16(100, 1, 100, 1, 100, 1, 100, 1));  // 4 values <= 9999
  v = _mm_packs_epi32(v, v);
  v = _mm_madd_epi16(v, _mm_setr_epi16(10000, 1, 10000, 1, 10000, 1, 10000, 1));  // 2 values <= 99999999
  const auto octets = static_cast<std::uint64_t>(_mm_cvtsi128_si64(v));
  return (octets & 0xFFFFFFFF) * 100000000 + (octets >> 32);
#else
  return up_to_16_digits_portable(end, n);
#endif
}

inline constexpr std::uint64_t kPow10[17] = {1,
                                             10,
                                             100,
                                             1000,
                                             10000,
                                             100000,
                                             1000000,
                                             10000000,
                                             100000000,
                                             1000000000,
                                             10000000000,
                                             100000000000,
                                             1000000000000,
                                             10000000000000,
                                             100000000000000,
                                             1000000000000000,
                                             10000000000000000};

/// Bit k set when first[k] is an ASCII digit, k < 32, one byte at a time.
[[gnu::always_inline]] inline std::uint32_t digits_of_32_portable(const char* first) {
  std::uint32_t mask = 0;
  for (unsigned k = 0; k < 32; ++k) {
    if (static_cast<unsigned char>(first[k] - '0') < 10) mask |= std::uint32_t{1} << k;
  }
  return mask;
}

/// The same as digits_of_32_portable (tests/test_decimal.cpp compares them), with SSE2 where there is SSE2.
[[gnu::always_inline]] inline std::uint32_t digits_of_32(const char* first) {
#if defined(__SSE2__)
  const __m128i zero = _mm_set1_epi8('0');
  const __m128i nine = _mm_set1_epi8(9);
  const __m128i a = _mm_sub_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(first)), zero);
  const __m128i b = _mm_sub_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(first + 16)), zero);
  // A digit's byte minus '0' is 0..9 unsigned: min(x, 9) == x.
  return static_cast<std::uint32_t>(_mm_movemask_epi8(_mm_cmpeq_epi8(_mm_min_epu8(a, nine), a))) |
         (static_cast<std::uint32_t>(_mm_movemask_epi8(_mm_cmpeq_epi8(_mm_min_epu8(b, nine), b))) << 16);
#else
  return digits_of_32_portable(first);
#endif
}

/// Bit k set when first[k] (k < 32, first + k < last) is an ASCII digit.
[[gnu::always_inline]] inline std::uint32_t digit_mask(const char* first, const char* last) {
  std::uint32_t mask = digits_of_32(first);
  const std::ptrdiff_t room = last - first;
  if (room < 32) mask &= (std::uint32_t{1} << room) - 1;
  return mask;
}

}  // namespace short_decimal

/// A short plain decimal found by scan_short_decimal: its digits and where they are.
struct ShortDecimal {
  const char* whole_end = nullptr;  ///< the end of the digits before the mark
  const char* end = nullptr;        ///< the end of the number (of the digits after the mark, if any)
  unsigned whole = 0;               ///< digits before the mark, <= 16
  unsigned fraction = 0;            ///< digits after the mark, <= 16; whole + fraction in [1, 19]
  bool negative = false;
};

/// Finds the short plain decimal at `first` (before `last`, with the decimal mark `decimal`) into `out`;
/// returns its end, or nullptr when the text is not of that form (see the top of this header): then
/// fast_float::from_chars_advanced must parse it. The buffer must be readable kDecimalReadBefore bytes before
/// `first` and kDecimalReadAfter bytes after `last`.
[[gnu::always_inline]] inline const char* scan_short_decimal(const char* first, const char* last,
                                                             char decimal, ShortDecimal& out) {
  if (first == last) return nullptr;
  const bool negative = *first == '-';
  const char* const digits = first + (negative ? 1 : 0);
  const std::uint64_t mask = short_decimal::digit_mask(digits, last);    // bits 32 and up: 0
  const unsigned whole = static_cast<unsigned>(__builtin_ctzll(~mask));  // <= 32
  if (whole > 16) return nullptr;
  const char* end = digits + whole;
  unsigned fraction = 0;
  if (end != last && *end == decimal) {
    fraction = static_cast<unsigned>(__builtin_ctzll(~(mask >> (whole + 1))));
    end += 1 + fraction;
  }
  if (fraction > 16 || whole + fraction > 19 || whole + fraction == 0) return nullptr;
  // The number must end here for fast_float too: not at a digit beyond the 32 bytes looked at, nor at an
  // exponent (fast_float reads "1e5" on, and "1e" as 1 before the 'e': left to it).
  if (end != last && (static_cast<unsigned char>(*end - '0') < 10 || *end == 'e' || *end == 'E'))
    return nullptr;
  out.whole_end = digits + whole;
  out.end = end;
  out.whole = whole;
  out.fraction = fraction;
  out.negative = negative;
  return end;
}

/// The value of a number found by scan_short_decimal into `value`: w * 10^-fraction correctly rounded, with
/// its sign (see the top of this header). False (`value` unchanged) in the case compute_float cannot decide,
/// which does not arise for these w and q (a guard: the caller then leaves the text to fast_float).
[[gnu::always_inline]] inline bool short_decimal_value(const ShortDecimal& d, double& value) {
  std::uint64_t w = d.whole <= 8 ? short_decimal::up_to_8_digits(d.whole_end, d.whole)
                                 : short_decimal::up_to_16_digits(d.whole_end, d.whole);
  if (d.fraction > 0) {
    w = w * short_decimal::kPow10[d.fraction] + (d.fraction <= 8
                                                     ? short_decimal::up_to_8_digits(d.end, d.fraction)
                                                     : short_decimal::up_to_16_digits(d.end, d.fraction));
  } else if (d.whole <= 15) {
    // An integer below 10^15 < 2^53 is a double exactly: no rounding (fast_float's shortcut too).
    value = std::bit_cast<double>(std::bit_cast<std::uint64_t>(static_cast<double>(w)) |
                                  (static_cast<std::uint64_t>(d.negative) << 63));
    return true;
  }
  // w < 10^19 and q in [-16, 0]: compute_float's Eisel-Lemire product decides every case (power2 >= 0).
  const fast_float::adjusted_mantissa am =
      fast_float::compute_float<fast_float::binary_format<double>>(-static_cast<std::int64_t>(d.fraction), w);
  if (am.power2 < 0) return false;
  // fast_float::to_float's packing (mantissa without its implicit bit, biased exponent, sign), with the sign
  // or'ed in as a bit: a choice between two words would be a branch, mispredicted on half of a noisy column.
  const std::uint64_t word = am.mantissa | (static_cast<std::uint64_t>(am.power2) << 52) |
                             (static_cast<std::uint64_t>(d.negative) << 63);
  value = std::bit_cast<double>(word);
  return true;
}

/// scan_short_decimal and short_decimal_value in one: the end of the number and its value in `value`, or
/// nullptr (`value` unchanged) for text of another form, which fast_float::from_chars_advanced must parse.
[[gnu::always_inline]] inline const char* parse_short_decimal(const char* first, const char* last,
                                                              char decimal, double& value) {
  ShortDecimal d;
  const char* const end = scan_short_decimal(first, last, decimal, d);
  if (end == nullptr || !short_decimal_value(d, value)) return nullptr;
  return end;
}

}  // namespace gyrocal
