#include "processing/base/portable_math.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace gyrod::processing::portable {
namespace {

// ln 2 = kLn2Hi + kLn2Lo; kLn2Hi has its low 32 bits zero so k·kLn2Hi is exact for
// |k| < 2^20 (the fdlibm split).
constexpr double kLn2Hi = 6.93147180369123816490e-01;  // 0x3FE62E42FEE00000
constexpr double kLn2Lo = 1.90821492927058770002e-10;  // 0x3DEA39EF35793C76
constexpr double kInvLn2 = 1.44269504088896338700e+00;
constexpr double kSqrtHalf = 0.70710678118654752440;

}  // namespace

double log(double x) {
  if (!(x > 0.0) || !std::isfinite(x))
    throw std::invalid_argument("the logarithm needs an argument that is finite and > 0, got " + std::to_string(x));
  int e = 0;
  double m = std::frexp(x, &e);  // x = m·2^e, m in [0.5, 1), exact
  if (m < kSqrtHalf) {
    m *= 2.0;  // exact
    e -= 1;
  }
  // m in [√½, √2): u = (m−1)/(m+1), |u| ≤ 0.1716, u² ≤ 0.02944. m−1 is exact (Sterbenz).
  const double u = (m - 1.0) / (m + 1.0);
  const double u2 = u * u;
  // ln m = 2·(u + u³/3 + u⁵/5 + …); terms to u²⁵ leave a relative error < 1e-19.
  double series = 2.0 / 25.0;
  series = 2.0 / 23.0 + u2 * series;
  series = 2.0 / 21.0 + u2 * series;
  series = 2.0 / 19.0 + u2 * series;
  series = 2.0 / 17.0 + u2 * series;
  series = 2.0 / 15.0 + u2 * series;
  series = 2.0 / 13.0 + u2 * series;
  series = 2.0 / 11.0 + u2 * series;
  series = 2.0 / 9.0 + u2 * series;
  series = 2.0 / 7.0 + u2 * series;
  series = 2.0 / 5.0 + u2 * series;
  series = 2.0 / 3.0 + u2 * series;
  const double ln_m = 2.0 * u + u * u2 * series;
  const double k = static_cast<double>(e);
  return k * kLn2Hi + (k * kLn2Lo + ln_m);
}

double exp(double x) {
  if (std::isnan(x)) throw std::invalid_argument("the exponential cannot take NaN");
  if (x > 709.78) return HUGE_VAL;
  if (x < -745.2) return 0.0;
  // k = nearest integer to x/ln2 (floor(y + 0.5) is exact rounding arithmetic).
  const double k = std::floor(x * kInvLn2 + 0.5);
  const double r = (x - k * kLn2Hi) - k * kLn2Lo;  // |r| ≲ 0.347
  // e^r by Taylor to r¹⁷/17! (remainder < 1e-22 relative).
  double p = 1.0 / 355687428096000.0;  // 1/17!
  p = 1.0 / 20922789888000.0 + r * p;  // 1/16!
  p = 1.0 / 1307674368000.0 + r * p;   // 1/15!
  p = 1.0 / 87178291200.0 + r * p;     // 1/14!
  p = 1.0 / 6227020800.0 + r * p;      // 1/13!
  p = 1.0 / 479001600.0 + r * p;       // 1/12!
  p = 1.0 / 39916800.0 + r * p;        // 1/11!
  p = 1.0 / 3628800.0 + r * p;         // 1/10!
  p = 1.0 / 362880.0 + r * p;          // 1/9!
  p = 1.0 / 40320.0 + r * p;           // 1/8!
  p = 1.0 / 5040.0 + r * p;            // 1/7!
  p = 1.0 / 720.0 + r * p;             // 1/6!
  p = 1.0 / 120.0 + r * p;             // 1/5!
  p = 1.0 / 24.0 + r * p;              // 1/4!
  p = 1.0 / 6.0 + r * p;               // 1/3!
  p = 0.5 + r * p;                     // 1/2!
  p = 1.0 + r * p;
  p = 1.0 + r * p;
  // ldexp is exact unless the result is subnormal, where it rounds as IEEE specifies.
  // Split the scaling so that 2^k itself never overflows for k = 1024.
  const int ki = static_cast<int>(k);
  return std::ldexp(std::ldexp(p, ki / 2), ki - ki / 2);
}

double expm1(double x) {
  if (std::isnan(x)) throw std::invalid_argument("the exponential cannot take NaN");
  // Beyond 0.7 the subtraction exp(x) − 1 costs at most about one bit.
  if (std::fabs(x) > 0.7) return exp(x) - 1.0;
  // x·(1 + x/2! + x²/3! + … + x¹⁸/19!), remainder < 1e-21 relative for |x| ≤ 0.7.
  double p = 1.0 / 121645100408832000.0;  // 1/19!
  p = 1.0 / 6402373705728000.0 + x * p;   // 1/18!
  p = 1.0 / 355687428096000.0 + x * p;    // 1/17!
  p = 1.0 / 20922789888000.0 + x * p;     // 1/16!
  p = 1.0 / 1307674368000.0 + x * p;      // 1/15!
  p = 1.0 / 87178291200.0 + x * p;        // 1/14!
  p = 1.0 / 6227020800.0 + x * p;         // 1/13!
  p = 1.0 / 479001600.0 + x * p;          // 1/12!
  p = 1.0 / 39916800.0 + x * p;           // 1/11!
  p = 1.0 / 3628800.0 + x * p;            // 1/10!
  p = 1.0 / 362880.0 + x * p;             // 1/9!
  p = 1.0 / 40320.0 + x * p;              // 1/8!
  p = 1.0 / 5040.0 + x * p;               // 1/7!
  p = 1.0 / 720.0 + x * p;                // 1/6!
  p = 1.0 / 120.0 + x * p;                // 1/5!
  p = 1.0 / 24.0 + x * p;                 // 1/4!
  p = 1.0 / 6.0 + x * p;                  // 1/3!
  p = 0.5 + x * p;                        // 1/2!
  p = 1.0 + x * p;
  return x * p;
}

double tan(double x) {
  if (!(std::fabs(x) <= 1.2))
    throw std::invalid_argument("the tangent is computed only for |x| <= 1.2, got " + std::to_string(x));
  const double x2 = x * x;
  // sin x = x·Σ (−x²)^n/(2n+1)!, cos x = Σ (−x²)^n/(2n)!, to n = 12 (remainder < 1e-22
  // relative at |x| = 1.2).
  // Horner in y = −x² with reciprocal-factorial literals (folded by the compiler with
  // correct rounding, hence identical on every target).
  const double y = -x2;
  double s = 1.0 / 25852016738884976640000.0;  // 1/23!
  s = 1.0 / 51090942171709440000.0 + y * s;    // 1/21!
  s = 1.0 / 121645100408832000.0 + y * s;      // 1/19!
  s = 1.0 / 355687428096000.0 + y * s;         // 1/17!
  s = 1.0 / 1307674368000.0 + y * s;           // 1/15!
  s = 1.0 / 6227020800.0 + y * s;              // 1/13!
  s = 1.0 / 39916800.0 + y * s;                // 1/11!
  s = 1.0 / 362880.0 + y * s;                  // 1/9!
  s = 1.0 / 5040.0 + y * s;                    // 1/7!
  s = 1.0 / 120.0 + y * s;                     // 1/5!
  s = 1.0 / 6.0 + y * s;                       // 1/3!
  s = 1.0 + y * s;
  double c = 1.0 / 620448401733239439360000.0;  // 1/24!
  c = 1.0 / 1124000727777607680000.0 + y * c;   // 1/22!
  c = 1.0 / 2432902008176640000.0 + y * c;      // 1/20!
  c = 1.0 / 6402373705728000.0 + y * c;         // 1/18!
  c = 1.0 / 20922789888000.0 + y * c;           // 1/16!
  c = 1.0 / 87178291200.0 + y * c;              // 1/14!
  c = 1.0 / 479001600.0 + y * c;                // 1/12!
  c = 1.0 / 3628800.0 + y * c;                  // 1/10!
  c = 1.0 / 40320.0 + y * c;                    // 1/8!
  c = 1.0 / 720.0 + y * c;                      // 1/6!
  c = 1.0 / 24.0 + y * c;                       // 1/4!
  c = 0.5 + y * c;                              // 1/2!
  c = 1.0 + y * c;
  return (x * s) / c;
}

}  // namespace gyrod::processing::portable
