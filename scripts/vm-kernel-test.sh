#!/usr/bin/env bash
# gyrod's Linux backends against a real kernel: Debian's 6.1 kernel under QEMU (TCG; no KVM
# needed) with a busybox initramfs holding the freshly built gyrod and gyroctl, i2c-dev,
# i2c-stub at 0x68 (a real /dev/i2c-0, SMBus only), gpio-sim built out of tree (a real GPIO
# chip whose line gyrod watches through libgpiod and epoll) and tests/vm/vm_chip (what the
# chip does by itself). tests/vm/init.sh runs the checks and sets QEMU's exit status.
#
#   scripts/vm-kernel-test.sh [--build-dir DIR] [--timeout SECONDS]
#   scripts/vm-kernel-test.sh --prepare-only   (the kernel and modules only; prints their folder,
#                                              for scripts/vm-systemd-test.sh)
#
# Downloads (the kernel, its headers and source, busybox) are cached in build/vm/. Nothing
# is installed except, when missing, qemu-system-x86 (apt). Exit status 0 = every check passed.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
build_dir=build
timeout_s=600
prepare_only=0
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build_dir=$2; shift 2 ;;
    --timeout) timeout_s=$2; shift 2 ;;
    --prepare-only) prepare_only=1; shift ;;
    *) echo "usage: $0 [--build-dir DIR] [--timeout SECONDS] | --prepare-only" >&2; exit 2 ;;
  esac
done

vm=$root/build/vm
debs=$vm/debs
mkdir -p "$debs"
log() { printf '[vm-kernel-test %(%T)T] %s\n' -1 "$*" >&2; }
t_start=$(date +%s)

if ! command -v qemu-system-x86_64 >/dev/null; then
  log "installing qemu-system-x86"
  apt-get install -y -qq --no-install-recommends qemu-system-x86 >/dev/null
fi

# Debian bookworm's current 6.1 kernel ABI (6.1.0-N-amd64) and its package version; the
# headers, kbuild and source packages are taken at that same version.
kver=$(apt-cache depends linux-image-amd64 | sed -n 's/.*Depends: linux-image-\(6\.1\..*-amd64\)$/\1/p' | head -n1)
[ -n "$kver" ] || { echo "apt-cache: no linux-image-6.1.*-amd64 behind linux-image-amd64" >&2; exit 1; }

# --- downloads (apt-get download: never installed) ---
fetch() { # NAME [VERSION] → the .deb's path (downloaded once into build/vm/debs)
  local f
  f=$(ls "$debs"/"$1"_"${2:-}"*.deb 2>/dev/null | head -n1 || true)
  if [ -z "$f" ]; then
    (cd "$debs" && apt-get download "$1${2:+=$2}" >/dev/null 2>&1) ||
      { echo "apt-get download $1${2:+=$2} failed" >&2; exit 1; }
    f=$(ls "$debs"/"$1"_"${2:-}"*.deb | head -n1)
  fi
  echo "$f"
}
# NAME at VERSION, else the newest NAME of the same upstream version: the archive can move a
# package on by a Debian revision while the image stays (linux-kbuild-6.1 went from 6.1.192-2 to
# -3 with linux-image 6.1.192-2 still current), and within one upstream version the build tools
# and sources are the same kernel's.
fetch_same_upstream() { # NAME VERSION → the .deb's path
  local v
  if ls "$debs"/"$1"_"${2%-*}"-*.deb >/dev/null 2>&1 || ! apt-cache madison "$1" | awk '{print $3}' | grep -x "$2" >/dev/null; then
    v=$(apt-cache madison "$1" | awk -v up="${2%-*}-" 'index($3, up) == 1 {print $3; exit}')
    [ -n "$v" ] || { echo "$1: neither $2 nor another ${2%-*}-* in the archive" >&2; exit 1; }
    [ "$v" = "$2" ] || echo "$1 $2 is no longer in the archive: using $v (the same upstream version)" >&2
    fetch "$1" "$v"
  else
    fetch "$1" "$2"
  fi
}
image_deb=$(fetch linux-image-$kver)
busybox_deb=$(fetch busybox-static)
kpkg_ver=$(dpkg-deb -f "$image_deb" Version)

kernel_dir=$vm/kernel-$kver
if [ ! -f "$kernel_dir/vmlinuz" ]; then
  log "unpacking the kernel $kver ($kpkg_ver)"
  rm -rf "$kernel_dir" && mkdir -p "$kernel_dir/x"
  dpkg-deb --fsys-tarfile "$image_deb" |
    tar -x -C "$kernel_dir/x" --wildcards './boot/vmlinuz-*' '*/i2c-dev.ko' '*/i2c-stub.ko' '*/configfs.ko'
  find "$kernel_dir/x" -name '*.ko' -exec cp {} "$kernel_dir/" \;
  cp "$kernel_dir"/x/boot/vmlinuz-* "$kernel_dir/vmlinuz"
  rm -rf "$kernel_dir/x"
fi

# --- gpio-sim, out of tree (Debian does not enable CONFIG_GPIO_SIM) ---
gpio_sim=$vm/gpio-sim-$kver
if [ ! -f "$gpio_sim/gpio-sim-oot.ko" ]; then
  log "building gpio-sim against linux-headers-$kver"
  hdr=$vm/headers-$kver
  if [ ! -d "$hdr/usr/src/linux-headers-$kver" ]; then
    rm -rf "$hdr" && mkdir -p "$hdr"
    for p in linux-headers-$kver linux-headers-${kver%-amd64}-common linux-kbuild-6.1; do
      dpkg -x "$(fetch_same_upstream "$p" "$kpkg_ver")" "$hdr"
    done
    # The headers' Makefile includes the -common tree by an absolute /usr/src path.
    sed -i "s|/usr/src/|$hdr/usr/src/|" "$hdr/usr/src/linux-headers-$kver/Makefile"
  fi
  src_deb=$(fetch_same_upstream linux-source-6.1 "$kpkg_ver")
  rm -rf "$gpio_sim" && mkdir -p "$gpio_sim"
  dpkg-deb --fsys-tarfile "$src_deb" | tar -xO ./usr/src/linux-source-6.1.tar.xz | xz -d |
    tar -x -C "$gpio_sim" --strip-components=3 linux-source-6.1/drivers/gpio/gpio-sim.c \
      linux-source-6.1/drivers/gpio/gpiolib.h linux-source-6.1/kernel/irq/irq_sim.c
  # irq_to_desc() is not exported to modules; generic_handle_irq() does the same lookup.
  sed -i 's/handle_simple_irq(irq_to_desc(irqnum));/generic_handle_irq(irqnum);/' "$gpio_sim/irq_sim.c"
  grep -q 'generic_handle_irq(irqnum)' "$gpio_sim/irq_sim.c" || { echo "irq_sim.c: the patch no longer applies" >&2; exit 1; }
  printf 'obj-m := gpio-sim-oot.o\ngpio-sim-oot-y := gpio-sim.o irq_sim.o\n' >"$gpio_sim/Kbuild"
  make -s -C "$hdr/usr/src/linux-headers-$kver" M="$gpio_sim" modules >"$gpio_sim/build.log" 2>&1 ||
    { cat "$gpio_sim/build.log" >&2; exit 1; }
fi

busybox=$vm/busybox
[ -x "$busybox" ] || { dpkg-deb --fsys-tarfile "$busybox_deb" | tar -xO ./bin/busybox >"$busybox"; chmod +x "$busybox"; }
cp "$gpio_sim/gpio-sim-oot.ko" "$kernel_dir/" # one folder with every module the guests load
if [ $prepare_only = 1 ]; then
  echo "$kernel_dir"
  exit 0
fi

# --- the initramfs ---
bin=$root/$build_dir/bin
for b in gyrod gyroctl; do [ -x "$bin/$b" ] || { echo "$bin/$b missing: build gyrod and gyroctl first" >&2; exit 1; }; done
rd=$vm/initramfs
rm -rf "$rd" && mkdir -p "$rd"/{bin,sbin,etc,proc,sys,dev,tmp,run,lib/modules,usr/bin}
cp "$busybox" "$rd/bin/busybox"
for applet in $("$busybox" --list); do [ -e "$rd/bin/$applet" ] || ln -s busybox "$rd/bin/$applet"; done
gcc -static -O2 -Wall -Wextra -Werror -o "$rd/bin/vm_chip" "$root/tests/vm/vm_chip.c"
# Stripped copies: the initramfs is unpacked by an emulated CPU, every megabyte costs boot time.
strip -o "$rd/usr/bin/gyrod" "$bin/gyrod"
strip -o "$rd/usr/bin/gyroctl" "$bin/gyroctl"
# Their shared libraries, at the paths the dynamic loader looks in.
for lib in $(ldd "$bin/gyrod" "$bin/gyroctl" | awk '/=> \//{print $3} /^\t\/lib/{print $1}' | sort -u); do
  mkdir -p "$rd$(dirname "$lib")" && strip -o "$rd$lib" "$lib"
done
cp "$kernel_dir"/*.ko "$rd/lib/modules/"
cp "$root/tests/vm/init.sh" "$rd/init" && chmod +x "$rd/init"
echo 'root:x:0:0:root:/:/bin/sh' >"$rd/etc/passwd"
echo 'nobody:x:65534:65534:nobody:/:/bin/false' >>"$rd/etc/passwd"
echo 'root:x:0:' >"$rd/etc/group"
(cd "$rd" && find . | "$busybox" cpio -o -H newc 2>/dev/null | gzip -1 >"$vm/initramfs.cpio.gz")
t_built=$(date +%s)
log "initramfs $(du -h "$vm/initramfs.cpio.gz" | cut -f1), prepared in $((t_built - t_start)) s; booting (timeout ${timeout_s} s)"

# --- boot ---
console=$vm/console.log
status=0
# no_timer_check: on a busy host the emulated CPU is slow enough for the kernel's IO-APIC
# timer check to fail ("IO-APIC + timer doesn't work!", a panic); the timer does work.
# isa-debug-exit: the guest's `vm_chip exit N` ends QEMU with status 2N+1, so 1 = passed.
timeout --kill-after=10 "$timeout_s" nice -n 10 qemu-system-x86_64 -machine q35,accel=tcg -cpu max -m 512 -smp 1 \
  -kernel "$kernel_dir/vmlinuz" -initrd "$vm/initramfs.cpio.gz" \
  -append "console=ttyS0 no_timer_check panic=-1 quiet loglevel=4" \
  -nographic -nic none -no-reboot -device isa-debug-exit,iobase=0xf4,iosize=0x04 >"$console" 2>&1 || status=$?
t_end=$(date +%s)
# The guest's lines, without the firmware's terminal escapes in front of the first one.
tr -d '\r' <"$console" | grep -a -o -E '(VMTEST|CHECK) .*' || true
boot_line=$(tr -d '\r' <"$console" | grep -a -o -m1 'VMTEST booted.*' || true)
log "QEMU exit status $status; boot + checks took $((t_end - t_built)) s (${boot_line#VMTEST }); whole script $((t_end - t_start)) s"
case $status in
  1) log "PASSED"; exit 0 ;;
  124 | 137) log "FAILED: timed out after $timeout_s s (a hang); console log: $console" ;;
  *) log "FAILED; console log: $console" ;;
esac
tail -n 40 "$console" >&2
exit 1
