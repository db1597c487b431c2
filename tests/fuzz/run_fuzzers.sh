#!/usr/bin/env bash
# Builds the libFuzzer targets (build-fuzz, clang, if needed) and runs each for DURATION_S seconds on its
# seed corpus. Any crash, leak, sanitizer report or input taking over 1 s fails the run: the script exits
# non-zero and names the targets, whose reproducers are left in build-fuzz/findings/<target>/.
# Usage: tests/fuzz/run_fuzzers.sh DURATION_S [TARGET...]   (FUZZ_BUILD_DIR overrides build-fuzz)
set -euo pipefail
cd "$(dirname "$0")/../.."

if [[ $# -lt 1 || ! $1 =~ ^[0-9]+$ ]]; then
  echo "usage: $0 DURATION_S [TARGET...]" >&2
  exit 2
fi
duration=$1
shift
targets=("$@")
if ((${#targets[@]} == 0)); then
  targets=(fuzz_mesh_obj fuzz_mesh_off fuzz_mesh_stl fuzz_mesh_ply fuzz_mesh_gltf fuzz_mesh_glb fuzz_measurements_csv)
fi
build=${FUZZ_BUILD_DIR:-build-fuzz}

if ! command -v clang++ >/dev/null 2>&1; then
  echo "run_fuzzers: clang++ not found (deploy/install-deps.sh installs clang and libclang-rt-14-dev)" >&2
  exit 1
fi
if [[ ! -f "$build/build.ninja" ]]; then
  launcher=()
  if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBALLOON_BUILD_FUZZ=ON \
    "${launcher[@]}" >/dev/null
fi
cmake --build "$build" -j"$(nproc)" --target balloon_fuzz

# Fresh seeds from tests/data each run; what a run discovers is kept in corpus/ for the next one.
rm -rf "$build/seeds"
"$build/tests/fuzz/make_fuzz_seeds" tests/data "$build/seeds"

# True if the run's only finding is a timeout whose input runs within the 1 s limit twice on replay.
replay_in_time() {
  local target=$1 findings=$2 unit
  unit=$(ls "$findings"/timeout-* 2>/dev/null | head -1)
  [[ -n $unit && $(ls "$findings" | wc -l) -eq 1 ]] || return 1
  for _ in 1 2; do
    timeout -k 5 30 "$build/tests/fuzz/$target" -timeout=1 -runs=1 "$unit" >/dev/null 2>&1 || return 1
  done
}

failed=()
for target in "${targets[@]}"; do
  corpus="$build/corpus/$target"
  findings="$build/findings/$target"
  rm -rf "$findings"  # only this run's findings
  mkdir -p "$corpus" "$findings"
  log="$build/findings/$target.log"
  echo "run_fuzzers: $target for ${duration} s"
  # -timeout=1: an input over 1 s is a finding; -rss_limit_mb: a reader that allocates 2 GB is one too.
  # detect_leaks is on by default under ASan; -error_exitcode makes every finding the same non-zero.
  # The outer timeout: libFuzzer's own timeout handler can deadlock while it reports (seen with ASan).
  # A fixed -seed (FUZZ_SEED, default 1) and a cap on executions (FUZZ_MAX_RUNS, default 20000) make a run
  # from the fresh seeds replay the same mutations, stopping at the cap or at DURATION_S, whichever comes
  # first: CI's run is a prefix of one checked here with a longer DURATION_S, not a new lottery.
  if timeout -k 10 $((duration + 120)) "$build/tests/fuzz/$target" -seed="${FUZZ_SEED:-1}" -runs="${FUZZ_MAX_RUNS:-20000}" \
      -max_total_time="$duration" -timeout=1 -rss_limit_mb=2048 \
      -error_exitcode=77 -timeout_exitcode=78 -artifact_prefix="$findings/" -print_final_stats=1 \
      "$corpus" "$build/seeds/$target" >"$log" 2>&1; then
    grep -E '^stat::number_of_executed_units|^#[0-9]+.*DONE' "$log" | tail -2 | sed "s/^/  /"
  elif replay_in_time "$target" "$findings"; then
    # A shared machine can stall any input for a second; the input itself replayed in time.
    echo "run_fuzzers: $target: a timeout that did not reproduce (machine load), not counted"
  else
    echo "run_fuzzers: $target FAILED (log $log, reproducer in $findings/):" >&2
    grep -E 'ERROR|SUMMARY|Test unit written|runtime error' "$log" | head -8 | sed "s/^/  /" >&2
    failed+=("$target")
  fi
done

if ((${#failed[@]} > 0)); then
  echo "run_fuzzers: ${#failed[@]} of ${#targets[@]} targets failed: ${failed[*]}" >&2
  exit 1
fi
echo "run_fuzzers: ${#targets[@]} targets ran ${duration} s each with no crash, leak or timeout"
