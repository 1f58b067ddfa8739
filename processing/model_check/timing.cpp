// The model check's sample-timing detector: gaps in the t column.
#include "processing/model_check/pipeline.hpp"

namespace gyrod::processing::model_check_detail {

void checkSampleTiming(std::span<const double> time_s, AxisModelCheck& out) {
  const SampleTiming timing = analyzeSampleTiming(time_s);
  out.statistics.push_back({"sample_gaps", static_cast<double>(timing.gaps), 0.0, 0.5, timing.gaps > 0});
  if (timing.gaps == 0) return;
  DetectedEffect e;
  e.effect = ModelEffect::SampleGaps;
  e.count = timing.gaps;
  e.lost = timing.lost;
  e.evidence.median_spacing_s = timing.median_spacing_s;
  e.evidence.jitter = timing.jitter;
  out.effects.push_back(e);
}

}  // namespace gyrod::processing::model_check_detail
