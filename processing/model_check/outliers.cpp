// The model check's outlier detector: samples far from their neighbours.
#include <algorithm>
#include <cmath>

#include "processing/model_check/pipeline.hpp"

namespace gyrod::processing::model_check_detail {

OutliersFound checkOutliers(std::span<const double> xd, std::vector<double>& xc, const NullSummary& null,
                            std::size_t replicas, AxisModelCheck& out) {
  OutliersFound found;
  const std::vector<double> z = localOutlierScores(xc, kOutlierHalfWindow);
  double zmax = 0.0;
  for (double v : z) zmax = std::max(zmax, std::fabs(v));
  out.statistics.push_back(makeStatistic("outliers_max_robust_z", zmax, null));
  if (!null.fires(zmax)) return found;
  std::vector<std::size_t> at;
  for (std::size_t i = 0; i < z.size(); ++i)
    if (std::fabs(z[i]) > null.threshold) at.push_back(i);
  // Replace each by the mean of its neighbours that are not outliers themselves.
  std::vector<double> amplitudes;
  for (std::size_t i : at) {
    const std::size_t lo = i >= kOutlierHalfWindow ? i - kOutlierHalfWindow : 0;
    const std::size_t hi = std::min(xc.size(), i + kOutlierHalfWindow + 1);
    double s = 0.0;
    std::size_t k = 0;
    for (std::size_t j = lo; j < hi; ++j)
      if (!std::binary_search(at.begin(), at.end(), j)) {
        s += xd[j];
        ++k;
      }
    const double local = k > 0 ? s / static_cast<double>(k) : 0.0;
    amplitudes.push_back(std::fabs(xd[i] - local));
    xc[i] = local;
  }
  found.found = true;
  found.count = at.size();
  found.samples = at;
  found.median_amplitude = medianOf(amplitudes);
  DetectedEffect e;
  e.effect = ModelEffect::Outliers;
  e.count = found.count;
  e.outlier_median_amplitude_dps = found.median_amplitude;
  e.evidence = nullEvidence(zmax, null, replicas);
  out.effects.push_back(e);
  return found;
}

}  // namespace gyrod::processing::model_check_detail
