#pragma once
// std::from_chars for a double (chars_format::general, as every CSV reader of the project
// calls it), the same value, end and error bit for bit, and faster on the plain decimals
// recordings hold: "-0.095492528826543799", "1234.56" (issue 15: reading a 10⁷-line
// recording spent half its time in std::from_chars). The gain is modest, ~1.15× a number
// (docs/performance.md): libstdc++'s from_chars is already Lemire's fast_float; what is
// saved is its generality, and the digits of the fraction are read eight at a time.
//
// A plain decimal is [-]digits[.digits] with at most 19 significant digits, so that its
// digits are an exact integer w < 10¹⁹ and its value is w / 10^k, k ≤ 27 the number of
// digits after the point. That quotient is rounded once, correctly:
//   - w ≤ 2⁵³ and k ≤ 22: w and 10^k are exact doubles and one IEEE division rounds
//     (Clinger's fast path, "How to read floating point numbers accurately", PLDI 1990);
//   - else w / 10^k = w / 5^k · 2^−k from w times a 128-bit truncation of 2^b / 5^k (the
//     method of Lemire, "Number parsing at a gigabyte per second", 2021): the 192-bit
//     product lies below the exact one by less than 2⁶⁴, so the bits below the double's 53
//     decide the rounding unless they come within 2⁶⁴ of halfway or of a carry, the rare
//     case (exact midpoints among them) left to std::from_chars.
// Everything else (exponents, more digits, "inf", ".5", "1.") goes to std::from_chars.
#include <array>
#include <bit>
#include <cfloat>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <system_error>

namespace gyrod::recording {
namespace decimal_detail {

// A word read little-endian with the high bit of each byte set from the first byte that is
// not an ASCII digit on (the bytes after it may be marked too: a borrow runs upwards);
// zero for eight digits.
inline std::uint64_t nonDigitBytes(std::uint64_t word) {
  return ((word + 0x4646464646464646ULL) | (word - 0x3030303030303030ULL)) & 0x8080808080808080ULL;
}

inline constexpr std::uint64_t kPowersOfTenInteger[] = {1, 10, 100, 1000, 10000, 100000, 1000000, 10000000, 100000000};

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

#if defined(__SIZEOF_INT128__)
__extension__ typedef unsigned __int128 Uint128;  // GCC and Clang on 64-bit targets

// 2^(127 + c) / 5^k rounded down, c the bit length of 5^k (so that it lies in [2¹²⁷, 2¹²⁸)),
// for 1 ≤ k ≤ 27 (5²⁷ < 2⁶³); by long division, one bit of 2^(127 + c) at a time.
struct ReciprocalOfFive {
  Uint128 truncated = 0;
  int bits_of_power = 0;  // c
};
constexpr ReciprocalOfFive reciprocalOfFiveToThe(int k) {
  std::uint64_t power = 1;
  for (int i = 0; i < k; ++i) power *= 5;
  const int bits = 64 - std::countl_zero(power);
  Uint128 quotient = 0;
  std::uint64_t remainder = 1;  // the leading 1 of 2^(127 + c); power > 1 takes none of it
  for (int i = 0; i < 127 + bits; ++i) {
    remainder <<= 1;  // < 2 · power < 2⁶⁴
    quotient <<= 1;
    if (remainder >= power) {
      remainder -= power;
      quotient |= 1;
    }
  }
  return {quotient, bits};
}
constexpr int kLongestFraction = 27;
inline constexpr auto kReciprocalsOfFive = [] {
  std::array<ReciprocalOfFive, kLongestFraction + 1> table{};
  for (int k = 1; k <= kLongestFraction; ++k) table[static_cast<std::size_t>(k)] = reciprocalOfFiveToThe(k);
  return table;
}();

// w / 10^k correctly rounded into `value` for 1 ≤ w < 2⁶⁴, 1 ≤ k ≤ 27; false (value
// untouched) when the truncated product cannot tell the rounding.
inline bool roundedQuotientOfTenPower(std::uint64_t w, int k, double& value) {
  const ReciprocalOfFive& r = kReciprocalsOfFive[static_cast<std::size_t>(k)];
  const int leading_zeros = std::countl_zero(w);
  const std::uint64_t normalized = w << leading_zeros;  // in [2⁶³, 2⁶⁴)
  const Uint128 low_product = static_cast<Uint128>(normalized) * static_cast<std::uint64_t>(r.truncated);
  const Uint128 high_product = static_cast<Uint128>(normalized) * static_cast<std::uint64_t>(r.truncated >> 64);
  // The product's three words: top (bits 128..191), middle, bottom.
  const std::uint64_t bottom = static_cast<std::uint64_t>(low_product);
  const std::uint64_t middle = static_cast<std::uint64_t>(high_product) + static_cast<std::uint64_t>(low_product >> 64);
  const std::uint64_t top =
      static_cast<std::uint64_t>(high_product >> 64) + (middle < static_cast<std::uint64_t>(high_product) ? 1 : 0);
  // The product is ≥ 2¹⁹⁰: its top bit is bit 191 or 190 and the double takes the 53 from there.
  const int dropped_top_bits = static_cast<int>(top >> 63) + 10;  // bits of `top` below the 53
  const std::uint64_t half = std::uint64_t{1} << (dropped_top_bits - 1);
  const std::uint64_t rest = top & ((half << 1) - 1);
  // The exact product is this one plus less than 2⁶⁴: near a carry into the 53 bits or near
  // halfway (the middle word all ones), or exactly halfway, it could round either way.
  if (middle == ~std::uint64_t{0} || (rest == half && middle == 0 && bottom == 0)) return false;
  std::uint64_t significand = (top >> dropped_top_bits) + ((rest & half) != 0 ? 1 : 0);
  int exponent =
      128 + dropped_top_bits - leading_zeros - 127 - r.bits_of_power - k;  // value = significand · 2^exponent
  if (significand == std::uint64_t{1} << 53) {
    significand >>= 1;
    ++exponent;
  }
  const std::uint64_t bits =
      (static_cast<std::uint64_t>(exponent + 1075) << 52) | (significand & ((std::uint64_t{1} << 52) - 1));
  value = std::bit_cast<double>(bits);
  return true;
}
#endif

inline bool isDigit(char c) { return static_cast<unsigned char>(c - '0') < 10; }

// The plain decimal at [first, last) correctly rounded into `value`, and the end of what it
// read; nullptr (value untouched) when the text is not one this can round on its own.
inline const char* plainDecimal(const char* first, const char* last, double& value) {
  const char* p = first;
  const bool negative = p != last && *p == '-';
  p += negative ? 1 : 0;  // no branch: signs alternate at random in a recording
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
        const std::uint64_t non_digits = nonDigitBytes(word);
        if (non_digits == 0) {
          w = w * 100000000 + eightDigitsValue(word);
          p += 8;
          continue;
        }
        // The digits before the first non-digit byte, without a branch per digit: moved to
        // the top of the word behind '0's.
        const int digits = std::countr_zero(non_digits) / 8;
        if (digits > 0) {
          const int shift = 64 - 8 * digits;
          w = w * kPowersOfTenInteger[digits] +
              eightDigitsValue((word << shift) | (0x3030303030303030ULL >> (8 * digits)));
          p += digits;
        }
        break;
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
  } else if (fraction_digits == 0) {
    magnitude = static_cast<double>(w);  // the conversion rounds correctly
  } else {
#if defined(__SIZEOF_INT128__)
    if (fraction_digits > kLongestFraction) return nullptr;
    if (w != 0 && !roundedQuotientOfTenPower(w, fraction_digits, magnitude)) return nullptr;
#else
    return nullptr;
#endif
  }
  value = std::bit_cast<double>(std::bit_cast<std::uint64_t>(magnitude) | (std::uint64_t{negative} << 63));
  return p;
}

}  // namespace decimal_detail

// std::from_chars(first, last, value) with chars_format::general, faster on plain decimals.
inline std::from_chars_result decimalFromChars(const char* first, const char* last, double& value) {
  if (const char* end = decimal_detail::plainDecimal(first, last, value)) return {end, std::errc()};
  return std::from_chars(first, last, value);
}

}  // namespace gyrod::recording
