#pragma once
// Elementary functions whose results are the same bits on every IEEE-754 machine the
// project builds on (x86_64, aarch64). libm's log/exp/tan are only "within an ulp or
// so" and their last bit differs between implementations and architectures; the noise
// simulator must give the same stream from the same seed everywhere, so the functions
// it needs are written here from + − × ÷ sqrt, frexp and ldexp (all exact or correctly
// rounded by IEEE 754). This file is compiled with -ffp-contract=off (no FMA fusion),
// see processing/CMakeLists.txt. Accuracy (tests/processing/test_portable_random.cpp):
// log, exp, expm1 within 2 ulp of glibc, tan within 4 ulp.
namespace gyrod::processing::portable {

// Natural logarithm for finite x > 0. Throws std::invalid_argument otherwise.
// Method: x = m·2^e with m in [√½, √2); ln m = 2·atanh(u), u = (m−1)/(m+1), by its
// odd power series (|u| ≤ 0.172); ln 2 split into an exact high part and a low part.
double log(double x);

// e^x for finite x (0 below −745.2, +inf above 709.8). Throws for NaN.
// Method: x = k·ln 2 + r with |r| ≤ ln2/2, Taylor series of e^r, then ·2^k (ldexp).
double exp(double x);

// e^x − 1 without the cancellation of exp(x) − 1 near 0 (needed for 1 − e^{−2τ0/T}
// with T ≫ τ0). Taylor series for |x| ≤ 0.7, exp(x) − 1 beyond.
double expm1(double x);

// tan x for |x| ≤ 1.2 (the DLPF design needs x = π·f/fs ≤ 0.6). Throws outside.
// Method: Taylor series of sin and cos, then their quotient.
double tan(double x);

}  // namespace gyrod::processing::portable
