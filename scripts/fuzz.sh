#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (AddressSanitizer + UndefinedBehaviorSanitizer) in build-fuzz and runs
# each for SECONDS (default 60) from its committed seed corpus tests/fuzz/corpus/<target>/. New inputs the
# fuzzer finds go to build-fuzz/corpus/<target>/ (the committed seeds are only read); a crash, a leak, undefined
# behaviour, a timeout or running out of memory stops the script with the input saved as
# build-fuzz/findings/<target>-crash-<hash> (replay: build-fuzz/bin/palpate_fuzz_<target> FILE).
# SECONDS 0 runs every committed seed of each target once (a regression check that cannot find anything new).
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]   targets: scene replay_csv shm_pose mesh_check (the project's
#   checks before the reader) http_head (the live view's request parser) ws_frame (its WebSocket frames and page
#   messages) mesh_off mesh_ply mesh_obj
#   mesh_stl mesh_dae (the mesh load path, one per format hint; OFF, PLY and STL by the project's own readers).
#   mesh_dae runs only when named: it still finds a crash inside the system's assimp within a minute (a null
#   pointer in the Collada reader), not yet refused before the reader.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(scene replay_csv shm_pose mesh_check http_head ws_frame mesh_off mesh_ply mesh_obj mesh_stl)

# -O1 -g1: the instrumented code compiles about a third faster than at RelWithDebInfo's -O2 -g, and a finding's stack
# keeps its files and lines; a new build folder is made for Ninja
generator=()
if [ ! -f build-fuzz/CMakeCache.txt ] && command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
cmake -S . -B build-fuzz "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
  -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DPALPATE_FUZZ=ON \
  -DPALPATE_BUILD_TESTS=OFF -DPALPATE_BUILD_BENCH=OFF -DPALPATE_WERROR=OFF >/dev/null
cmake --build build-fuzz -j "${JOBS:-$(nproc)}" --target "${targets[@]/#/palpate_fuzz_}"

mkdir -p build-fuzz/findings
export ASAN_OPTIONS="detect_leaks=1"
# leaks inside the system's assimp on its error paths are not ours (see the file)
export LSAN_OPTIONS="suppressions=$PWD/tests/fuzz/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1"
# one target: its fuzzer's exit status goes to build-fuzz/fuzz-<target>.status
fuzz_target() {
  local t=$1 status=0
  mkdir -p "build-fuzz/corpus/$t"
  rm -f "build-fuzz/findings/$t-"*
  if [ "$seconds" = 0 ]; then
    # each seed file once: libFuzzer runs the files it is given and exits
    build-fuzz/bin/palpate_fuzz_"$t" -rss_limit_mb=2048 -timeout=15 -artifact_prefix="build-fuzz/findings/$t-" \
      "tests/fuzz/corpus/$t"/* >"build-fuzz/fuzz-$t.log" 2>&1 || status=$?
  else
    build-fuzz/bin/palpate_fuzz_"$t" "build-fuzz/corpus/$t" "tests/fuzz/corpus/$t" \
      -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=15 -max_len=65536 -print_final_stats=1 \
      -artifact_prefix="build-fuzz/findings/$t-" >"build-fuzz/fuzz-$t.log" 2>&1 || status=$?
  fi
  echo "$status" >"build-fuzz/fuzz-$t.status"
}

# the targets run JOBS at a time (each fuzzer is one process on one core, so each still gets SECONDS of a core);
# their reports follow in the order given
jobs=${JOBS:-$(nproc)}
for ((i = 0; i < ${#targets[@]}; i += jobs)); do
  for t in "${targets[@]:i:jobs}"; do
    fuzz_target "$t" &
  done
  wait
done
for t in "${targets[@]}"; do
  echo "== fuzz $t: ${seconds} s"
  status=$(cat "build-fuzz/fuzz-$t.status")
  [ "$seconds" != 0 ] || grep -c '^Executed ' "build-fuzz/fuzz-$t.log" | sed "s/^/seeds run: /" || true
  grep -E '^(stat::number_of_executed_units|stat::peak_rss_mb|INFO: seed corpus|Done)' "build-fuzz/fuzz-$t.log" || true
  if [ "$status" -ne 0 ]; then
    tail -n 60 "build-fuzz/fuzz-$t.log" >&2
    echo "fuzz $t: finding (exit $status), input saved in build-fuzz/findings/:" >&2
    ls "build-fuzz/findings/$t-"* >&2 || true
    exit 1
  fi
done
