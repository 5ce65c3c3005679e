#!/usr/bin/env bash
# Device-in-the-loop figures: shim round trip (palpate-shim-bench), then the servo's wake latency and compute time
# at 1 kHz with the device in-process (scripted) vs in another process (palpate-device over the shim), with the
# sim only (--no-render, "idle") and beside a full recording (render + PNG). Usage: scripts/bench_device.sh [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${BIN_DIR:-build/bin}
secs=${1:-4}
scene=scenes/cube_press.json
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

"$bin/palpate-shim-bench" 3000

figures() {  # label summary.json
  python3 - "$1" "$2" <<'PY'
import json, sys
j = json.load(open(sys.argv[2])); s = j["servo"]
print(f'{sys.argv[1]:<34} wake p50 {s["latency_us"]["p50"]:6.0f} p99 {s["latency_us"]["p99"]:6.0f} '
      f'p99.9 {s["latency_us"]["p999"]:6.0f} max {s["latency_us"]["max"]:8.1f} us | compute p50 {s["compute_us"]["p50"]:4.0f} '
      f'p99 {s["compute_us"]["p99"]:4.0f} us | overruns {s["overruns"]} | ticks {j["servo_ticks"]}')
PY
}

for load in idle record; do
  flags=(--mode realtime --duration "$secs" -q)
  [ "$load" = idle ] && flags+=(--no-render)
  "$bin/palpate" record "$scene" "${flags[@]}" --out "$out/in_$load" > /dev/null
  figures "in-process device, $load" "$out/in_$load/summary.json"
  "$bin/palpate-device" --name "bench-$$" --scene "$scene" -q > "$out/dev_$load.txt" &
  dev=$!
  "$bin/palpate" record "$scene" "${flags[@]}" --device "shm:bench-$$" --out "$out/shm_$load" > /dev/null
  kill -TERM "$dev"; wait "$dev"
  figures "device in another process, $load" "$out/shm_$load/summary.json"
  grep -E "wake latency|written by the sim|round trip" "$out/dev_$load.txt" | sed 's/^/    palpate-device:/'
done
