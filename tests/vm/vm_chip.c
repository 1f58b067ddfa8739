// The guest helper of scripts/vm-kernel-test.sh and scripts/vm-systemd-test.sh: what a real
// MPU6050 does by itself that i2c-stub's plain register cells do not, plus the few things the
// busybox init cannot do.
//
//   vm_chip preload BUS            WHO_AM_I, TEMP_OUT, FIFO_COUNT and FIFO frames (values below)
//   vm_chip emulate BUS            forever: clear DEVICE_RESET after a reset write, serve the
//                                  frames FIFO_EN asks for, keep the cells
//   vm_chip silence BUS            FIFO_COUNT = 0: the chip stops producing samples (stop emulate first)
//   vm_chip edges PULL_FILE N US   N rising edges on a gpio-sim line, one every US microseconds
//   vm_chip rdwr BUS               exit 0 if I2C_RDWR fails with EOPNOTSUPP (an SMBus-only adapter)
//   vm_chip asuser UID CMD...      run CMD as UID (for the non-root check)
//   vm_chip exit CODE              power off through QEMU's isa-debug-exit (status 2*CODE+1)
//
// i2c-stub (SMBus only) keeps one 16-bit cell per register: byte transfers use its low byte,
// word transfers the whole cell, I2C-block transfers the low bytes of consecutive cells (at
// most 32, and never past cell 0xFF). So a FIFO burst at FIFO_R_W (0x74) reads the cells 0x74,
// 0x75, ... again and again: the frames stay, FIFO_COUNT stays, and every wake-up reads the
// same known frame. vm_chip lays the cells 0x74 .. 0x93 out as whole frames repeated (byte i
// = frame byte i mod the frame size) and holds FIFO_COUNT at one frame, so every burst gyrod
// makes (one frame, or up to 32 bytes of whole frames) starts at a frame boundary.
//
// The frame size follows FIFO_EN, as the chip's does: with ACCEL_FIFO_EN (gyrod's default,
// FIFO_EN 0xF8) 14-byte frames ACCEL_X, ACCEL_Y, ACCEL_Z, TEMP, GYRO_X, GYRO_Y, GYRO_Z;
// without it (`accel = false`, FIFO_EN 0xF0, or before gyrod has written FIFO_EN) 8-byte
// frames TEMP, GYRO_X, GYRO_Y, GYRO_Z. `emulate` reads FIFO_EN every turn (2 ms) and lays the
// cells out again when the size changes; gyrod waits 50 ms between writing the table and
// reading the FIFO. WHO_AM_I (0x75) is also byte 1 of the first frame: the low byte of the
// temperature word in an 8-byte frame, of ACCEL_X in a 14-byte one; both end in 0x68.
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <grp.h>
#include <linux/i2c-dev.h>
#include <linux/i2c.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/io.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

enum {
  kAddress = 0x68,
  kTempOut = 0x41,
  kFifoEn = 0x23,
  kAccelFifoEn = 0x08,
  kPwrMgmt1 = 0x6B,
  kFifoCount = 0x72,
  kFifoRw = 0x74,
  kWhoAmI = 0x75,
  kDeviceReset = 0x80,
  kSleep = 0x40,
  kGyroFrameBytes = 8,    // TEMP, GYRO_X/Y/Z
  kAccelFrameBytes = 14,  // ACCEL_X/Y/Z, TEMP, GYRO_X/Y/Z
  kFifoCells = 32,        // one SMBus I2C-block read: 4 whole 8-byte frames, 2 whole 14-byte ones
};

// The frames every wake-up reads, big-endian words. The init scripts check that gyrod
// publishes exactly these: deg C = word / 340 + 36.53; 131 LSB per deg/s at FS_SEL 0;
// 16384 / 8192 / 4096 / 2048 LSB per g at AFS_SEL 0..3.
static const int16_t kTemp = (int16_t)0xF868;  // -1944: 30.8124 deg C; low byte = WHO_AM_I
// 8-byte frames (accel off): 1, -2, 5 deg/s.
static const int16_t kGyro[3] = {131, -262, 655};
// 14-byte frames (accel on): other values, so a frame of the wrong size cannot pass.
// ACCEL_X 0x7F68 = 32616 (99.5 % of full scale; low byte = WHO_AM_I), ACCEL_Y 0xE800 = -6144,
// ACCEL_Z 0x8000 = -32768 (negative full scale): 1.99072265625, -0.375, -2 g at AFS_SEL 0,
// 7.962890625, -1.5, -8 g at AFS_SEL 2. Gyro 0xFE77 = -393, 0x7FEE = 32750, 0x8012 = -32750:
// -3, 250, -250 deg/s (250 deg/s is 99.9 % of FS_SEL 0's full scale).
static const int16_t kAccelFrameAccel[3] = {(int16_t)0x7F68, -6144, (int16_t)0x8000};
static const int16_t kAccelFrameGyro[3] = {-393, 32750, -32750};

static _Noreturn void die(const char* what) {
  fprintf(stderr, "vm_chip: %s: %s\n", what, strerror(errno));
  exit(2);
}

static int openBus(const char* path) {
  const int fd = open(path, O_RDWR);
  if (fd < 0) die(path);
  if (ioctl(fd, I2C_SLAVE, kAddress) < 0) die("I2C_SLAVE 0x68");
  return fd;
}

static int smbus(int fd, char rw, uint8_t reg, int size, union i2c_smbus_data* data) {
  struct i2c_smbus_ioctl_data args = {.read_write = rw, .command = reg, .size = size, .data = data};
  return ioctl(fd, I2C_SMBUS, &args);
}

static int readByte(int fd, uint8_t reg) {
  union i2c_smbus_data d;
  if (smbus(fd, I2C_SMBUS_READ, reg, I2C_SMBUS_BYTE_DATA, &d) < 0) die("read byte");
  return d.byte;
}

static void writeByte(int fd, uint8_t reg, uint8_t value) {
  union i2c_smbus_data d = {.byte = value};
  if (smbus(fd, I2C_SMBUS_WRITE, reg, I2C_SMBUS_BYTE_DATA, &d) < 0) die("write byte");
}

// The chip sends a word's high byte first; SMBus calls the first byte the low one.
static uint16_t smbusCellFor(uint16_t big_endian_value) {
  return (uint16_t)((big_endian_value << 8) | (big_endian_value >> 8));
}

static int readWord(int fd, uint8_t reg) {
  union i2c_smbus_data d;
  if (smbus(fd, I2C_SMBUS_READ, reg, I2C_SMBUS_WORD_DATA, &d) < 0) die("read word");
  return d.word;
}

static void writeWord(int fd, uint8_t reg, uint16_t cell) {
  union i2c_smbus_data d = {.word = cell};
  if (smbus(fd, I2C_SMBUS_WRITE, reg, I2C_SMBUS_WORD_DATA, &d) < 0) die("write word");
}

static int frameSizeFor(int fifo_en) { return (fifo_en & kAccelFifoEn) ? kAccelFrameBytes : kGyroFrameBytes; }

static void putWord(uint8_t* out, int16_t word) {
  out[0] = (uint8_t)((uint16_t)word >> 8);
  out[1] = (uint8_t)((uint16_t)word & 0xFF);
}

// One frame of `size` bytes (8 or 14) in FIFO order (register order, RM 4.31).
static void frameBytes(int size, uint8_t out[kAccelFrameBytes]) {
  if (size == kAccelFrameBytes) {
    for (int i = 0; i < 3; ++i) putWord(out + 2 * i, kAccelFrameAccel[i]);
    putWord(out + 6, kTemp);
    for (int i = 0; i < 3; ++i) putWord(out + 8 + 2 * i, kAccelFrameGyro[i]);
  } else {
    putWord(out, kTemp);
    for (int i = 0; i < 3; ++i) putWord(out + 2 + 2 * i, kGyro[i]);
  }
}

// Rewrites whatever differs from what the chip would hold with `size`-byte frames; returns
// how many cells it fixed.
static int keepCells(int fd, int size) {
  int fixed = 0;
  uint8_t frame[kAccelFrameBytes];
  frameBytes(size, frame);
  if (frame[1] != 0x68) {  // the frame's byte 1 is the WHO_AM_I cell (see the header)
    fprintf(stderr, "vm_chip: a %d-byte frame's byte 1 must be WHO_AM_I (0x68)\n", size);
    exit(2);
  }
  for (int i = 0; i < kFifoCells; ++i) {
    const uint8_t want = frame[i % size];
    if (readByte(fd, (uint8_t)(kFifoRw + i)) != want) writeByte(fd, (uint8_t)(kFifoRw + i), want), ++fixed;
  }
  if (readByte(fd, kWhoAmI) != 0x68) writeByte(fd, kWhoAmI, 0x68), ++fixed;
  const uint16_t temp_cell = smbusCellFor((uint16_t)kTemp);
  if (readWord(fd, kTempOut) != temp_cell) writeWord(fd, kTempOut, temp_cell), ++fixed;
  const uint16_t count_cell = smbusCellFor((uint16_t)size);  // one frame per wake-up, like one edge per sample
  if (readWord(fd, kFifoCount) != count_cell) writeWord(fd, kFifoCount, count_cell), ++fixed;
  return fixed;
}

static void sleepUs(long us) {
  struct timespec t = {.tv_sec = us / 1000000, .tv_nsec = (us % 1000000) * 1000};
  while (nanosleep(&t, &t) < 0 && errno == EINTR) {}
}

static int emulate(const char* bus) {
  const int fd = openBus(bus);
  int size = 0;
  for (unsigned long turn = 0;; ++turn) {
    // A real part clears DEVICE_RESET itself and comes up asleep (PWR_MGMT_1 = 0x40).
    if (readByte(fd, kPwrMgmt1) & kDeviceReset) writeByte(fd, kPwrMgmt1, kSleep);
    const int fifo_en = readByte(fd, kFifoEn);
    if (frameSizeFor(fifo_en) != size) {  // gyrod wrote FIFO_EN: the frames change size now
      size = frameSizeFor(fifo_en);
      const int fixed = keepCells(fd, size);
      printf("VMTEST vm_chip: FIFO_EN 0x%02x: serving %d-byte frames, FIFO_COUNT %d (%d cells written)\n", fifo_en,
             size, size, fixed);
      fflush(stdout);
    } else if (turn % 50 == 0) {
      keepCells(fd, size);  // nothing but a reset should change them: look now and then
    }
    sleepUs(2000);
  }
  return 0;
}

static int writePull(const char* file, const char* value) {
  const int fd = open(file, O_WRONLY);
  if (fd < 0) die(file);
  const ssize_t n = write(fd, value, strlen(value));
  close(fd);
  return n == (ssize_t)strlen(value) ? 0 : -1;
}

// A rising edge is pull-down then pull-up; the line rests high between edges for most of the
// period, like a pulse-mode INT seen upside down (gyrod counts rising edges only).
static int edges(const char* pull_file, long count, long period_us) {
  struct timespec next;
  clock_gettime(CLOCK_MONOTONIC, &next);
  for (long i = 0; i < count; ++i) {
    if (writePull(pull_file, "pull-down") < 0 || writePull(pull_file, "pull-up") < 0) die(pull_file);
    next.tv_nsec += period_us * 1000;
    while (next.tv_nsec >= 1000000000) next.tv_nsec -= 1000000000, ++next.tv_sec;
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, NULL) == EINTR) {}
  }
  return 0;
}

static int rdwrUnsupported(const char* bus) {
  const int fd = openBus(bus);
  uint8_t reg = kWhoAmI, value = 0;
  struct i2c_msg msgs[2] = {{.addr = kAddress, .flags = 0, .len = 1, .buf = &reg},
                            {.addr = kAddress, .flags = I2C_M_RD, .len = 1, .buf = &value}};
  struct i2c_rdwr_ioctl_data data = {.msgs = msgs, .nmsgs = 2};
  if (ioctl(fd, I2C_RDWR, &data) >= 0) {
    fprintf(stderr, "vm_chip: I2C_RDWR worked on %s\n", bus);
    return 1;
  }
  printf("I2C_RDWR on %s: %s\n", bus, strerror(errno));
  return errno == EOPNOTSUPP ? 0 : 1;
}

static int debugExit(int code) {
  if (ioperm(0xf4, 4, 1) < 0) die("ioperm 0xf4");
  outl((unsigned)code, 0xf4);
  return 3;  // not reached under QEMU with -device isa-debug-exit
}

int main(int argc, char** argv) {
  const char* mode = argc > 1 ? argv[1] : "";
  if (!strcmp(mode, "preload") && argc == 3) {
    const int fd = openBus(argv[2]);
    writeByte(fd, kPwrMgmt1, kSleep);
    const int size = frameSizeFor(readByte(fd, kFifoEn));
    printf("vm_chip: preloaded %d-byte frames (%d cells written)\n", size, keepCells(fd, size));
    return 0;
  }
  if (!strcmp(mode, "emulate") && argc == 3) return emulate(argv[2]);
  if (!strcmp(mode, "silence") && argc == 3) {
    writeWord(openBus(argv[2]), kFifoCount, 0);
    return 0;
  }
  if (!strcmp(mode, "edges") && argc == 5) return edges(argv[2], atol(argv[3]), atol(argv[4]));
  if (!strcmp(mode, "rdwr") && argc == 3) return rdwrUnsupported(argv[2]);
  if (!strcmp(mode, "asuser") && argc >= 4) {
    const uid_t uid = (uid_t)atoi(argv[2]);
    if (setgroups(0, NULL) < 0 || setgid(uid) < 0 || setuid(uid) < 0) die("setuid");
    execvp(argv[3], argv + 3);
    die(argv[3]);
  }
  if (!strcmp(mode, "exit") && argc == 3) return debugExit(atoi(argv[2]));
  fprintf(
      stderr,
      "usage: vm_chip preload|emulate|silence BUS | edges PULL_FILE N US | rdwr BUS | asuser UID CMD... | exit CODE\n");
  return 2;
}
