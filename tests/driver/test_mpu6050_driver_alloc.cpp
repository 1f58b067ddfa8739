// The streaming path allocates nothing per sample: a counting global operator new (for this
// test binary) sees no allocation during ten seconds of steady streaming.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "driver/mock/mock_mpu6050.hpp"
#include "driver/mock/mock_signal_source.hpp"
#include "driver/mpu6050_driver.hpp"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<std::uint64_t> g_allocations{0};
}  // namespace

// Not under AddressSanitizer: replacing new/delete for the whole test binary would switch
// off ASan's own new/delete checks for every other driver test.
#if !defined(__SANITIZE_ADDRESS__)
#define GYROD_COUNT_ALLOCATIONS 1
// Replacement allocation functions over malloc/free. GCC 12 flags free() inside a
// replacement operator delete as a new/free mismatch; here both sides are ours.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return ::operator new(n); }
// The nothrow forms too (std::stable_sort uses them), so every form pairs with our delete.
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n == 0 ? 1 : n);
}
void* operator new[](std::size_t n, const std::nothrow_t& t) noexcept { return ::operator new(n, t); }
void operator delete(void* p, const std::nothrow_t&) noexcept { ::operator delete(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { ::operator delete(p); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { ::operator delete(p); }
void operator delete(void* p, std::size_t) noexcept { ::operator delete(p); }
void operator delete[](void* p, std::size_t) noexcept { ::operator delete(p); }
#pragma GCC diagnostic pop
#endif

namespace gyrod::driver {
namespace {

class CountingSink final : public SampleSink {
 public:
  void onSample(const GyroSample&) override { ++samples; }
  void onGap(const SampleGap&) override { ++gaps; }
  std::uint64_t samples = 0;
  std::uint64_t gaps = 0;
};

TEST(Mpu6050DriverAllocation, SteadyStreamingAllocatesNothing) {
#if !defined(GYROD_COUNT_ALLOCATIONS)
  GTEST_SKIP() << "allocation counting is off under AddressSanitizer";
#endif
  // The counter counts (so a zero below means something).
  g_counting = true;
  int* volatile probe = new int(1);  // volatile: the allocation cannot be elided
  g_counting = false;
  delete probe;
  ASSERT_EQ(g_allocations.exchange(0), 1u);

  VirtualClock clock(kNsPerSecond);
  ConstantSource source({1.0, 2.0, 3.0}, 25.0);
  MockMpu6050Config mc;
  mc.accel_noise_g = 0.0;
  MockMpu6050 mock(clock, source, mc);
  CountingSink sink;
  Mpu6050Driver driver(mock, mock.dataReady(), clock, sink, Mpu6050Config{});
  driver.start();
  const auto run = [&](std::int64_t until) {
    while (clock.nowNs() < until) {
      std::int64_t t = until;
      if (auto s = mock.nextSampleTimeNs()) t = std::min(t, *s);
      if (auto d = driver.nextDeadlineNs()) t = std::min(t, std::max(*d, clock.nowNs()));
      clock.setNs(t);
      mock.sync();
      driver.onDataReady();
      if (auto d = driver.nextDeadlineNs(); d && *d <= t) driver.onTimer(t);
    }
  };
  run(3 * kNsPerSecond);  // probe, configure, first samples (these allocate: messages)
  ASSERT_EQ(driver.status().state, DeviceState::Streaming);
  const std::uint64_t before = sink.samples;
  g_counting = true;
  run(13 * kNsPerSecond);
  g_counting = false;
  EXPECT_NEAR(static_cast<double>(sink.samples - before), 500.0, 1.0);  // 10 s at 50 Hz
  EXPECT_EQ(sink.gaps, 0u);
  EXPECT_EQ(g_allocations.load(), 0u);
}

}  // namespace
}  // namespace gyrod::driver
