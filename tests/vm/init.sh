#!/bin/sh
# /init of scripts/vm-kernel-test.sh's initramfs (busybox sh, PID 1): loads i2c-dev,
# i2c-stub (chip_addr=0x68) and gpio-sim, then runs gyrod's Linux backends against
# /dev/i2c-0 and the gpio-sim line and checks what they do. One "CHECK name: PASS|FAIL
# detail" line per check; QEMU's exit status says whether all passed (vm_chip exit).
export PATH=/bin:/usr/bin
mount -t proc proc /proc
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev
mount -t tmpfs tmp /tmp && chmod 1777 /tmp
mount -t tmpfs run /run
echo "VMTEST booted in $(cut -d' ' -f1 /proc/uptime) s (kernel $(uname -r))"

passed=0
failed=0
pass() { echo "CHECK $1: PASS $2"; passed=$((passed + 1)); }
fail() { echo "CHECK $1: FAIL $2"; failed=$((failed + 1)); }
finish() {
  echo "VMTEST summary: $passed passed, $failed failed; guest uptime $(cut -d' ' -f1 /proc/uptime) s"
  sync
  vm_chip exit $((failed > 0 ? 1 : 0))
  poweroff -f
}

# --- the kernel side ---
insmod /lib/modules/configfs.ko && mount -t configfs none /sys/kernel/config &&
  insmod /lib/modules/i2c-dev.ko && insmod /lib/modules/i2c-stub.ko chip_addr=0x68 &&
  insmod /lib/modules/gpio-sim-oot.ko || { fail modules "insmod failed"; finish; }
sim=/sys/kernel/config/gpio-sim/vm
mkdir $sim $sim/bank0 && echo 4 >$sim/bank0/num_lines && echo 1 >$sim/live ||
  { fail gpio-sim "configfs setup failed"; finish; }
chip=$(cat $sim/bank0/chip_name)
pull=/sys/devices/platform/$(cat $sim/dev_name)/$chip/sim_gpio0/pull
[ -e /dev/i2c-0 ] && [ -e "/dev/$chip" ] && [ -w "$pull" ] ||
  { fail devices "/dev/i2c-0, /dev/$chip or $pull missing"; finish; }
echo "VMTEST devices: /dev/i2c-0 (i2c-stub at 0x68), /dev/$chip line 0 (gpio-sim)"
vm_chip preload /dev/i2c-0 || { fail preload "vm_chip preload failed"; finish; }
vm_chip emulate /dev/i2c-0 &

# --- helpers ---
# conf NAME BUS ADDRESS [GPIO_CHIP [DEVICE_LINES]]: /tmp/NAME.toml (bias from the config; the
# Kalman filter is identified over a still period of 200 samples, which vm_chip's constant
# frames refuse). DEVICE_LINES go into [device]: accel is on unless they say otherwise, and
# vm_chip serves the frames FIFO_EN asks for (14 bytes with accel, 8 without).
conf() {
  {
    printf '[device]\nbackend = "i2c"\nbus = %s\naddress = %s\n' "$2" "$3"
    [ -n "$5" ] && printf '%s\n' "$5"
    printf '[gpio]\nchip = "%s"\n' "$4"
    [ -n "$4" ] && printf 'line = 0\n'
    printf '[bias]\nsource = "config"\nstill_seconds = 4\n'
  } >/tmp/$1.toml
}
# start NAME: gyrod in the background on /tmp/NAME.toml; its pid in $gyrod_pid
start() {
  gyrod --config /tmp/$1.toml --socket /run/$1.sock --record "" --log-level debug >/tmp/$1.log 2>&1 &
  gyrod_pid=$!
}
stop() { kill -TERM "$1" 2>/dev/null; wait "$1" 2>/dev/null; }
# Every client call is bounded: a hang is a failure with a log, not a stuck VM.
status() { timeout 30 gyroctl status --socket /run/$1.sock --json 2>/dev/null; }
watch_json() { timeout 60 gyroctl watch --socket /run/$1.sock --json --count "$2" >"$3" 2>&1; }
# show NAME: the tail of gyrod's log and its STATUS, for a failed check
show() {
  tail -n 12 /tmp/$1.log | cut -c1-400 | sed "s/^/VMTEST | $1.log: /"
  echo "VMTEST | $1 status: $(status "$1" | cut -c1-1500)"
}
field() { sed -n "s/.*\"$1\":\"\{0,1\}\([^,\"]*\).*/\1/p"; } # a scalar field of a JSON line
samples() { status "$1" | field samples_delivered; }
# wait_samples NAME N SECONDS: until NAME has delivered N samples
wait_samples() {
  i=0
  while [ $i -lt $(($3 * 5)) ]; do
    s=$(samples "$1")
    [ -n "$s" ] && [ "$s" -ge "$2" ] && return 0
    sleep 0.2
    i=$((i + 1))
  done
  return 1
}
uptime_s() { cut -d' ' -f1 /proc/uptime; }
# rate NAME SECONDS: samples delivered per second over about SECONDS (timed by the kernel's
# clock: under TCG a gyroctl call itself takes a noticeable fraction of a second)
rate() {
  a=$(samples "$1")
  ta=$(uptime_s)
  sleep "$2"
  b=$(samples "$1")
  tb=$(uptime_s)
  awk "BEGIN{printf \"%d\", (${b:-0} - ${a:-0}) / ($tb - $ta)}"
}
# run_to_exit NAME [CMD PREFIX...]: gyrod in the foreground (20 s at most); its exit status in $code
run_to_exit() {
  name=$1
  shift
  timeout 20 "$@" gyrod --config /tmp/$name.toml --socket /tmp/$name.sock --record "" >/tmp/$name.log 2>&1
  code=$?
}
has() { grep -q -- "$2" /tmp/$1.log; }
logline() { grep -m1 -- "$2" /tmp/$1.log | cut -c1-300; }

t0=$(uptime_s)

# --- SMBus only: what gyrod must cope with on this adapter ---
if out=$(vm_chip rdwr /dev/i2c-0); then pass smbus-only "$out"; else fail smbus-only "$out"; fi

# --- probe, register table, exact values (no INT line: polling) ---
# read_table REG...: the registers' bytes as (busybox's) i2cget reads them now
read_table() {
  t=""
  for reg in "$@"; do t="$t $(i2cget -y 0 0x68 "$reg")"; done
  echo "$t"
}
table_names="PWR_MGMT_1 PWR_MGMT_2 SMPLRT_DIV CONFIG GYRO_CONFIG ACCEL_CONFIG INT_ENABLE FIFO_EN USER_CTRL"
# poll_run NAME FRAME_BYTES WANT_TABLE WANT_RATE DETAIL: gyrod without an INT line on
# /tmp/NAME.toml; the probe (first run only), the register table read back after one Configure
# pass, and 5 RATE lines that must all contain WANT_RATE exactly (the frame vm_chip preloaded).
poll_run() {
  start "$1"
  run_pid=$gyrod_pid
  if wait_samples "$1" 5 60; then
    st=$(status "$1")
    if [ "$1" = poll ]; then
      if has poll "looking for the MPU6050 at 0x68 on /dev/i2c-0" && has poll "streaming from the MPU6050 at 0x68" &&
        [ "$(echo "$st" | field device_state)" = streaming ]; then
        pass probe "$(logline poll 'streaming from')"
      else
        fail probe "$(tail -n 5 /tmp/poll.log)"
      fi
    fi
    # One Configure pass means StartFifo read the whole table back without a mismatch.
    configures=$(echo "$st" | field configures)
    table=$(read_table 0x6b 0x6c 0x19 0x1a 0x1b 0x1c 0x38 0x23 0x6a)
    if [ "$configures" = 1 ] && [ "$table" = "$3" ]; then
      pass "register-table-$2" "configures=1; $table_names =$table"
    else
      fail "register-table-$2" "configures=$configures; read$table; want$3"
    fi
    watch_json "$1" 5 "/tmp/$1-watch.json"
    n=$(grep -c '"class":"RATE"' "/tmp/$1-watch.json")
    exact=$(grep '"class":"RATE"' "/tmp/$1-watch.json" | grep -c -F "$4")
    # A burst of the wrong frame size fails gyrod's temperature check: misaligned_bursts.
    misaligned=$(status "$1" | field misaligned_bursts)
    if [ "$n" = 5 ] && [ "$exact" = 5 ] && [ "$misaligned" = 0 ]; then
      pass "exact-values-$2" "5 of 5 RATE lines ($2-byte frames): $5; misaligned_bursts=0"
    else
      fail "exact-values-$2" "$exact of $n exact, misaligned_bursts=$misaligned; want $4: $(grep -m1 RATE "/tmp/$1-watch.json" | cut -c1-400)"
      show "$1"
    fi
  else
    fail "probe-$2" "no samples in 60 s: $(tail -n 5 /tmp/$1.log)"
  fi
  stop $run_pid
}

# gyrod's default: accel on, here at +-8 g (AFS_SEL 2, 4096 LSB/g): 14-byte frames, FIFO_EN
# 0xF8, ACCEL_CONFIG 0x10, PWR_MGMT_2 0 (no axis in standby). vm_chip's 14-byte frame: accel
# 32616, -6144, -32768 LSB = 7.962890625, -1.5, -8 g (near and at full scale, negative words
# sign-extended); gyro -393, 32750, -32750 LSB = -3, 250, -250 deg/s at 131 LSB/(deg/s); TEMP
# -1944 LSB = 30.81235294117647 deg C.
conf poll 0 0x68 "" "accel_range_g = 8"
poll_run poll 14 " 0x01 0x00 0x13 0x04 0x00 0x10 0x11 0xf8 0x40" \
  '"temp":30.81235294117647,"raw":[-3,250,-250],' \
  'temp 30.81235294117647, raw [-3,250,-250] deg/s, accel [7.962890625,-1.5,-8] g'
# The accel fields of the same lines (after the gyro streams and "time").
exact=$(grep '"class":"RATE"' /tmp/poll-watch.json | grep -c -F '"accel":[7.962890625,-1.5,-8],')
if [ "$exact" = 5 ]; then
  pass exact-accel-14 "5 of 5 RATE lines: accel [7.962890625,-1.5,-8] g at AFS_SEL 2"
else
  fail exact-accel-14 "$exact of 5 with accel [7.962890625,-1.5,-8]: $(grep -m1 RATE /tmp/poll-watch.json | cut -c1-400)"
fi

# accel = false: the gyro-only driver's table (ACCEL_CONFIG neither written nor checked: it
# keeps the 0x10 of the run before), FIFO_EN 0xF0, and vm_chip's 8-byte frame: 131, -262,
# 655 LSB = 1, -2, 5 deg/s; no accel field.
conf poll8 0 0x68 "" "accel = false"
poll_run poll8 8 " 0x01 0x00 0x13 0x04 0x00 0x10 0x11 0xf0 0x40" \
  '"temp":30.81235294117647,"raw":[1,-2,5],' 'temp 30.81235294117647, raw [1,-2,5] deg/s, no accel'
if [ -s /tmp/poll8-watch.json ] && ! grep -q '"accel' /tmp/poll8-watch.json; then
  pass no-accel-8 "no accel or accel_ms2 field in the RATE lines"
else
  fail no-accel-8 "an accel field without accel (or no lines): $(grep -m1 RATE /tmp/poll8-watch.json | cut -c1-400)"
fi

# --- edges through libgpiod and the epoll loop ---
conf gpio 0 0x68 "$chip"
vm_chip edges "$pull" 1000000 20000 &
edges_pid=$!
start gpio
gpio_pid=$gyrod_pid
if wait_samples gpio 20 60; then
  m0=$(status gpio | field data_ready_missed)
  s0=$(samples gpio)
  r=$(rate gpio 4)
  m1=$(status gpio | field data_ready_missed)
  s1=$(samples gpio)
  # One frame per wake-up (vm_chip holds FIFO_COUNT at one 14-byte frame): ~50/s on edges, at most ~11/s from
  # the watchdog alone (every 88 ms). On a loaded host the guest's edges come late and the
  # watchdog takes a few: most samples must still have been announced by an edge.
  watchdog=$((m1 - m0))
  delivered=$((s1 - s0))
  if [ "$r" -ge 15 ] && [ $((watchdog * 4)) -lt "$delivered" ]; then
    pass edges "$r samples/s on 50 Hz edges; $watchdog of $delivered read by the watchdog"
  else
    fail edges "$r samples/s on 50 Hz edges (want >= 15); $watchdog of $delivered read by the watchdog (want < 1/4)"
    show gpio
  fi
  # The timestamps come from the kernel's edge stamps through the sample clock: 20 ms per
  # sequence step (a sample refused with a still period leaves a hole in seq). They never
  # go back; the median step is the period (on a loaded host the guest's edges come late
  # and the clock re-anchors now and then, so single steps may be off).
  watch_json gpio 41 /tmp/gpio-watch.json
  steps=$(sed -n 's/.*"class":"RATE","seq":\([0-9]*\),"t":\([0-9.]*\).*/\1 \2/p' /tmp/gpio-watch.json |
    awk 'NR > 1 { printf "%.9f\n", ($2 - p) / ($1 - q) } { q = $1; p = $2 }' | sort -n |
    awk '{ d[NR] = $1 } END { m = d[int((NR + 1) / 2)]; printf "%d steps: min %.4f, median %.4f, max %.4f s", NR, d[1], m, d[NR]
         exit !(NR == 40 && d[1] >= 0 && m > 0.018 && m < 0.022) }')
  if [ $? -eq 0 ]; then pass edge-timestamps "$steps (50 Hz)"; else
    fail edge-timestamps "$steps (want 40 steps, none back in time, median 0.018 .. 0.022 s)"
    show gpio
  fi

  # The same line requested twice: the second gyrod must stop with a clear message.
  conf busy 0 0x68 "$chip"
  run_to_exit busy
  if [ $code -ne 0 ] && [ $code -ne 124 ] && has busy "is already in use"; then
    pass busy-line "exit $code: $(logline busy 'already in use')"
  else
    fail busy-line "exit $code: $(tail -n 3 /tmp/busy.log)"
  fi

  kill $edges_pid
  wait $edges_pid 2>/dev/null
  # A burst: 500 edges at 5 kHz, far faster than the sample clock allows.
  before=$(samples gpio)
  vm_chip edges "$pull" 500 200
  sleep 2
  after=$(samples gpio)
  st=$(status gpio)
  if kill -0 $gpio_pid 2>/dev/null && [ "$(echo "$st" | field device_state)" = streaming ] && [ "$after" -gt "$before" ]; then
    pass edge-burst "still streaming ($before -> $after samples), timestamp_rejections=$(echo "$st" | field timestamp_rejections)"
  else
    fail edge-burst "pid alive? $(kill -0 $gpio_pid 2>/dev/null && echo yes || echo no); $before -> $after samples; $(tail -n 3 /tmp/gpio.log)"
    show gpio
  fi

  # No edges at all (a stuck INT): the watchdog reads the FIFO on its own.
  m0=$(status gpio | field data_ready_missed)
  r=$(rate gpio 4)
  m1=$(status gpio | field data_ready_missed)
  if [ "$r" -ge 3 ] && [ "$r" -lt 35 ] && [ "$m1" -gt "$m0" ] && has gpio "no data-ready edge came"; then
    pass no-edges "$r samples/s from the watchdog, data_ready_missed $m0 -> $m1: $(logline gpio 'no data-ready edge')"
  else
    fail no-edges "$r samples/s, data_ready_missed $m0 -> $m1"
    show gpio
  fi

  # vm_chip's frames never change: each still period is refused once (zero variance) and
  # starts again, and no other sample is skipped (it used to refuse every sample after it).
  n=$(samples gpio)
  refused=$(grep -c "cannot identify the filter" /tmp/gpio.log)
  other=$(grep "skipped" /tmp/gpio.log | grep -vc "cannot identify the filter")
  if [ "$refused" -ge 1 ] && [ "$refused" -le $((n / 200 + 1)) ] && [ "$other" = 0 ]; then
    pass constant-signal "$refused still periods of 200 refused in $n samples: $(logline gpio 'cannot identify' | cut -c1-160)"
  else
    fail constant-signal "$refused refused, $other other skipped samples in $n"
    show gpio
  fi
else
  fail edges "no samples in 60 s: $(tail -n 5 /tmp/gpio.log)"
  kill $edges_pid
fi
stop $gpio_pid

# --- the error messages ---
conf nodev 0 0x69
start nodev
nodev_pid=$gyrod_pid
sleep 4
stop $nodev_pid
if has nodev "0x69 on /dev/i2c-0" && has nodev "ENODEV"; then pass enodev "$(logline nodev ENODEV)"; else
  fail enodev "$(tail -n 3 /tmp/nodev.log)"
fi

conf nobus 7 0x68
run_to_exit nobus
if [ $code -ne 0 ] && [ $code -ne 124 ] && has nobus "/dev/i2c-7 does not exist"; then
  pass missing-bus "exit $code: $(logline nobus 'does not exist')"
else
  fail missing-bus "exit $code: $(tail -n 3 /tmp/nobus.log)"
fi

conf notadapter '"/dev/null"' 0x68
run_to_exit notadapter
if [ $code -ne 0 ] && [ $code -ne 124 ] && has notadapter "is not an I2C adapter"; then
  pass not-an-adapter "exit $code: $(logline notadapter 'not an I2C adapter')"
else
  fail not-an-adapter "exit $code: $(tail -n 3 /tmp/notadapter.log)"
fi

conf nonroot 0 0x68
chmod 644 /tmp/nonroot.toml
run_to_exit nonroot vm_chip asuser 65534
if [ $code -ne 0 ] && [ $code -ne 124 ] && has nonroot "permission denied opening /dev/i2c-0"; then
  pass non-root "exit $code: $(logline nonroot 'permission denied')"
else
  fail non-root "exit $code: $(tail -n 3 /tmp/nonroot.log)"
fi

t1=$(uptime_s)
echo "VMTEST checks took $(awk "BEGIN{print $t1 - $t0}") s"
finish
