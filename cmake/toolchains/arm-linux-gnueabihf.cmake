# 32-bit ARM with hardware float (Raspberry Pi OS 32-bit, ARMv7): Debian armhf, crossbuild-essential-armhf.
# Usage: scripts/cross-test.sh armhf (it builds the sysroot this file expects). Here size_t and long are
# 32 bits wide and time_t is 32 bits unless _TIME_BITS=64: what the 64-bit hosts cannot show.
set(GYROD_CROSS_TRIPLET arm-linux-gnueabihf)
set(GYROD_CROSS_PROCESSOR arm)
set(GYROD_DEBIAN_ARCH armhf)
set(GYROD_QEMU qemu-arm-static)
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
