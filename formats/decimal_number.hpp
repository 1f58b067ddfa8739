#pragma once
// std::from_chars for a double (chars_format::general, as every CSV reader of the project
// calls it), the same value, end and error bit for bit, but about twice as fast on the plain
// decimals recordings hold: "-0.095492528826543799", "1234.56". Reading a 10⁷-line recording
// spent half its time in std::from_chars (issue 15).
//
// A plain decimal is [-]digits[.digits] with at most 19 significant digits, so that its
// digits are an exact integer w < 10¹⁹ and its value is w / 10^k, k the number of digits
// after the point. That quotient is rounded once, correctly, when
//   - w ≤ 2⁵³ and k ≤ 22: w and 10^k are exact doubles and one IEEE division rounds
//     (Clinger's fast path, "How to read floating point numbers accurately", PLDI 1990);
//   - else on x86-64 with k ≤ 27: w and 10^k (5^27 < 2⁶⁴) are exact in the x87 80-bit long
//     double, whose division rounds to 64 bits; rounding that to 53 bits again gives the
//     correctly rounded double unless the 64-bit quotient lies exactly halfway between two
//     doubles (its low 11 bits 100 0000 0000), the one case left to std::from_chars.
// Everything else (exponents, more digits, "inf", ".5", "1.") goes to std::from_chars.
#include <bit>
#include <cfloat>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <limits>
#include <system_error>

namespace gyrod::recording {
namespace decimal_detail {

// Eight ASCII digits in a word read little-endian (each byte within '0'..'9').
inline bool areEightDigits(std::uint64_t word) {
  return (((word + 0x4646464646464646ULL) | (word - 0x3030303030303030ULL)) & 0x8080808080808080ULL) == 0;
}

// The value of eight ASCII digits read little-endian, the first digit the most significant:
// pairs, then fours, then the eight, by multiplications within the word.
inline std::uint32_t eightDigitsValue(std::uint64_t word) {
  word -= 0x3030303030303030ULL;
  word = word * 10 + (word >> 8);
  word = (((word & 0x000000FF000000FFULL) * 0x000F424000000064ULL) +
          (((word >> 16) & 0x000000FF000000FFULL) * 0x0000271000000001ULL)) >>
         32;
  return static_cast<std::uint32_t>(word);
}

inline constexpr double kExactPowersOfTen[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                               1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

#if defined(__x86_64__)
inline constexpr bool kExtendedQuotient = std::numeric_limits<long double>::digits == 64;
inline constexpr long double kExactPowersOfTenLong[] = {
    1e0L,  1e1L,  1e2L,  1e3L,  1e4L,  1e5L,  1e6L,  1e7L,  1e8L,  1e9L,  1e10L, 1e11L, 1e12L, 1e13L,
    1e14L, 1e15L, 1e16L, 1e17L, 1e18L, 1e19L, 1e20L, 1e21L, 1e22L, 1e23L, 1e24L, 1e25L, 1e26L, 1e27L};
#else
inline constexpr bool kExtendedQuotient = false;
#endif

inline bool isDigit(char c) { return static_cast<unsigned char>(c - '0') < 10; }

// The plain decimal at [first, last) correctly rounded into `value`, and the end of what it
// read; nullptr (value untouched) when the text is not one this can round on its own.
inline const char* plainDecimal(const char* first, const char* last, double& value) {
  const char* p = first;
  const bool negative = p != last && *p == '-';
  if (negative) ++p;
  const char* const digits_begin = p;
  std::uint64_t w = 0;  // wraps beyond 19 significant digits: refused below
  while (p != last && isDigit(*p)) w = w * 10 + static_cast<unsigned>(*p++ - '0');
  if (p == digits_begin) return nullptr;
  const char* const int_end = p;
  int fraction_digits = 0;
  if (p != last && *p == '.') {
    const char* const fraction_begin = ++p;
    if constexpr (std::endian::native == std::endian::little) {
      while (last - p >= 8) {
        std::uint64_t word = 0;
        std::memcpy(&word, p, sizeof word);
        if (!areEightDigits(word)) break;
        w = w * 100000000 + eightDigitsValue(word);
        p += 8;
      }
    }
    while (p != last && isDigit(*p)) w = w * 10 + static_cast<unsigned>(*p++ - '0');
    fraction_digits = static_cast<int>(p - fraction_begin);
    if (fraction_digits == 0) return nullptr;  // "1." is std::from_chars's to read
  }
  if (p != last && (*p == 'e' || *p == 'E')) return nullptr;
  const auto all_digits = (int_end - digits_begin) + fraction_digits;
  if (all_digits > 19) {  // leading zeros do not count, wherever the point is
    int significant = static_cast<int>(all_digits);
    for (const char* q = digits_begin; q != p && (*q == '0' || *q == '.'); ++q) significant -= *q == '0' ? 1 : 0;
    if (significant > 19) return nullptr;
  }
  double magnitude = 0.0;
  if (w <= (std::uint64_t{1} << 53) && fraction_digits <= 22 && FLT_EVAL_METHOD == 0) {
    magnitude = static_cast<double>(w) / kExactPowersOfTen[fraction_digits];
  } else {
#if defined(__x86_64__)
    if constexpr (!kExtendedQuotient) return nullptr;
    if (fraction_digits > 27) return nullptr;
    const long double quotient = static_cast<long double>(w) / kExactPowersOfTenLong[fraction_digits];
    std::uint64_t significand = 0;  // the 64 bits of the quotient's significand come first
    std::memcpy(&significand, &quotient, sizeof significand);
    if ((significand & 0x7FF) == 0x400) return nullptr;  // halfway: a second rounding could err
    magnitude = static_cast<double>(quotient);
#else
    return nullptr;
#endif
  }
  value = negative ? -magnitude : magnitude;
  return p;
}

}  // namespace decimal_detail

// std::from_chars(first, last, value) with chars_format::general, faster on plain decimals.
inline std::from_chars_result decimalFromChars(const char* first, const char* last, double& value) {
  if (const char* end = decimal_detail::plainDecimal(first, last, value)) return {end, std::errc()};
  return std::from_chars(first, last, value);
}

}  // namespace gyrod::recording
