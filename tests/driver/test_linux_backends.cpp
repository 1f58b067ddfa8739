// What can be tested of the Linux backends without hardware: the messages for each way
// opening fails (real open()/ioctl() calls on paths that fail in the wanted way), the
// I2C_RDWR message construction, the busy address through the driver, the GPIO request
// failures, and the polling timer.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/i2c.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <string>

#include "binary_command.hpp"
#include "driver/clock.hpp"
#include "driver/gpio_data_ready.hpp"
#include "driver/i2c_messages.hpp"
#include "driver/linux_i2c_bus.hpp"
#include "driver/mock/mock_mpu6050.hpp"
#include "driver/mock/mock_signal_source.hpp"
#include "driver/mpu6050_driver.hpp"
#include "driver/polling_data_ready.hpp"

namespace gyrod::driver {
namespace {

bool contains(const std::string& s, const std::string& needle) { return s.find(needle) != std::string::npos; }

template <typename Error, typename F>
Error catchError(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e;
  }
  ADD_FAILURE() << "no exception";
  return Error("", 0);
}

TEST(LinuxI2cBus, MissingDeviceSaysHowToEnableI2c) {
  const I2cBusError e = catchError<I2cBusError>([] { LinuxI2cBus bus(99); });
  EXPECT_EQ(e.error(), ENOENT);
  const std::string m = e.what();
  EXPECT_TRUE(contains(m, "/dev/i2c-99")) << m;
  EXPECT_TRUE(contains(m, "raspi-config")) << m;
  EXPECT_TRUE(contains(m, "dtparam=i2c_arm=on")) << m;
}

TEST(LinuxI2cBus, ANonAdapterIsRefusedBecauseI2cFuncsFails) {
  // /dev/null and a regular file open fine, but the I2C_FUNCS ioctl fails with ENOTTY.
  char path[] = "/tmp/gyrod-not-i2c-XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  ::close(fd);
  // qemu-user does not pass I2C_FUNCS to the kernel: it answers ENOSYS itself, where the
  // kernel answers ENOTTY. That the file is refused, and named, is still checked there.
  const bool emulated = gyrod::test::underEmulator();
  for (const std::string& p : {std::string("/dev/null"), std::string(path)}) {
    const I2cBusError e = catchError<I2cBusError>([&] { LinuxI2cBus bus(p); });
    EXPECT_EQ(e.error(), emulated ? ENOSYS : ENOTTY) << p;
    EXPECT_TRUE(contains(e.what(), emulated ? "cannot query the functions of" : "is not an I2C adapter")) << e.what();
    EXPECT_TRUE(contains(e.what(), p)) << e.what();
  }
  ::unlink(path);
  if (gyrod::test::underEmulator()) {
    GTEST_SKIP() << "emulator gap: qemu-user answers I2C_FUNCS with ENOSYS, not the kernel's ENOTTY; "
                    "the ENOTTY case is checked only on a native run";
  }
}

TEST(LinuxI2cBus, PermissionDeniedNamesTheI2cGroup) {
  const std::string m = describeOpenError(EACCES, "/dev/i2c-1");
  EXPECT_TRUE(contains(m, "permission denied opening /dev/i2c-1")) << m;
  EXPECT_TRUE(contains(m, "usermod -aG i2c")) << m;
  EXPECT_TRUE(contains(m, "udev")) << m;
  if (geteuid() == 0) GTEST_SKIP() << "root opens any file; the real EACCES path needs an unprivileged user";
  char path[] = "/tmp/gyrod-no-access-XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  ::close(fd);
  ::chmod(path, 0);
  const I2cBusError e = catchError<I2cBusError>([&] { LinuxI2cBus bus{std::string(path)}; });
  EXPECT_EQ(e.error(), EACCES);
  EXPECT_TRUE(contains(e.what(), "'i2c' group")) << e.what();
  ::unlink(path);
}

TEST(LinuxI2cBus, TransferAndSelectErrorsReadAsActions) {
  EXPECT_TRUE(contains(describeTransferError(-EREMOTEIO), "i2cdetect"));
  EXPECT_TRUE(contains(describeTransferError(-EREMOTEIO), "AD0"));
  EXPECT_TRUE(contains(describeTransferError(-ENXIO), "no acknowledge"));
  EXPECT_TRUE(contains(describeTransferError(-ETIMEDOUT), "power-cycle"));
  EXPECT_TRUE(contains(describeTransferError(-kShortReadErrno), "short read"));
  EXPECT_TRUE(contains(describeTransferError(-EIO), "pull-ups"));
  const std::string busy = describeSelectError(-EBUSY, 0x68);
  EXPECT_TRUE(contains(busy, "0x68")) << busy;
  EXPECT_TRUE(contains(busy, "kernel driver")) << busy;
  EXPECT_TRUE(contains(busy, "inv-mpu6050")) << busy;
  EXPECT_TRUE(contains(busy, "UU")) << busy;
  EXPECT_TRUE(isTransientTransferError(-EREMOTEIO));
  EXPECT_TRUE(isTransientTransferError(-EIO));
  EXPECT_FALSE(isTransientTransferError(-ENODEV));
  EXPECT_FALSE(isTransientTransferError(-EINVAL));
}

TEST(LinuxI2cBus, RegisterReadIsOneWriteThenOneReadAfterARepeatedStart) {
  std::uint8_t reg = 0x74;
  std::array<std::uint8_t, 1024> out{};
  const auto m = registerReadMessages(0x68, &reg, std::span(out.data(), 960));
  EXPECT_EQ(m[0].addr, 0x68);
  EXPECT_EQ(m[0].flags, 0);  // write
  EXPECT_EQ(m[0].len, 1);
  EXPECT_EQ(m[0].buf, &reg);
  EXPECT_EQ(m[1].addr, 0x68);
  EXPECT_EQ(m[1].flags, I2C_M_RD);
  EXPECT_EQ(m[1].len, 960);
  EXPECT_EQ(m[1].buf, out.data());
  EXPECT_THROW(registerReadMessages(0x80, &reg, std::span(out.data(), 1)), std::invalid_argument);
  EXPECT_THROW(registerReadMessages(0x68, &reg, std::span(out.data(), 0)), std::invalid_argument);
}

// The mock with I2C_SLAVE answering EBUSY, as when inv-mpu6050 is bound to the address.
class BusyAddressBus final : public I2cBus {
 public:
  int selectDevice(std::uint8_t) override { return -EBUSY; }
  std::uint8_t selectedDevice() const override { return 0; }
  int readByte(std::uint8_t, std::uint8_t&) override { return -EREMOTEIO; }
  int writeByte(std::uint8_t, std::uint8_t) override { return -EREMOTEIO; }
  int readWordBigEndian(std::uint8_t, std::uint16_t&) override { return -EREMOTEIO; }
  int readBlock(std::uint8_t, std::span<std::uint8_t>) override { return -EREMOTEIO; }
  std::size_t maxBurstLength() const override { return 32; }
};

class NullSink final : public SampleSink {
 public:
  void onSample(const GyroSample&) override { ++samples; }
  void onGap(const SampleGap&) override {}
  int samples = 0;
};

TEST(LinuxI2cBus, DriverReportsAnAddressOwnedByAKernelDriver) {
  VirtualClock clock(kNsPerSecond);
  PollingDataReady ready(clock, 100 * kNsPerMillisecond);
  BusyAddressBus bus;
  NullSink sink;
  Mpu6050Config c;
  c.bus_name = "/dev/i2c-1";
  Mpu6050Driver driver(bus, ready, clock, sink, c);
  driver.start();
  for (int i = 0; i < 20; ++i) {
    if (auto d = driver.nextDeadlineNs()) clock.setNs(std::max(*d, clock.nowNs()));
    driver.onTimer(clock.nowNs());
  }
  const DeviceStatus& s = driver.status();
  EXPECT_EQ(s.state, DeviceState::Failed);
  EXPECT_TRUE(contains(s.reason, "kernel driver")) << s.reason;
  EXPECT_TRUE(contains(s.reason, "/dev/i2c-1")) << s.reason;
  EXPECT_EQ(sink.samples, 0);
}

TEST(GpioDataReady, MissingChipSaysHowToFindIt) {
  GpioLineConfig cfg;
  cfg.chip = "gpiochip99";
  const GpioError e = catchError<GpioError>([&] { GpioDataReady line(cfg); });
  EXPECT_EQ(e.error(), ENOENT);
  EXPECT_TRUE(contains(e.what(), "gpiochip99")) << e.what();
  EXPECT_TRUE(contains(e.what(), "gpiodetect")) << e.what();
}

TEST(GpioDataReady, ANonGpioDeviceIsRefused) {
  GpioLineConfig cfg;
  cfg.chip = "/dev/null";
  const GpioError e = catchError<GpioError>([&] { GpioDataReady line(cfg); });
  EXPECT_EQ(e.error(), ENOTTY);
  EXPECT_TRUE(contains(e.what(), "not a GPIO character device")) << e.what();
}

TEST(GpioDataReady, LineAndRequestFailuresNameTheCulprit) {
  GpioLineConfig cfg;
  cfg.offset = 60;
  const std::string range = describeGpioError("line", EINVAL, cfg, 54);
  EXPECT_TRUE(contains(range, "out of range")) << range;
  EXPECT_TRUE(contains(range, "54 lines")) << range;
  EXPECT_TRUE(contains(range, "BCM GPIO number")) << range;
  cfg.offset = 17;
  const std::string busy = describeGpioError("request", EBUSY, cfg, 0, "sysfs");
  EXPECT_TRUE(contains(busy, "line 17")) << busy;
  EXPECT_TRUE(contains(busy, "by 'sysfs'")) << busy;
  EXPECT_TRUE(contains(busy, "gpioinfo")) << busy;
  EXPECT_TRUE(contains(describeGpioError("open", EACCES, cfg), "'gpio' group"));
}

TEST(PollingDataReady, VirtualTimeReportsOnePollPerElapsedPeriod) {
  VirtualClock clock(kNsPerSecond);
  PollingDataReady poll(clock, 100 * kNsPerMillisecond);
  std::int64_t t = 0;
  EXPECT_EQ(poll.consumeEdge(t), -EAGAIN);
  clock.advanceNs(100 * kNsPerMillisecond);
  ASSERT_EQ(poll.consumeEdge(t), 0);
  EXPECT_EQ(t, clock.nowNs());
  EXPECT_EQ(poll.consumeEdge(t), -EAGAIN);
  clock.advanceNs(350 * kNsPerMillisecond);  // three periods missed: one poll (the FIFO holds the data)
  EXPECT_EQ(poll.consumeEdge(t), 0);
  EXPECT_EQ(poll.consumeEdge(t), -EAGAIN);
  EXPECT_EQ(poll.nextPollNs(), kNsPerSecond + 500 * kNsPerMillisecond);
  EXPECT_THROW(PollingDataReady(clock, 0), std::invalid_argument);
}

TEST(PollingDataReady, RealTimeFdBecomesReadableAndStampsTheReadTime) {
  MonotonicClock clock;
  PollingDataReady poll(clock, kNsPerMillisecond);
  pollfd p{poll.fd(), POLLIN, 0};
  ASSERT_EQ(::poll(&p, 1, 5000), 1);
  const std::int64_t before = clock.nowNs();
  std::int64_t t = 0;
  ASSERT_EQ(poll.consumeEdge(t), 0);
  EXPECT_GE(t, before);
  EXPECT_LE(t, clock.nowNs());
  EXPECT_EQ(poll.edgesDropped(), 0u);
}

}  // namespace
}  // namespace gyrod::driver
