// Reading a recording (readRecordingCsv: one pass, std::from_chars, no allocation per line)
// in MB/s of CSV, on a file written here from a seed: t,gx,gy,gz,temp with 17 significant
// digits, as `gyroctl simulate` writes, and the single-axis t,gx. The file lives in
// $TMPDIR (default /tmp) and is removed at the end.
#include <benchmark/benchmark.h>

#include <unistd.h>
#include <ctime>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "formats/recording_csv.hpp"

namespace {

constexpr std::size_t kLines = 2'000'000;

std::string writeRecording(bool three_axes) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("gyrod-bench-read-" + std::to_string(::getpid()) + (three_axes ? "-3" : "-1") + ".csv");
  std::ofstream out(path);
  std::mt19937_64 gen(20261123);
  std::normal_distribution<double> noise(0.0, 0.05);
  char line[256];
  out << (three_axes ? "t,gx,gy,gz,temp\n" : "t,gx\n");
  for (std::size_t i = 0; i < kLines; ++i) {
    const double t = 0.02 * static_cast<double>(i);
    if (three_axes)
      std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%.17g,25\n", t, noise(gen), noise(gen), noise(gen));
    else
      std::snprintf(line, sizeof line, "%.17g,%.17g\n", t, noise(gen));
    out << line;
  }
  return path.string();
}

void readBenchmark(benchmark::State& state, bool three_axes) {
  const std::string path = writeRecording(three_axes);
  const auto bytes = static_cast<std::int64_t>(std::filesystem::file_size(path));
  gyrod::recording::ReadOptions options;
  options.line_numbers = false;  // as gyroctl analyze reads
  // The reading runs on two threads: bytes_per_second is by wall time (UseRealTime), and
  // MB_per_cpu_s counts the CPU time of all the process's threads.
  timespec cpu_start{}, cpu_end{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cpu_start);
  for (auto _ : state) {
    const auto rec = gyrod::recording::readRecordingCsv(path, options);
    benchmark::DoNotOptimize(rec.axes.front().data());
  }
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cpu_end);
  const double cpu_s = static_cast<double>(cpu_end.tv_sec - cpu_start.tv_sec) +
                       1e-9 * static_cast<double>(cpu_end.tv_nsec - cpu_start.tv_nsec);
  state.counters["MB_per_cpu_s"] = static_cast<double>(state.iterations() * bytes) / 1e6 / cpu_s;
  state.SetBytesProcessed(state.iterations() * bytes);
  std::filesystem::remove(path);
}

void BM_ReadRecordingOneAxis(benchmark::State& state) { readBenchmark(state, false); }
void BM_ReadRecordingThreeAxesAndTemp(benchmark::State& state) { readBenchmark(state, true); }

}  // namespace

BENCHMARK(BM_ReadRecordingOneAxis)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReadRecordingThreeAxesAndTemp)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();
