#pragma once
// InvenSense MPU-6050 registers used by gyrod: the register numbers, the bits we set or
// read, the documented reset values and the FIFO frame layout. One source of truth for
// the mock device and the real driver.
//
// Reference: InvenSense "MPU-6000 and MPU-6050 Register Map and Descriptions",
// RM-MPU-6000A-00 rev 4.2 (2013-08-19), cited below as "RM §section p.page".
// Reset values (RM §3 p.8): 0x00 for every register except PWR_MGMT_1 (0x40) and
// WHO_AM_I (0x68).
#include <array>
#include <cstddef>
#include <cstdint>

namespace gyrod::driver::mpu6050 {

inline constexpr std::uint8_t Bit0 = 1U << 0;
inline constexpr std::uint8_t Bit1 = 1U << 1;
inline constexpr std::uint8_t Bit2 = 1U << 2;
inline constexpr std::uint8_t Bit3 = 1U << 3;
inline constexpr std::uint8_t Bit4 = 1U << 4;
inline constexpr std::uint8_t Bit5 = 1U << 5;
inline constexpr std::uint8_t Bit6 = 1U << 6;
inline constexpr std::uint8_t Bit7 = 1U << 7;

// 7-bit I2C address: 0x68 with AD0 low, 0x69 with AD0 high (RM §4.32, WHO_AM_I).
inline constexpr std::uint8_t kI2cAddressAd0Low = 0x68;
inline constexpr std::uint8_t kI2cAddressAd0High = 0x69;

// WHO_AM_I reads 0x68 on a genuine MPU-6050 (RM §4.32 p.45, bits 6:1 of the address;
// the AD0 pin does not change it). Clones and relatives answer otherwise, e.g. 0x70
// (MPU-6500), 0x72 and 0x98 (seen on counterfeit boards).
inline constexpr std::uint8_t kWhoAmI = 0x68;

enum class Register : std::uint8_t {
  SMPLRT_DIV = 0x19,    // RM §4.2 p.11
  CONFIG = 0x1A,        // RM §4.3 p.13
  GYRO_CONFIG = 0x1B,   // RM §4.4 p.14
  ACCEL_CONFIG = 0x1C,  // RM §4.5 p.15

  FIFO_EN = 0x23,  // RM §4.6 p.16

  INT_PIN_CFG = 0x37,  // Register 55
  INT_ENABLE = 0x38,   // Register 56
  INT_STATUS = 0x3A,   // Register 58, read-only, cleared by reading

  ACCEL_XOUT_H = 0x3B,  // Registers 59..64, big-endian two's complement
  ACCEL_XOUT_L = 0x3C,
  ACCEL_YOUT_H = 0x3D,
  ACCEL_YOUT_L = 0x3E,
  ACCEL_ZOUT_H = 0x3F,
  ACCEL_ZOUT_L = 0x40,
  TEMP_OUT_H = 0x41,  // Registers 65..66
  TEMP_OUT_L = 0x42,
  GYRO_XOUT_H = 0x43,  // Registers 67..72
  GYRO_XOUT_L = 0x44,
  GYRO_YOUT_H = 0x45,
  GYRO_YOUT_L = 0x46,
  GYRO_ZOUT_H = 0x47,
  GYRO_ZOUT_L = 0x48,

  SIGNAL_PATH_RESET = 0x68,  // Register 104
  USER_CTRL = 0x6A,          // Register 106
  PWR_MGMT_1 = 0x6B,         // Register 107, reset value 0x40
  PWR_MGMT_2 = 0x6C,         // Register 108

  FIFO_COUNTH = 0x72,  // RM §4.30 p.43
  FIFO_COUNTL = 0x73,
  FIFO_R_W = 0x74,  // RM §4.31 p.44
  WHO_AM_I = 0x75,  // RM §4.32 p.45, reset value 0x68
};

constexpr std::uint8_t address(Register r) { return static_cast<std::uint8_t>(r); }

// CONFIG (RM §4.3 p.13)
enum CONFIG_BIT : std::uint8_t {
  EXT_SYNC_SET_MASK = Bit5 | Bit4 | Bit3,  // FSYNC sampling; gyrod keeps it 0 (disabled)
  DLPF_CFG_MASK = Bit2 | Bit1 | Bit0,      // 0..6; 7 is reserved (PX4 uses it to bypass)
};
inline constexpr int kDlpfCfgReserved = 7;

// GYRO_CONFIG (RM §4.4 p.14)
enum GYRO_CONFIG_BIT : std::uint8_t {
  XG_ST = Bit7,
  YG_ST = Bit6,
  ZG_ST = Bit5,
  FS_SEL_MASK = Bit4 | Bit3,  // FS_SEL[4:3]
  FS_SEL_250_DPS = 0,
  FS_SEL_500_DPS = Bit3,
  FS_SEL_1000_DPS = Bit4,
  FS_SEL_2000_DPS = Bit4 | Bit3,
};
inline constexpr int kFsSelShift = 3;

// ACCEL_CONFIG (RM §4.5 p.15)
enum ACCEL_CONFIG_BIT : std::uint8_t {
  XA_ST = Bit7,
  YA_ST = Bit6,
  ZA_ST = Bit5,
  AFS_SEL_MASK = Bit4 | Bit3,  // AFS_SEL[4:3]
};
inline constexpr int kAfsSelShift = 3;

// FIFO_EN (RM §4.6 p.16)
enum FIFO_EN_BIT : std::uint8_t {
  TEMP_FIFO_EN = Bit7,
  XG_FIFO_EN = Bit6,
  YG_FIFO_EN = Bit5,
  ZG_FIFO_EN = Bit4,
  ACCEL_FIFO_EN = Bit3,  // all three accel axes
  SLV2_FIFO_EN = Bit2,   // external sensors: not used by gyrod
  SLV1_FIFO_EN = Bit1,
  SLV0_FIFO_EN = Bit0,
};

// INT_PIN_CFG (Register 55)
enum INT_PIN_CFG_BIT : std::uint8_t {
  INT_LEVEL = Bit7,     // 1: INT active low; 0: active high
  INT_OPEN = Bit6,      // 1: open drain; 0: push-pull
  LATCH_INT_EN = Bit5,  // 1: INT held until cleared; 0: a 50 µs pulse
  INT_RD_CLEAR = Bit4,  // 1: status cleared by any read; 0: only by reading INT_STATUS
  FSYNC_INT_LEVEL = Bit3,
  FSYNC_INT_EN = Bit2,
  I2C_BYPASS_EN = Bit1,
};
inline constexpr std::int64_t kIntPulseWidthNs = 50'000;  // Register 55: "50us long pulse"

// INT_ENABLE (Register 56)
enum INT_ENABLE_BIT : std::uint8_t {
  FIFO_OFLOW_EN = Bit4,
  I2C_MST_INT_EN = Bit3,
  DATA_RDY_EN = Bit0,
};

// INT_STATUS (Register 58): each bit clears when the register is read.
enum INT_STATUS_BIT : std::uint8_t {
  FIFO_OFLOW_INT = Bit4,
  I2C_MST_INT = Bit3,
  DATA_RDY_INT = Bit0,
};

// USER_CTRL (Register 106)
enum USER_CTRL_BIT : std::uint8_t {
  FIFO_EN = Bit6,
  I2C_MST_EN = Bit5,
  I2C_IF_DIS = Bit4,  // SPI only (MPU-6000); must stay 0 on the MPU-6050
  FIFO_RESET = Bit2,  // self-clearing
  I2C_MST_RESET = Bit1,
  SIG_COND_RESET = Bit0,
};

// PWR_MGMT_1 (Register 107)
enum PWR_MGMT_1_BIT : std::uint8_t {
  DEVICE_RESET = Bit7,  // self-clearing; afterwards the chip is asleep (0x40)
  SLEEP = Bit6,
  CYCLE = Bit5,
  TEMP_DIS = Bit3,
  CLKSEL_MASK = Bit2 | Bit1 | Bit0,  // 0 internal 8 MHz, 1 PLL with X gyro reference, ...
  CLKSEL_PLL_XGYRO = Bit0,
};
inline constexpr std::uint8_t kPwrMgmt1ResetValue = SLEEP;  // 0x40

// PWR_MGMT_2 (Register 108)
enum PWR_MGMT_2_BIT : std::uint8_t {
  LP_WAKE_CTRL_MASK = Bit7 | Bit6,
  STBY_XA = Bit5,
  STBY_YA = Bit4,
  STBY_ZA = Bit3,
  STBY_XG = Bit2,
  STBY_YG = Bit1,
  STBY_ZG = Bit0,
};

// Gyro sensitivity (product spec §6.1): LSB per °/s for FS_SEL = 0..3.
inline constexpr std::array<double, 4> kGyroLsbPerDps = {131.0, 65.5, 32.8, 16.4};
// Accel sensitivity (product spec §6.2): LSB per g for AFS_SEL = 0..3.
inline constexpr std::array<double, 4> kAccelLsbPerG = {16384.0, 8192.0, 4096.0, 2048.0};

// Temperature (RM, Registers 65 and 66): °C = TEMP_OUT / 340 + 36.53.
inline constexpr double kTemperatureLsbPerDegC = 340.0;
inline constexpr double kTemperatureOffsetDegC = 36.53;
constexpr double temperatureDegCFromRaw(std::int16_t raw) {
  return static_cast<double>(raw) / kTemperatureLsbPerDegC + kTemperatureOffsetDegC;
}

// Gyro output rate before the divider (RM §4.2 p.11): 8 kHz with DLPF_CFG 0 or 7, else 1 kHz.
// Sample rate = gyro output rate / (1 + SMPLRT_DIV).
constexpr double gyroOutputRateHz(int dlpf_cfg) {
  return (dlpf_cfg == 0 || dlpf_cfg == kDlpfCfgReserved) ? 8000.0 : 1000.0;
}
// The accelerometer's output rate (RM §4.2 p.11): at a faster sample rate the FIFO and the
// registers get the same accel sample more than once.
inline constexpr double kAccelOutputRateHz = 1000.0;
// The fastest I2C clock the chip supports (product spec: Fast-mode, 400 kHz): a byte on the wire
// takes 9 clocks (8 bits and the acknowledge).
inline constexpr double kMaxI2cClockHz = 400'000.0;
inline constexpr double kI2cClocksPerByte = 9.0;

namespace fifo {

inline constexpr std::size_t kSize = 1024;  // bytes (product spec §7.17)

// Bytes one sample adds to the FIFO for a FIFO_EN value: data are written "in order of
// register number" (RM §4.31 p.44), i.e. accel X,Y,Z (6) if ACCEL_FIFO_EN, then TEMP
// (2), then gyro X, Y, Z (2 each). External-sensor bits are ignored (no slaves).
constexpr std::size_t frameSize(std::uint8_t fifo_en) {
  std::size_t n = 0;
  if (fifo_en & ACCEL_FIFO_EN) n += 6;
  if (fifo_en & TEMP_FIFO_EN) n += 2;
  if (fifo_en & XG_FIFO_EN) n += 2;
  if (fifo_en & YG_FIFO_EN) n += 2;
  if (fifo_en & ZG_FIFO_EN) n += 2;
  return n;
}

// Frame layout with every sensor enabled (FIFO_EN = 0xF8): registers 0x3B..0x48.
struct [[gnu::packed]] FullFrame {
  std::uint8_t ACCEL_XOUT_H, ACCEL_XOUT_L;
  std::uint8_t ACCEL_YOUT_H, ACCEL_YOUT_L;
  std::uint8_t ACCEL_ZOUT_H, ACCEL_ZOUT_L;
  std::uint8_t TEMP_OUT_H, TEMP_OUT_L;
  std::uint8_t GYRO_XOUT_H, GYRO_XOUT_L;
  std::uint8_t GYRO_YOUT_H, GYRO_YOUT_L;
  std::uint8_t GYRO_ZOUT_H, GYRO_ZOUT_L;
};
static_assert(sizeof(FullFrame) == 14);
static_assert(frameSize(TEMP_FIFO_EN | XG_FIFO_EN | YG_FIFO_EN | ZG_FIFO_EN | ACCEL_FIFO_EN) == sizeof(FullFrame));

// Frame layout gyrod's driver uses (FIFO_EN = 0xF0): temperature as the sync marker, then
// the gyro (registers 0x41..0x48).
struct [[gnu::packed]] TempGyroFrame {
  std::uint8_t TEMP_OUT_H, TEMP_OUT_L;
  std::uint8_t GYRO_XOUT_H, GYRO_XOUT_L;
  std::uint8_t GYRO_YOUT_H, GYRO_YOUT_L;
  std::uint8_t GYRO_ZOUT_H, GYRO_ZOUT_L;
};
static_assert(sizeof(TempGyroFrame) == 8);
static_assert(frameSize(TEMP_FIFO_EN | XG_FIFO_EN | YG_FIFO_EN | ZG_FIFO_EN) == sizeof(TempGyroFrame));

}  // namespace fifo

// Big-endian register pair → signed value (RM: "_H" holds bits 15:8).
constexpr std::int16_t combineBigEndian(std::uint8_t high, std::uint8_t low) {
  return static_cast<std::int16_t>(static_cast<std::uint16_t>((high << 8) | low));
}

}  // namespace gyrod::driver::mpu6050
