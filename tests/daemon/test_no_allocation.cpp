// The per-sample path allocates nothing: publishRate (formatting once, copying into each
// watcher's buffer, writing, switching EPOLLOUT on and off) and the loop's dispatch of the
// resulting write events. Counted with a replacement of the global operator new for this
// test program (it counts every call and otherwise behaves as the default one).
#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <new>

#include "daemon/sample_pipeline.hpp"
#include "server_fixture.hpp"

namespace {
std::atomic<std::size_t> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size == 0 ? 1 : size);
}
void* operator new[](std::size_t size, const std::nothrow_t& t) noexcept { return operator new(size, t); }
[[gnu::noinline]] void operator delete(void* p) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete[](void* p) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

using namespace gyrod;
using namespace gyrod::test;

namespace {

class CountAllocations {
 public:
  CountAllocations() : start_(g_allocations.load()) {}
  std::size_t count() const { return g_allocations.load() - start_; }

 private:
  std::size_t start_;
};

}  // namespace

TEST(NoAllocationCounter, SeesAnAllocation) {
  // The counter itself must be live, or the test below proves nothing.
  CountAllocations c;
  auto* p = new std::string(100, 'x');
  delete p;
  EXPECT_GE(c.count(), 1u);
}

TEST_F(ServerFixture, PublishingAllocatesNothing) {
  daemon::ServerOptions options;
  options.client_buffer_bytes = 1024 * 1024;  // big enough that the slow reader is never dropped
  startServer(options);
  auto fast = watcher();
  auto decimated = watcher(3);
  auto slow = watcher();  // read only now and then: its buffer fills, EPOLLOUT goes on and off
  auto idle = connect();  // connected, not watching
  std::size_t publish_allocations = 0;
  std::size_t dispatch_allocations = 0;
  const std::uint64_t n = 3000;
  std::size_t fast_lines = 0, decimated_lines = 0, slow_lines = 0;
  std::size_t max_slow_buffered = 0;
  for (std::uint64_t k = 0; k < n; ++k) {
    const protocol::RateSample s = syntheticSample(k);  // built outside the counted window
    {
      CountAllocations c;
      server_->publishRate(s);
      publish_allocations += c.count();
    }
    if (k % 50 == 0) {
      server_->publishGap({k, 1, "test_gap"});  // not counted: GAP is rare, but check it anyway below
    }
    {
      CountAllocations c;
      while (loop_.runOnce(0ms) > 0) {}
      dispatch_allocations += c.count();
    }
    fast->collect();
    decimated->collect();
    if (k % 1500 == 1499) {
      // Before the slow reader catches up: the kernel has refused some of its lines.
      max_slow_buffered = std::max(max_slow_buffered, server_->serverStatus().client_list[2].buffered_bytes);
      slow->collect();
    }
  }
  EXPECT_TRUE(pumpUntil(loop_, [&] {
    slow->collect();
    fast->collect();
    decimated->collect();
    return slow->received() >= n + n / 50;
  }));
  fast_lines = fast->received();
  decimated_lines = decimated->received();
  slow_lines = slow->received();
  EXPECT_EQ(publish_allocations, 0u);
  EXPECT_EQ(dispatch_allocations, 0u);
  // And the lines did flow: every RATE (and GAP) line to each watcher.
  EXPECT_EQ(fast_lines, n + n / 50);
  EXPECT_EQ(decimated_lines, n / 3 + n / 50);
  EXPECT_EQ(slow_lines, n + n / 50);
  EXPECT_EQ(server_->serverStatus().clients_dropped, 0u);
  EXPECT_GT(max_slow_buffered, 0u) << "the partial-write / EPOLLOUT path was not exercised";

  CountAllocations gap;
  server_->publishGap({n, 2, "fifo_overflow"});
  EXPECT_EQ(gap.count(), 0u);
}

// The pipeline's per-sample step, the rate stream's RateEstimator included (a sensor model
// with a temperature term, so the residual filter and the still detector both run), and with
// the accel the orientation on that stream (its motion errors learned while it turns).
TEST(NoAllocation, PipelineProcessAllocatesNothingWithARateModel) {
  daemon::PipelineSettings p;
  p.bias_origin = daemon::BiasOrigin::Config;
  p.kalman = {0.9, 0.001, 0.1};
  p.allan_window_samples = 4096;
  processing::RateEstimatorParameters model;
  for (auto& axis : model.axes) {
    axis.terms.arw_deg_per_sqrt_h = 0.9;
    axis.temperature_coefficient_dps_per_c = 0.02;
    axis.temperature_coefficient_std_dps_per_c = 0.002;
  }
  p.rate_model = model;
  daemon::SamplePipeline pipeline(p);
  std::size_t allocations = 0, still = 0, oriented = 0;
  for (std::uint64_t k = 0; k < 6000; ++k) {
    const double noise = 0.01 * static_cast<double>(static_cast<int>(k * 7919 % 13) - 6);
    const double turning = (k / 1000) % 2 == 1 ? 30.0 : 0.0;
    CountAllocations c;
    const daemon::ProcessedSample out =
        pipeline.process(k, static_cast<double>(k) / 50.0, {noise, -noise, turning + noise}, 25.0 + 1e-3 * k,
                         {0.1 * noise, -0.1 * noise, 1.0});
    allocations += c.count();
    still += out.still.value_or(false) ? 1 : 0;
    oriented += out.attitude ? 1 : 0;
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(oriented, 6000u);
  EXPECT_GT(still, 0u);
  EXPECT_LT(still, 6000u);
}
