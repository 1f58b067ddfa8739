# Shared part of the Debian cross toolchain files (aarch64-linux-gnu.cmake, arm-linux-gnueabihf.cmake).
# The compiler and the target's libc come from crossbuild-essential-<arch> (/usr/<triplet>); every
# other library comes from a sysroot of the target's packages unpacked with dpkg -x, because
# installing the foreign -dev packages with apt can fail when the foreign indexes lag the host's.
# scripts/cross-test.sh builds that sysroot; GYROD_SYSROOT overrides where it is.
# The caller sets GYROD_CROSS_TRIPLET, GYROD_CROSS_PROCESSOR, GYROD_DEBIAN_ARCH and GYROD_QEMU first.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR ${GYROD_CROSS_PROCESSOR})
set(CMAKE_C_COMPILER ${GYROD_CROSS_TRIPLET}-gcc)
set(CMAKE_CXX_COMPILER ${GYROD_CROSS_TRIPLET}-g++)

if(NOT GYROD_SYSROOT)
  set(GYROD_SYSROOT "$ENV{GYROD_SYSROOT}")
endif()
if(NOT GYROD_SYSROOT)
  get_filename_component(GYROD_SYSROOT "${CMAKE_CURRENT_LIST_DIR}/../../build/sysroot-${GYROD_DEBIAN_ARCH}" ABSOLUTE)
endif()
# try_compile re-reads this file in a fresh project: hand it the same sysroot.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES GYROD_SYSROOT)
if(NOT EXISTS "${GYROD_SYSROOT}/usr/include")
  message(FATAL_ERROR "no sysroot at ${GYROD_SYSROOT}: run scripts/cross-test.sh ${GYROD_DEBIAN_ARCH} "
                      "(or set GYROD_SYSROOT to a folder of the target's packages unpacked with dpkg -x)")
endif()

set(CMAKE_FIND_ROOT_PATH "${GYROD_SYSROOT}" "/usr/${GYROD_CROSS_TRIPLET}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# pkg-config (libsystemd, libgpiod) must read the target's .pc files and prefix their paths.
set(ENV{PKG_CONFIG_LIBDIR} "${GYROD_SYSROOT}/usr/lib/${GYROD_CROSS_TRIPLET}/pkgconfig:${GYROD_SYSROOT}/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${GYROD_SYSROOT}")
set(ENV{PKG_CONFIG_PATH} "")

# GCC notes (with no warning) that passing some aggregates changed ABI in GCC 10.1 on ARM; that
# matters only when linking objects built by an older GCC, and everything here is built by one.
set(CMAKE_CXX_FLAGS_INIT "-Wno-psabi")

# The linker resolves the libraries' own dependencies (libsystemd0 -> libzstd ...) in the sysroot.
set(_gyrod_rpath_link
    "-Wl,-rpath-link,${GYROD_SYSROOT}/usr/lib/${GYROD_CROSS_TRIPLET}:${GYROD_SYSROOT}/lib/${GYROD_CROSS_TRIPLET}")
set(CMAKE_EXE_LINKER_FLAGS_INIT "${_gyrod_rpath_link}")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "${_gyrod_rpath_link}")

# Test executables run under qemu-user with the sysroot as their root (its ld.so, libc and
# libraries); gtest_discover_tests and ctest use this, and tests/ hands it to the tests that
# start gyrod or gyroctl themselves (binfmt_misc is not assumed).
# An absolute path: the tests exec it with execv/posix_spawn, which do not search PATH.
find_program(GYROD_QEMU_PATH ${GYROD_QEMU} NO_CMAKE_FIND_ROOT_PATH)
if(NOT GYROD_QEMU_PATH)
  message(FATAL_ERROR "${GYROD_QEMU} not found: apt-get install qemu-user-static")
endif()
set(CMAKE_CROSSCOMPILING_EMULATOR ${GYROD_QEMU_PATH} -L ${GYROD_SYSROOT})
