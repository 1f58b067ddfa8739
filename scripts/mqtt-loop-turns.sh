#!/usr/bin/env bash
# gyrod's longest sample-loop turn with its MQTT broker up, down (a closed port), unreachable
# (an address that never answers) and stopped for 5 s then restarted mid-stream (qos 1): the
# publisher's thread must keep the network off the sample loop in each (docs/fleet.md).
# Each run: the mock at 1 kHz with accel, real time, SECONDS long (default 20), as root
# SCHED_FIFO when allowed. usage: scripts/mqtt-loop-turns.sh [SECONDS]   (after scripts/test.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-20}
gyrod=build/bin/gyrod
dir=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$dir"' EXIT
port=$((20000 + RANDOM % 20000))
chrt_cmd=()
chrt -f 10 true 2>/dev/null && chrt_cmd=(chrt -f 10)

run() {  # NAME URL [restart]
  local name=$1 url=$2
  cat >"$dir/$name.toml" <<CONF
[device]
backend = "mock"
rate_hz = 1000
dlpf = 1
[socket]
path = "$dir/$name.sock"
[mqtt]
url = "$url"
prefix = "turns/$name"
client_id = "turns-$name"
qos = 1
CONF
  "${chrt_cmd[@]}" "$gyrod" --config "$dir/$name.toml" >"$dir/$name.log" 2>&1 &
  local pid=$!
  if [ "${3:-}" = restart ]; then
    sleep $((seconds / 2))
    kill "$broker"
    wait "$broker" 2>/dev/null || true
    sleep 5
    mosquitto -p "$port" >/dev/null 2>&1 &
    broker=$!
    sleep $((seconds / 2 - 5))
  else
    sleep "$seconds"
  fi
  kill -TERM "$pid"
  wait "$pid" || true
  local stop
  stop=$(grep -o 'stopped after.*' "$dir/$name.log" | head -n1)
  printf '%-12s %s\n' "$name" "$stop"
}

mosquitto -p "$port" >/dev/null 2>&1 &
broker=$!
sleep 0.5
echo "gyrod $(git describe --always --dirty 2>/dev/null || echo '?'), ${seconds} s each, load $(cut -d' ' -f1-3 /proc/loadavg), ${chrt_cmd[*]:-SCHED_OTHER}"
run up "mqtt://127.0.0.1:$port"
run restarted "mqtt://127.0.0.1:$port" restart
kill "$broker"
wait "$broker" 2>/dev/null || true
run down "mqtt://127.0.0.1:$port"
run unreachable "mqtt://10.255.255.1:1883"
