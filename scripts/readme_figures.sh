#!/usr/bin/env bash
# Re-runs the commands behind the README's measured figures, in the README's order, and keeps every output in one
# folder so each table can be set beside this machine's numbers. Timings depend on the machine and its load (the
# README says the load each figure was taken under); errors, forces and state hashes are lockstep results and
# should match the README to the digits it prints.
#
# Usage: scripts/readme_figures.sh [OUT_DIR] [SECTION...]
#   sections: record realtime scale loop force sim box model device (default: all; about 15 minutes on 2 cores)
# Needs a build (scripts/build.sh); BIN_DIR overrides build/bin.
#
#        scripts/readme_figures.sh --commands [--slow] [--timeout S] [--out DIR] [FILE.md...]
#   runs every command of the fenced ```sh blocks of README.md and docs/*.md (or the FILEs given) as written, one
#   line at a time from the repository root, and reports which fail. Lines whose comment says `# slow:` are skipped
#   unless --slow is given; each command is stopped after S seconds (default 600). Logs go to DIR (default
#   out/readme_commands). Exit status 1 when a command failed.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "${1:-}" = "--commands" ]; then
  shift
  exec python3 scripts/doc_commands.py "$@"
fi
bin=${BIN_DIR:-build/bin}
out=${1:-out/readme_figures}
shift || true
sections=("$@")
[ ${#sections[@]} -eq 0 ] && sections=(record realtime scale loop force sim box model device)
[ -x "$bin/palpate" ] || { echo "readme_figures: no $bin/palpate: run scripts/build.sh first" >&2; exit 1; }
mkdir -p "$out"
echo "readme_figures: outputs in $out (load average now: $(cut -d' ' -f1-3 /proc/loadavg))"

run() {  # name, command...: prints the command, keeps its stdout+stderr in $out/name.txt, and shows the stdout
  local name=$1
  shift
  echo
  echo "== $name: $*"
  "$@" 2> "$out/$name.stderr" | tee "$out/$name.txt"
}

stages() {  # summary.json -> the stage table of "Measured on this machine"
  python3 - "$1" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
ms = lambda k: j[k]["ms"] if "ms" in j[k] else j[k]
print(f'state_hash {j.get("state_hash")}  frames {j.get("frames_written")}  wall {j.get("wall_s", 0):.2f} s '
      f'for {j.get("duration_s")} scene-s')
for k in ("sim", "render", "png", "video"):
    v = j.get(k)
    if isinstance(v, dict):
        m = v.get("ms", v.get("encode_ms", {}))
        if "p50" in m: print(f'  {k:<7} p50 {m["p50"]:.2f} ms  p99 {m["p99"]:.2f} ms')
s = j["servo"]
print(f'  servo wake p50 {s["latency_us"]["p50"]} p99 {s["latency_us"]["p99"]} p99.9 {s["latency_us"]["p999"]} '
      f'max {s["latency_us"]["max"]} us, overruns {s["overruns"]}')
PY
}

for section in "${sections[@]}"; do
  case "$section" in
    record)
      run record "$bin/palpate" record scenes/bunny_pull_springs.json -q --out "$out/bunny_pull_springs_lockstep"
      stages "$out/bunny_pull_springs_lockstep/summary.json" ;;
    realtime)
      run realtime "$bin/palpate" record scenes/bunny_pull_springs.json --mode realtime -q --out "$out/bunny_pull_springs_realtime"
      stages "$out/bunny_pull_springs_realtime/summary.json" ;;
    scale)
      run scale "$bin/palpate" bench scale scenes/bunny_pull_springs.json --max-subdivisions 4 --json "$out/scale.json" \
        --plot "$out/bench_scale.png" ;;
    loop)
      run loop "$bin/palpate" bench loop --load record --json "$out/loop.json" --plot "$out/bench_loop_record.png"
      run loop_sweep "$bin/palpate" bench loop --sweep --load record --json "$out/loop_sweep.json" ;;
    force)
      run force "$bin/palpate" bench force --json "$out/force.json" ;;
    sim)
      run sim "$bin/palpate" bench sim scenes/bunny_pull_springs.json --levels 4,5 --substeps 0,2,4 --iterations 0,3 \
        --json "$out/sim.json" --plot "$out/bench_sim_bunny_pull.png"
      run sim_explicit "$bin/palpate" bench sim scenes/bunny_pull_explicit.json --substeps 0,2 ;;
    box)
      run box "$bin/palpate" bench sim scenes/bunny_pull_springs.json --box 4,8,16 --integrators symplectic_euler,implicit_euler \
        --json "$out/box.json" ;;
    model)
      run model "$bin/palpate" bench model --json "$out/model.json" --plot "$out/bench_model.png" ;;
    device)
      run device scripts/bench_device.sh ;;
    *)
      echo "readme_figures: unknown section '$section' (known: record realtime scale loop force sim box model device)" >&2
      exit 2 ;;
  esac
done
echo
echo "readme_figures: done; outputs in $out"
