// The noise refit off the event loop gives exactly what SamplePipeline::refitNoiseTerms
// gives on the loop, for the state at the moment the cycle started.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <future>
#include <memory>
#include <mutex>
#include <random>
#include <stdexcept>

#include "daemon/noise_refit_worker.hpp"

using namespace gyrod::daemon;
using namespace std::chrono_literals;

namespace {

PipelineSettings settings() {
  PipelineSettings p;
  p.rate_hz = 50.0;
  p.bias_origin = BiasOrigin::Config;
  p.bias_dps = {1.5, -0.25, 0.125};
  p.kalman = {-0.2855, 0.0577, 0.0667};
  p.allan_window_samples = 4096;
  return p;
}

void feed(SamplePipeline& p, std::uint64_t first, std::uint64_t count, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.05);
  double walk = 0.0;
  for (std::uint64_t k = first; k < first + count; ++k) {
    walk += 0.002 * noise(rng);
    p.process(k, static_cast<double>(k) / 50.0, {1.5 + walk + noise(rng), -0.25 + noise(rng), 0.125 - walk}, 25.0);
  }
}

void expectSameNoiseTerms(const gyrod::processing::NoiseTermFit& got, const gyrod::processing::NoiseTermFit& expected) {
  for (const auto term : gyrod::processing::kAllNoiseTerms) {
    EXPECT_EQ(got.value.get(term), expected.value.get(term));
    EXPECT_EQ(got.uncertainty.get(term), expected.uncertainty.get(term));
  }
}

}  // namespace

TEST(NoiseRefitWorker, GivesExactlyTheNoiseTermsOfTheRefitOnTheLoop) {
  SamplePipeline on_loop(settings()), off_loop(settings());
  feed(on_loop, 0, 3000, 1);
  feed(off_loop, 0, 3000, 1);
  on_loop.refitNoiseTerms();

  EventLoop loop;
  int cycles = 0;
  NoiseRefitWorker worker(loop, off_loop, 50.0, [&] { ++cycles; });
  EXPECT_FALSE(off_loop.noiseTerms()[0].has_value());
  ASSERT_TRUE(worker.startCycle());
  EXPECT_TRUE(worker.busy());
  EXPECT_FALSE(worker.startCycle());  // one cycle at a time
  feed(off_loop, 3000, 500, 2);       // samples keep coming during the cycle; axis 0 was copied before them
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (cycles == 0 && std::chrono::steady_clock::now() < deadline) loop.runOnce(10ms);
  ASSERT_EQ(cycles, 1);
  EXPECT_FALSE(worker.busy());

  const auto& expected = on_loop.noiseTerms()[0];
  const auto& got = off_loop.noiseTerms()[0];
  ASSERT_TRUE(expected.has_value());
  ASSERT_TRUE(got.has_value());
  expectSameNoiseTerms(*got, *expected);
  EXPECT_EQ(got->points_used, expected->points_used);
  for (std::size_t axis = 1; axis < kAxes; ++axis) EXPECT_TRUE(off_loop.noiseTerms()[axis].has_value()) << axis;
}

TEST(NoiseRefitWorker, TooEarlyKeepsNothingAndStillCompletesTheCycle) {
  SamplePipeline p(settings());
  feed(p, 0, 3, 1);
  EventLoop loop;
  int cycles = 0;
  NoiseRefitWorker worker(loop, p, 50.0, [&] { ++cycles; });
  ASSERT_TRUE(worker.startCycle());
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (cycles == 0 && std::chrono::steady_clock::now() < deadline) loop.runOnce(10ms);
  EXPECT_EQ(cycles, 1);
  for (std::size_t axis = 0; axis < kAxes; ++axis) EXPECT_FALSE(p.noiseTerms()[axis].has_value());
  EXPECT_TRUE(worker.startCycle());  // and the next cycle can start
}

// gyrod's exit on SIGTERM destroys the worker; a refit of one axis takes seconds at a 1 h window
// at 1 kHz (more on a Pi), and the destructor used to join the thread, so the exit waited for
// it. Here the refit is held until the destructor has returned: a destructor that waits for it
// never returns on its own (the wait below would run out), one that abandons it returns at once.
TEST(NoiseRefitWorker, StoppingAbandonsARefitInProgressAndDropsItsResult) {
  SamplePipeline p(settings());
  feed(p, 0, 3000, 1);
  EventLoop loop;
  std::mutex m;
  std::condition_variable changed;
  bool entered = false, released = false, finished = false;
  int cycles = 0;
  auto held_refit = [&](const gyrod::processing::RollingOverlappingAllan& stream, double tau0_s, bool fit_terms) {
    {
      std::unique_lock lock(m);
      entered = true;
      changed.notify_all();
      changed.wait(lock, [&] { return released; });
    }
    const NoiseRefit result = refitNoiseTerms(stream, tau0_s, fit_terms);
    const std::lock_guard lock(m);
    finished = true;
    changed.notify_all();  // under the lock: after it, nothing here touches this test's variables
    return result;
  };
  auto worker = std::make_unique<NoiseRefitWorker>(
      loop, p, 50.0, [&] { ++cycles; }, held_refit);
  ASSERT_TRUE(worker->startCycle());
  {
    std::unique_lock lock(m);
    ASSERT_TRUE(changed.wait_for(lock, 60s, [&] { return entered; }));
  }
  auto destroyed = std::async(std::launch::async, [&] { worker.reset(); });
  const bool returned_while_refitting = destroyed.wait_for(60s) == std::future_status::ready;
  {
    const std::lock_guard lock(m);
    released = true;
    changed.notify_all();
  }
  destroyed.wait();
  EXPECT_TRUE(returned_while_refitting) << "the destructor waited for the refit in progress";
  {
    std::unique_lock lock(m);
    ASSERT_TRUE(changed.wait_for(lock, 60s, [&] { return finished; }));
  }
  loop.runOnce(0ms);  // the result of the abandoned refit never reaches the pipeline
  EXPECT_EQ(cycles, 0);
  for (std::size_t axis = 0; axis < kAxes; ++axis) EXPECT_FALSE(p.noiseTerms()[axis].has_value()) << axis;
}

TEST(NoiseRefitWorker, AnIdleWorkerStopsAndAnEmptyRefitFunctionIsRefused) {
  SamplePipeline p(settings());
  EventLoop loop;
  { NoiseRefitWorker idle(loop, p, 50.0, {}); }
  EXPECT_THROW(NoiseRefitWorker(loop, p, 50.0, {}, NoiseRefitWorker::RefitFunction{}), std::invalid_argument);
}

// A window larger than one turn's copy: the copy runs over several loop turns while samples keep
// coming between them, and the refit is still exactly that of the state when the cycle began.
TEST(NoiseRefitWorker, ACopyOverSeveralTurnsIsTheStateWhenTheCycleBegan) {
  PipelineSettings big = settings();
  big.allan_window_samples = 3 * NoiseRefitWorker::kCopyPointsPerTurn + 1000;
  SamplePipeline on_loop(big), off_loop(big);
  const std::uint64_t filled = big.allan_window_samples + 5000;
  feed(on_loop, 0, filled, 3);
  feed(off_loop, 0, filled, 3);
  on_loop.refitNoiseTerms();

  EventLoop loop;
  int cycles = 0, turns = 0;
  NoiseRefitWorker worker(loop, off_loop, 50.0, [&] { ++cycles; });
  ASSERT_TRUE(worker.startCycle());
  std::uint64_t next = filled;
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (cycles == 0 && std::chrono::steady_clock::now() < deadline) {
    feed(off_loop, next, 20, static_cast<unsigned>(next));  // samples between the turns
    next += 20;
    loop.runOnce(10ms);
    ++turns;
  }
  ASSERT_EQ(cycles, 1);
  EXPECT_GE(turns, 4);
  const auto& expected = on_loop.noiseTerms()[0];
  const auto& got = off_loop.noiseTerms()[0];
  ASSERT_TRUE(expected.has_value());
  ASSERT_TRUE(got.has_value());
  expectSameNoiseTerms(*got, *expected);
}
