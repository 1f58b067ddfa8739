#include "processing/base/distributions.hpp"

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <stdexcept>

namespace gyrod::processing {

double normalQuantile(double p) {
  if (!(p > 0.0 && p < 1.0))
    throw std::invalid_argument("the normal quantile needs a probability in (0, 1), got " + std::to_string(p));
  return boost::math::quantile(boost::math::normal_distribution<double>(), p);
}

double normalCdf(double z) { return boost::math::cdf(boost::math::normal_distribution<double>(), z); }

double chiSquareQuantile(double p, double dof) {
  if (!(p > 0.0 && p < 1.0))
    throw std::invalid_argument("the chi-square quantile needs a probability in (0, 1), got " + std::to_string(p));
  if (!(dof > 0.0))
    throw std::invalid_argument("the chi-square quantile needs degrees of freedom > 0, got " + std::to_string(dof));
  return boost::math::quantile(boost::math::chi_squared_distribution<double>(dof), p);
}

double chiSquareCdf(double x, double dof) {
  if (!(dof > 0.0))
    throw std::invalid_argument("the chi-square probability needs degrees of freedom > 0, got " + std::to_string(dof));
  if (x <= 0.0) return 0.0;
  return boost::math::cdf(boost::math::chi_squared_distribution<double>(dof), x);
}

double studentTUpperTail(double t, double dof) {
  if (!(dof > 0.0))
    throw std::invalid_argument("the t probability needs degrees of freedom > 0, got " + std::to_string(dof));
  return boost::math::cdf(boost::math::complement(boost::math::students_t_distribution<double>(dof), t));
}

}  // namespace gyrod::processing
