#pragma once
// Golden-section search for the minimum of a unimodal function on [a, b].
#include <cmath>

namespace gyrod::processing {

struct GoldenSectionStop {
  int max_iterations = 0;
  double min_width = 0.0;  // stop once b − a is no more than this; 0: iterations only
};

// The bracket [a, b] left once the search stops, narrowed around the minimum of f. Each step
// keeps the side of the lower of the two inner points (ties keep [x1, b]); f is called once
// per step after the first two.
struct GoldenSectionBracket {
  double a = 0.0, b = 0.0;
  double midpoint() const { return 0.5 * (a + b); }
};

template <class F>
GoldenSectionBracket goldenSectionMinimum(double a, double b, const GoldenSectionStop& stop, F&& f) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  double f1 = f(x1);
  double f2 = f(x2);
  for (int it = 0; it < stop.max_iterations && (stop.min_width <= 0.0 || (b - a) > stop.min_width); ++it) {
    if (f1 < f2) {
      b = x2;
      x2 = x1;
      f2 = f1;
      x1 = b - g * (b - a);
      f1 = f(x1);
    } else {
      a = x1;
      x1 = x2;
      f1 = f2;
      x2 = a + g * (b - a);
      f2 = f(x2);
    }
  }
  return {a, b};
}

}  // namespace gyrod::processing
