#!/bin/bash
# The checks of scripts/vm-systemd-test.sh, run by vm-checks.service in the guest (systemd is
# PID 1; i2c-stub at 0x68 is kept alive by vm-chip-emulate.service). One "CHECK name:
# PASS|FAIL detail" line each; QEMU's exit status says whether all passed (vm_chip exit).
export PATH=/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin
passed=0
failed=0
pass() { echo "CHECK $1: PASS $2"; passed=$((passed + 1)); }
fail() { echo "CHECK $1: FAIL $2"; failed=$((failed + 1)); }
uptime_s() { cut -d' ' -f1 /proc/uptime; }
since() { awk "BEGIN{printf \"%.1f\", $(uptime_s) - $1}"; }
prop() { systemctl show -p "$2" --value "$1"; }
journal() { journalctl -b -o cat --no-pager -u "$1"; }
# wait_for SECONDS COMMAND...: until COMMAND succeeds
wait_for() {
  local end=$(($(date +%s) + $1))
  shift
  until "$@"; do
    [ "$(date +%s)" -lt $end ] || return 1
    sleep 0.5
  done
}
show() {
  journal gyrod.service | tail -n 10 | cut -c1-300 | sed 's/^/VMTEST | gyrod: /'
  systemctl status --no-pager gyrod.service 2>&1 | head -n 12 | sed 's/^/VMTEST | /'
}
sock=/run/gyrod/gyrod.sock

echo "VMTEST booted: systemd reached vm-checks.service in $(uptime_s) s; $(systemctl --version | head -n1); gyrod from $VM_INSTALLED"
t0=$(uptime_s)

# Type=notify: `systemctl start` returns once gyrod has sent READY=1 (device streaming, socket up).
t=$(uptime_s)
if timeout 120 systemctl start gyrod.service; then
  state="$(prop gyrod.service ActiveState)/$(prop gyrod.service SubState)"
  if [ "$(prop gyrod.service Type)" = notify ] && [ "$state" = active/running ] &&
    journal gyrod.service | grep -q "socket listening: ready"; then
    pass notify-ready "ready after $(since "$t") s ($state, StatusText \"$(prop gyrod.service StatusText)\")"
  else
    fail notify-ready "$state"
    show
  fi
else
  fail notify-ready "systemctl start gyrod.service failed after $(since "$t") s"
  show
fi
pid=$(prop gyrod.service MainPID)

if journal gyrod.service | grep -q "streaming from the MPU6050 at 0x68 on /dev/i2c-0"; then
  pass journal "$(journal gyrod.service | grep -m1 'streaming from' | cut -c1-200)"
else
  fail journal "no 'streaming from' line"
  show
fi

if status=$(timeout 30 gyroctl status --socket $sock --json) && echo "$status" | grep -q '"device_state":"streaming"'; then
  pass client "gyroctl status on $sock: streaming, $(echo "$status" | grep -o '"samples":[0-9]*')"
else
  fail client "gyroctl status on $sock: $status"
fi

# The default configuration's 14-byte frames (accel on, +-2 g: AFS_SEL 0, 16384 LSB/g) through
# the real kernel's SMBus, exactly as vm_chip preloaded them: gyro -393, 32750, -32750 LSB at
# 131 LSB/(deg/s); accel 32616, -6144, -32768 LSB; TEMP -1944 LSB.
want_raw='"temp":30.81235294117647,"raw":[-3,250,-250],'
want_accel='"accel":[1.99072265625,-0.375,-2],'
timeout 60 gyroctl watch --socket $sock --json --count 5 >/tmp/watch.json 2>&1
n=$(grep -c '"class":"RATE"' /tmp/watch.json)
exact=$(grep '"class":"RATE"' /tmp/watch.json | grep -F "$want_raw" | grep -c -F "$want_accel")
if [ "$n" = 5 ] && [ "$exact" = 5 ]; then
  pass exact-values-14 "5 of 5 RATE lines: temp 30.81235294117647, raw [-3,250,-250] deg/s, accel [1.99072265625,-0.375,-2] g"
else
  fail exact-values-14 "$exact of $n exact: $(grep -m1 RATE /tmp/watch.json | cut -c1-400)"
fi

# CPUSchedulingPolicy=fifo is applied by systemd before RestrictRealtime=yes takes effect.
policy=$(chrt -p "$pid" 2>&1 | tr '\n' ' ')
if echo "$policy" | grep -q "SCHED_FIFO" && echo "$policy" | grep -q "priority: 10"; then
  pass sched-fifo "$policy(RestrictRealtime=$(prop gyrod.service RestrictRealtime))"
else
  fail sched-fifo "$policy"
fi

# The sandbox, seen from outside the process.
st=/proc/$pid/status
uid=$(awk '/^Uid:/ {print $2}' $st)
sandbox="user $(id -nu "$uid" 2>/dev/null || echo "$uid"); $(grep -E '^(NoNewPrivs|Seccomp|CapEff):' $st | tr '\t\n' '  ')"
root_ro=no
grep -qE '^[0-9]+ [0-9]+ [^ ]+ / / ro[, ]' /proc/$pid/mountinfo && root_ro=yes
own_net=no
[ "$(readlink /proc/$pid/ns/net)" != "$(readlink /proc/1/ns/net)" ] && own_net=yes
if [ "$(id -nu "$uid")" = gyrod ] && grep -qP '^NoNewPrivs:\t1' $st && grep -qP '^Seccomp:\t2' $st &&
  grep -qP '^CapEff:\t0+$' $st && [ $root_ro = yes ] && [ $own_net = yes ]; then
  pass sandbox "$sandbox/ read-only: $root_ro; own network namespace: $own_net"
else
  fail sandbox "$sandbox/ read-only: $root_ro; own network namespace: $own_net"
fi

# systemctl reload: SIGHUP, which re-reads the filter section.
n_before=$(journal gyrod.service | grep -c "SIGHUP")
if out=$(timeout 30 systemctl reload gyrod.service 2>&1) &&
  wait_for 20 sh -c "[ \$(journalctl -b -o cat --no-pager -u gyrod.service | grep -c SIGHUP) -gt $n_before ]"; then
  pass reload "$(journal gyrod.service | grep SIGHUP | tail -n1 | cut -c1-200); still PID $(prop gyrod.service MainPID)"
else
  fail reload "systemctl reload: $out (ExecReload=$(prop gyrod.service ExecReload))"
fi

# The watchdog: the chip stops producing samples (FIFO_COUNT 0), gyrod stops sending
# WATCHDOG=1 once its newest sample is WatchdogSec old, and systemd kills and restarts it
# WatchdogSec later (Restart=on-failure): about 2 x WatchdogSec after the last sample.
restarts=$(prop gyrod.service NRestarts)
t=$(uptime_s)
systemctl stop vm-chip-emulate.service
vm_chip silence /dev/i2c-0
if wait_for 60 sh -c "[ \$(systemctl show -p NRestarts --value gyrod.service) -gt $restarts ]"; then
  after=$(since "$t")
  systemctl start vm-chip-emulate.service
  if wait_for 120 sh -c '[ "$(systemctl is-active gyrod.service)" = active ]' &&
    journalctl -b -o cat --no-pager | grep -q "gyrod.service: Watchdog timeout"; then
    pass watchdog "restarted $after s after the samples stopped (WatchdogSec=$(prop gyrod.service WatchdogUSec)): $(journalctl -b -o cat --no-pager | grep -m1 'Watchdog timeout'); active again, NRestarts=$(prop gyrod.service NRestarts)"
  else
    fail watchdog "restarted, but not active again or no 'Watchdog timeout' in the journal"
    show
  fi
else
  fail watchdog "no restart within 60 s"
  systemctl start vm-chip-emulate.service
  show
fi

# Socket activation: with gyrod stopped and gyrod.socket listening, a client starts it.
systemctl stop gyrod.service
if timeout 30 systemctl start gyrod.socket && [ "$(systemctl is-active gyrod.service)" = inactive ]; then
  t=$(uptime_s)
  # gyrod answers the client that started it before it reports READY=1 (the unit is still
  # "activating"), and the journal may get its line after the client its reply: both waited
  # for, not raced.
  if status=$(timeout 120 gyroctl status --socket $sock --json) &&
    wait_for 30 sh -c '[ "$(systemctl is-active gyrod.service)" = active ]' &&
    wait_for 30 sh -c 'journalctl -b -o cat --no-pager -u gyrod.service | grep -q "using the socket passed by systemd"'; then
    pass socket-activation "gyroctl status started gyrod in $(since "$t") s: $(journal gyrod.service | grep 'socket passed by systemd' | tail -n1 | cut -c1-120); $(stat -c '%U:%G %a' $sock)"
  else
    fail socket-activation "gyroctl status: ${status:0:200}; gyrod.service $(systemctl is-active gyrod.service)"
    show
  fi
else
  fail socket-activation "gyrod.socket did not start, or gyrod.service ran without a client"
fi

# systemd's own reading of the unit's sandbox.
exposure=$(systemd-analyze security gyrod.service 2>&1 | grep -a "Overall exposure level" | tr -d '\033' | cut -c1-120)
level=$(echo "$exposure" | sed -n 's/.*: \([0-9.]*\) \([A-Z]*\).*/\1 \2/p')
case "${level#* }" in
  SAFE | OK) pass security "$exposure" ;;
  *) fail security "${exposure:-no exposure line} (want SAFE or OK)" ;;
esac

# MQTT from the installed unit (docs/fleet.md): its sandbox has no network, and gyrod says so;
# with the package's drop-in (/usr/share/gyrod/gyrod-mqtt.conf) it reaches the board's broker,
# and gyroctl fleet shows it online.
cp /etc/gyrod/gyrod.toml /tmp/gyrod.toml.orig
if grep -q '^\[mqtt\]$' /etc/gyrod/gyrod.toml; then
  sed -i 's|^\[mqtt\]$|[mqtt]\nurl = "mqtt://127.0.0.1:1883"|' /etc/gyrod/gyrod.toml
else
  printf '[mqtt]\nurl = "mqtt://127.0.0.1:1883"\n' >>/etc/gyrod/gyrod.toml
fi
systemctl start mosquitto.service 2>/dev/null || mosquitto -d -p 1883
n_before=$(journal gyrod.service | grep -c "MQTT: this gyrod may not open IP sockets")
timeout 120 systemctl restart gyrod.service
if wait_for 30 sh -c "[ \$(journalctl -b -o cat --no-pager -u gyrod.service | grep -c 'MQTT: this gyrod may not open IP sockets') -gt $n_before ]"; then
  sandboxed="$(journal gyrod.service | grep 'MQTT: this gyrod' | tail -n1 | cut -c1-120)"
  install -D -m 644 /usr/share/gyrod/gyrod-mqtt.conf /etc/systemd/system/gyrod.service.d/mqtt.conf
  systemctl daemon-reload
  timeout 120 systemctl restart gyrod.service
  fleet=""
  wait_for 30 sh -c 'gyroctl fleet --broker mqtt://127.0.0.1 --once --json --wait 2 >/tmp/fleet.json 2>&1 && grep -q "\"state\":\"online\"" /tmp/fleet.json && grep -q "\"rate_messages\":[1-9]" /tmp/fleet.json' &&
    fleet=$(cut -c1-200 /tmp/fleet.json)
  if [ -n "$fleet" ]; then
    pass mqtt-drop-in "in the sandbox: $sandboxed; with the drop-in: $fleet"
  else
    fail mqtt-drop-in "with the drop-in: $(cut -c1-300 /tmp/fleet.json)"
    show
  fi
  rm -f /etc/systemd/system/gyrod.service.d/mqtt.conf
else
  fail mqtt-drop-in "no 'MQTT: this gyrod may not open IP sockets' line in the sandbox"
  show
fi
cp /tmp/gyrod.toml.orig /etc/gyrod/gyrod.toml
systemctl daemon-reload
timeout 120 systemctl restart gyrod.service

echo "VMTEST checks took $(since "$t0") s"
echo "VMTEST summary: $passed passed, $failed failed; guest uptime $(uptime_s) s"
sync
vm_chip exit $((failed > 0 ? 1 : 0))
