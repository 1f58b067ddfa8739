# 64-bit ARM (Raspberry Pi 3/4/5 with a 64-bit OS): Debian arm64, crossbuild-essential-arm64.
# Usage: scripts/cross-test.sh arm64 (it builds the sysroot this file expects).
set(GYROD_CROSS_TRIPLET aarch64-linux-gnu)
set(GYROD_CROSS_PROCESSOR aarch64)
set(GYROD_DEBIAN_ARCH arm64)
set(GYROD_QEMU qemu-aarch64-static)
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
