#!/usr/bin/env bash
# Bounded libFuzzer runs of every fuzz target (fuzz/, docs/testing.md "Fuzzing").
# Usage: scripts/fuzz.sh [SECONDS_PER_TARGET]   (default 45)
# Configures build-fuzz with clang (GYROD_FUZZ=ON: ASan + UBSan + libFuzzer), builds the
# targets, runs each on a copy of its seed corpus (the tree's corpus never grows), prints the
# executions, exec/s and coverage per target, and exits non-zero on any crash, leak, timeout
# or out-of-memory, leaving the input in build-fuzz/fuzz-artifacts/TARGET/.
# Environment: FUZZ_JOBS (build jobs, default 2), FUZZ_PARALLEL (targets fuzzed at once, each on
# one core; default the number of cores), FUZZ_TARGETS (space-separated subset).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-45}
[[ $seconds =~ ^[1-9][0-9]*$ ]] || { echo "fuzz: SECONDS_PER_TARGET must be a positive integer (got '$seconds')" >&2; exit 2; }
command -v clang++ >/dev/null || { echo "fuzz: clang++ is not installed (apt-get install clang libclang-rt-14-dev)" >&2; exit 2; }

build=build-fuzz
start=$(date +%s)
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
generator=()
[ -f "$build/CMakeCache.txt" ] || ! command -v ninja >/dev/null || generator=(-G Ninja)
mkdir -p "$build"
nice -n 10 cmake -S . -B "$build" "${generator[@]}" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGYROD_FUZZ=ON \
  -DGYROD_BUILD_TESTS=OFF -DGYROD_BUILD_BENCHMARKS=OFF "${launcher[@]}" >"$build/configure.log" 2>&1 ||
  { cat "$build/configure.log" >&2; echo "fuzz: cmake configure failed" >&2; exit 2; }
nice -n 10 cmake --build "$build" -j "${FUZZ_JOBS:-2}" --target gyrod_fuzzers
built=$(date +%s)

# The longest input per target: a request line is bounded by the server
# (protocol::kMaxRequestLineBytes); the files get room for a few times their seeds.
declare -A max_len=([recording_csv]=4096 [import_imucal]=4096 [config]=16384 [model_toml]=8192 [request]=4096)
targets=${FUZZ_TARGETS:-recording_csv import_imucal config model_toml request}

run_dir=$build/fuzz-run
artifacts=$build/fuzz-artifacts
rm -rf "$run_dir"
mkdir -p "$run_dir"
for target in $targets; do
  [[ -n ${max_len[$target]+x} ]] || { echo "fuzz: unknown target '$target'" >&2; exit 2; }
done

# One target's run; its exit status is in $run_dir/TARGET.status.
fuzz_one() {
  local target=$1 corpus=$run_dir/$1/corpus log=$run_dir/$1.log dict=()
  mkdir -p "$corpus" "$artifacts/$target"
  cp fuzz/corpus/"$target"/* "$corpus"/
  [[ -f fuzz/$target.dict ]] && dict=(-dict="fuzz/$target.dict")
  echo "fuzz: $target for ${seconds}s (log $log)"
  # Leaks are found by ASan's LeakSanitizer at each input's end (-detect_leaks=1, the default).
  local status=0
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 nice -n 10 "$build/bin/fuzz_$target" \
    -max_total_time="$seconds" -max_len="${max_len[$target]}" -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$artifacts/$target/" "${dict[@]}" "$corpus" </dev/null >"$log" 2>&1 ||
    status=$?
  echo "$status" >"$run_dir/$target.status"
}

# Each libFuzzer process uses one core: FUZZ_PARALLEL of them at a time.
parallel=${FUZZ_PARALLEL:-$(nproc)}
[[ $parallel =~ ^[1-9][0-9]*$ ]] || { echo "fuzz: FUZZ_PARALLEL must be a positive integer (got '$parallel')" >&2; exit 2; }
running=0
for target in $targets; do
  if ((running >= parallel)); then
    wait -n
    running=$((running - 1))
  fi
  fuzz_one "$target" &
  running=$((running + 1))
done
wait

failed=()
rows=()
for target in $targets; do
  log=$run_dir/$target.log
  status=ok
  if [[ $(cat "$run_dir/$target.status" 2>/dev/null) != 0 ]]; then
    status=FAILED
    failed+=("$target")
    echo "fuzz: $target FAILED; the end of its log:" >&2
    tail -n 40 "$log" >&2
    echo "fuzz: the input is in $artifacts/$target/ (replay: $build/bin/fuzz_$target FILE)" >&2
  fi
  final=$(grep -E '^#[0-9]+.*cov: ' "$log" | tail -n 1 || true)
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$final")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$final")
  corp=$(sed -n 's/.* corp: \([0-9]*\)\/.*/\1/p' <<<"$final")
  rows+=("$(printf '%-14s %-7s %12s %9s %7s %7s %7s' "$target" "$status" "${execs:--}" "${rate:--}" "${cov:--}" \
    "${ft:--}" "${corp:--}")")
done

end=$(date +%s)
printf '%-14s %-7s %12s %9s %7s %7s %7s\n' target status executions exec/s cov ft corpus
printf '%s\n' "${rows[@]}"
echo "fuzz: build $((built - start)) s, runs $((end - built)) s, total $((end - start)) s"
if ((${#failed[@]})); then
  echo "fuzz: FAILED: ${failed[*]} (inputs in $artifacts/; keep each as fuzz/regressions/TARGET/NAME with its fix)" >&2
  exit 1
fi
