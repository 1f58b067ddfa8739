#pragma once
// Motion specs: the true rotation a simulated or mocked gyro turns through, as the user
// writes it after `gyroctl simulate --motion` or in gyrod's `[mock] motion` key
// (grammar and examples: docs/simulator.md). A spec is either
//  - built-in profiles written as text, summed with '+':
//      step:axis=z,at=5,rate=10 + sine:axis=x,freq=1,amp=20
//  - or the path of a CSV file of true rates, header t,wx,wy,wz (s, °/s; any of the w
//    columns, the others 0), interpolated linearly between its rows.
// Text whose part before the first ':' is a lowercase word is read as profiles (so a typo
// in a profile's name is reported as such, not as a missing file); anything else is a path
// (write ./name for a file whose name starts with a word and a colon).
#include <array>
#include <string>
#include <string_view>

#include "processing/simulation/motion_profile.hpp"
#include "processing/simulation/noise_simulator.hpp"

namespace gyrod::recording {

// True when `spec` is read as profile text rather than as a file path.
bool isMotionProfileText(std::string_view spec);

// Parses profile text. Throws std::invalid_argument naming the profile, the key and its
// value ("motion: sine: freq must be finite and > 0, got 0").
processing::MotionProfile parseMotionProfileText(std::string_view text);

// Reads a CSV of true rates with the recording CSV's conventions ('#' comments, blank lines
// skipped, fields trimmed). Throws RecordingError "FILE:LINE: cause".
processing::MotionProfile readMotionCsv(const std::string& path);

// Either of the two above, chosen by isMotionProfileText().
processing::MotionProfile motionFromSpec(const std::string& spec);

// A warm-up as `gyroctl simulate --warm-up` and gyrod's `[mock] warm_up` write it: "DELTA_C,TAU_S"
// (the die temperature rises by DELTA_C °C with time constant TAU_S s, e.g. "15,300"). Throws
// std::invalid_argument naming the value ("warm-up: ...").
processing::WarmUp parseWarmUpSpec(std::string_view text);

// One value for all three axes, or three values x,y,z ("0.03" or "0.03,-0.02,0.015"): the
// temperature coupling in °/s per °C. Throws std::invalid_argument naming `what` and the value.
std::array<double, processing::kSimulatedAxes> parseAxisValues(std::string_view text, std::string_view what);

}  // namespace gyrod::recording
