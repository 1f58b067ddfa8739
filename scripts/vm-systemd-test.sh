#!/usr/bin/env bash
# gyrod as a systemd service on a real systemd: a minimal Debian bookworm root (debootstrap)
# booted under QEMU (TCG) with systemd as PID 1, the same kernel as scripts/vm-kernel-test.sh
# and i2c-stub at 0x68 kept alive by tests/vm/vm_chip. gyrod is installed from the build
# tree (`cmake --install` into the root, prefix /usr, units from systemd/) or from a .deb
# (--deb). tests/vm/systemd-checks.sh runs the checks in the guest and sets QEMU's exit status.
#
#   scripts/vm-systemd-test.sh [--deb PATH] [--timeout SECONDS]
#
# Cached in build/vm/: the kernel, the debootstrap root (build/vm/sd/rootfs-base) and a /usr
# build of gyrod (build/vm/sd/cmake). Installs debootstrap and qemu-system-x86 when missing.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
deb=""
timeout_s=900
while [ $# -gt 0 ]; do
  case "$1" in
    --deb) deb=$(realpath "$2"); shift 2 ;;
    --timeout) timeout_s=$2; shift 2 ;;
    *) echo "usage: $0 [--deb PATH] [--timeout SECONDS]" >&2; exit 2 ;;
  esac
done
[ -z "$deb" ] || [ -f "$deb" ] || { echo "--deb $deb: no such file" >&2; exit 2; }
vm=$root/build/vm
sd=$vm/sd
mkdir -p "$sd"
log() { printf '[vm-systemd-test %(%T)T] %s\n' -1 "$*" >&2; }
t_start=$(date +%s)

kernel_dir=$(scripts/vm-kernel-test.sh --prepare-only)

# --- the root file system ---
base=$sd/rootfs-base
if [ ! -x "$base/lib/systemd/systemd" ] || [ ! -x "$base/usr/sbin/mosquitto" ]; then
  command -v debootstrap >/dev/null || apt-get install -y -qq --no-install-recommends debootstrap >/dev/null
  log "debootstrap bookworm (minbase + systemd, gyrod's libraries and an MQTT broker) into $base"
  rm -rf "$base"
  debootstrap --variant=minbase \
    --include=systemd,systemd-sysv,udev,libtomlplusplus3,libspdlog1.10,libfmt9,libi2c0,libgpiod2,libmosquitto1,mosquitto \
    bookworm "$base" http://deb.debian.org/debian >"$sd/debootstrap.log" 2>&1 ||
    { tail -n 20 "$sd/debootstrap.log" >&2; exit 1; }
fi
r=$sd/root
rm -rf "$r" && mkdir -p "$r"
# Without apt's caches, documentation and locales: the root is unpacked into the guest's RAM.
tar -C "$base" --exclude=./var/cache/apt --exclude=./var/lib/apt/lists --exclude=./usr/share/doc \
  --exclude=./usr/share/man --exclude=./usr/share/locale -cf - . | tar -C "$r" -xf -

# --- gyrod ---
if [ -n "$deb" ]; then
  log "installing $deb"
  cp "$deb" "$r/tmp/gyrod.deb"
  chroot "$r" dpkg -i /tmp/gyrod.deb >"$sd/dpkg.log" 2>&1 || { cat "$sd/dpkg.log" >&2; exit 1; }
  rm "$r/tmp/gyrod.deb"
  installed="the package $(basename "$deb")"
else
  build=$sd/cmake
  log "building gyrod with prefix /usr in $build"
  cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_INSTALL_PREFIX=/usr -DGYROD_BUILD_BENCHMARKS=OFF \
    -DBUILD_TESTING=OFF $(command -v ccache >/dev/null && echo -DCMAKE_CXX_COMPILER_LAUNCHER=ccache) \
    >"$sd/cmake.log" 2>&1 || { tail -n 20 "$sd/cmake.log" >&2; exit 1; }
  cmake --build "$build" -j2 --target gyrod gyroctl >>"$sd/cmake.log" 2>&1 || { tail -n 30 "$sd/cmake.log" >&2; exit 1; }
  DESTDIR=$r cmake --install "$build" --strip >>"$sd/cmake.log" 2>&1 || { tail -n 20 "$sd/cmake.log" >&2; exit 1; }
  installed="cmake --install (prefix /usr)"
fi
[ -f "$r/usr/lib/systemd/system/gyrod.service" ] || [ -f "$r/lib/systemd/system/gyrod.service" ] ||
  { echo "gyrod.service was not installed into the root" >&2; exit 1; }

# --- the VM's own pieces: the chip, the board's bus in a drop-in, the checks ---
mkdir -p "$r/usr/local/lib/vm" "$r/etc/systemd/system/multi-user.target.wants" "$r/etc/systemd/system/gyrod.service.d"
cp "$kernel_dir"/i2c-dev.ko "$kernel_dir"/i2c-stub.ko "$r/usr/local/lib/vm/"
cp "$vm/busybox" "$r/usr/local/bin/busybox" # insmod: the minbase root has no kmod
gcc -static -O2 -Wall -Wextra -Werror -o "$r/usr/local/bin/vm_chip" "$root/tests/vm/vm_chip.c"
install -m 755 "$root/tests/vm/systemd-checks.sh" "$r/usr/local/bin/vm-systemd-checks"
cat >"$r/etc/gyrod/gyrod.toml" <<'EOF'
# The VM's board: i2c-stub's /dev/i2c-0, no INT line (polling), a fixed bias and filter
# (vm_chip's frames never change, so no still period could identify one). Accel on (the
# default, +-2 g): vm_chip serves the 14-byte frames FIFO_EN asks for.
[device]
bus = 0
[bias]
source = "config"
[filter.kalman]
a = 0.5
q = 1e-4
r = 1e-3
EOF
# What a board with another bus does (the unit's own comment says so): a drop-in.
printf '[Service]\nDeviceAllow=/dev/i2c-0 rw\n' >"$r/etc/systemd/system/gyrod.service.d/vm-bus.conf"
cat >"$r/etc/systemd/system/vm-chip.service" <<'EOF'
[Unit]
Description=VM: i2c-stub at 0x68 preloaded by vm_chip
Before=gyrod.service gyrod.socket
After=systemd-udevd.service
[Service]
Type=oneshot
RemainAfterExit=yes
ExecStart=/usr/local/bin/busybox insmod /usr/local/lib/vm/i2c-dev.ko
ExecStart=/usr/local/bin/busybox insmod /usr/local/lib/vm/i2c-stub.ko chip_addr=0x68
ExecStart=/bin/sh -c 'for i in $(seq 100); do [ -e /dev/i2c-0 ] && exit 0; sleep 0.1; done; exit 1'
ExecStart=/usr/local/bin/vm_chip preload /dev/i2c-0
ExecStart=/bin/udevadm settle
[Install]
WantedBy=multi-user.target
EOF
cat >"$r/etc/systemd/system/vm-chip-emulate.service" <<'EOF'
[Unit]
Description=VM: what the MPU6050 does by itself (vm_chip emulate)
Requires=vm-chip.service
After=vm-chip.service
[Service]
ExecStart=/usr/local/bin/vm_chip emulate /dev/i2c-0
[Install]
WantedBy=multi-user.target
EOF
cat >"$r/etc/systemd/system/vm-checks.service" <<EOF
[Unit]
Description=VM: gyrod under systemd, the checks
# Wants, not Requires: the watchdog check stops vm-chip-emulate, which must not stop this unit.
Wants=vm-chip-emulate.service
After=vm-chip-emulate.service systemd-sysusers.service systemd-udev-trigger.service systemd-journald.service
[Service]
Type=oneshot
Environment="VM_INSTALLED=$installed"
ExecStart=/usr/local/bin/vm-systemd-checks
StandardOutput=journal+console
StandardError=journal+console
[Install]
WantedBy=multi-user.target
EOF
for u in vm-chip vm-chip-emulate vm-checks; do
  ln -sf "/etc/systemd/system/$u.service" "$r/etc/systemd/system/multi-user.target.wants/$u.service"
done
# No login prompts on the console; a fixed machine id; systemd as the initramfs' /init.
ln -sf /dev/null "$r/etc/systemd/system/serial-getty@ttyS0.service"
ln -sf /dev/null "$r/etc/systemd/system/getty@tty1.service"
echo 0123456789abcdef0123456789abcdef >"$r/etc/machine-id"
echo gyrod-vm >"$r/etc/hostname"
ln -sf /lib/systemd/systemd "$r/init"

(cd "$r" && find . | "$vm/busybox" cpio -o -H newc 2>/dev/null >"$sd/root.cpio")
t_built=$(date +%s)
log "root $(du -h "$sd/root.cpio" | cut -f1) (gyrod from $installed), prepared in $((t_built - t_start)) s; booting (timeout ${timeout_s} s)"

console=$sd/console.log
status=0
# no_timer_check: on a busy host the emulated CPU is slow enough for the kernel's IO-APIC
# timer check to fail ("IO-APIC + timer doesn't work!", a panic); the timer does work.
timeout --kill-after=10 "$timeout_s" nice -n 10 qemu-system-x86_64 -machine q35,accel=tcg -cpu max -m 1536 -smp 1 \
  -kernel "$kernel_dir/vmlinuz" -initrd "$sd/root.cpio" \
  -append "console=ttyS0 no_timer_check panic=-1 quiet loglevel=3 systemd.show_status=error" \
  -nographic -nic none -no-reboot -device isa-debug-exit,iobase=0xf4,iosize=0x04 >"$console" 2>&1 || status=$?
t_end=$(date +%s)
tr -d '\r' <"$console" | grep -a -o -E '(VMTEST|CHECK) .*' || true
log "QEMU exit status $status; boot + checks took $((t_end - t_built)) s; whole script $((t_end - t_start)) s"
case $status in
  1) log "PASSED"; exit 0 ;;
  124 | 137) log "FAILED: timed out after $timeout_s s (a hang); console log: $console" ;;
  *) log "FAILED; console log: $console" ;;
esac
tail -n 40 "$console" >&2
exit 1
