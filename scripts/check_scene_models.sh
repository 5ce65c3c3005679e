#!/usr/bin/env bash
# Real-model check: for every model given (default: assimp's OFF, PLY, STL and OBJ test models and the models
# scripts/make_test_models.py writes: a noisy scan, a thin shell, a flat plate, a sharp-edged CAD part), writes a
# touch, a pull and a cut scene with `palpate scene`, records each twice, and prints one row per model and mode:
#   pass/fail     pass: the tool made contact (max_force_N > 0), no NaN, and for cut the blade cut springs
#   s_per_scene_s wall seconds per scene second of the lockstep recording with frames (PNG, no video)
#   rt_frames     frames written by a realtime recording of the same scene (of the scene's 60 per second),
#                 rt_dropped frames it dropped
# then writes contact_sheet.png in the work folder: per model and mode the first, middle and last frame of the
# lockstep recording, labelled. Models `palpate info` refuses are listed as refused with its reason (not failures).
# Exits non-zero when any accepted model fails a mode.
# Usage: scripts/check_scene_models.sh [--big] [--modes "touch pull cut"] [--no-realtime] [MODEL_OR_DIR...]
#   --big          also the generated 10^5 and 10^6 triangle scans (minutes)
#   --no-realtime  skip the realtime recordings (rt_frames shows -)
# Environment: PALPATE (the binary, default build/bin/palpate), WORK (work folder, default a new one under /tmp),
# LIMIT_S (seconds allowed per command, default 300).
set -uo pipefail
cd "$(dirname "$0")/.."

big=0; realtime=1; modes="touch pull cut"; inputs=()
while [ $# -gt 0 ]; do
  case "$1" in
    --big) big=1; shift ;;
    --no-realtime) realtime=0; shift ;;
    --modes) modes=$2; shift 2 ;;
    -h|--help) sed -n '2,19p' "$0"; exit 0 ;;
    *) inputs+=("$1"); shift ;;
  esac
done
palpate=$(realpath "${PALPATE:-build/bin/palpate}")
work=$(realpath -m "${WORK:-$(mktemp -d /tmp/palpate_models.XXXXXX)}")
mkdir -p "$work/models" "$work/sheet"
limit_s=${LIMIT_S:-300}

if [ ${#inputs[@]} -eq 0 ]; then
  assimp=/usr/share/assimp/models
  for d in OFF PLY STL OBJ; do [ -d "$assimp/$d" ] && inputs+=("$assimp/$d"); done
  python3 scripts/make_test_models.py "$work/models" $([ $big = 1 ] && echo --big) || exit 1
  inputs+=("$work/models")
fi
models=()
for i in "${inputs[@]}"; do
  if [ -d "$i" ]; then
    while IFS= read -r -d '' f; do models+=("$f"); done < <(find "$i" -maxdepth 1 -type f \
      \( -iname '*.off' -o -iname '*.ply' -o -iname '*.stl' -o -iname '*.obj' \) -print0 | sort -z)
  else
    models+=("$i")
  fi
done

# one value of a summary.json ("-" when absent)
value() { python3 -c 'import json,sys
j=json.load(open(sys.argv[1])); v=j
for k in sys.argv[2].split("."): v=v.get(k,"-") if isinstance(v,dict) else "-"
print(round(v,3) if isinstance(v,float) else v)' "$1" "$2"; }

fails=(); refused=(); n=0; sheet=0
printf '%-34s %-5s %-4s %9s %13s %9s %10s  %s\n' model mode ok max_N s_per_scene_s rt_frames rt_dropped note
for f in "${models[@]}"; do
  name=$(basename "$f")
  if ! info=$(timeout "$limit_s" "$palpate" info "$f" 2>&1 >/dev/null); then
    refused+=("$name: $(echo "$info" | tail -1)"); continue
  fi
  n=$((n + 1))
  for mode in $modes; do
    id=$(printf '%03d_%s' "$n" "$mode"); scene="$work/$id.json"
    if ! note=$(timeout "$limit_s" "$palpate" scene "$f" --mode "$mode" --out "$scene" 2>&1 >/dev/null); then
      printf '%-34s %-5s %-4s %s\n' "$name" "$mode" FAIL "scene: $(echo "$note" | tail -1)"; fails+=("$name $mode"); continue
    fi
    ls_out="$work/$id.lockstep"; rt_out="$work/$id.realtime"
    if ! rec=$(timeout "$limit_s" "$palpate" record "$scene" --mode lockstep --no-video -q -o "$ls_out" 2>&1 >/dev/null); then
      printf '%-34s %-5s %-4s %s\n' "$name" "$mode" FAIL "record: $(echo "$rec" | tail -1)"; fails+=("$name $mode"); continue
    fi
    s="$ls_out/summary.json"
    force=$(value "$s" max_force_N); nans=$(value "$s" nan_events); cut=$(value "$s" cut.springs_cut)
    rt_frames=-; rt_dropped=-
    if [ $realtime = 1 ] && timeout "$limit_s" "$palpate" record "$scene" --mode realtime --no-video -q -o "$rt_out" >/dev/null 2>&1; then
      rt_frames=$(value "$rt_out/summary.json" frames_written); rt_dropped=$(value "$rt_out/summary.json" frames_dropped)
    fi
    ok=pass; why=$(value "$s" no_contact); [ "$why" = - ] && why=""
    python3 -c "import sys; sys.exit(0 if float('$force') > 0 else 1)" || ok=FAIL
    [ "$nans" = 0 ] || { ok=FAIL; why="$why NaN events $nans"; }
    if [ "$mode" = cut ]; then
      python3 -c "import sys; sys.exit(0 if '$cut' != '-' and float('$cut') > 0 else 1)" || { ok=FAIL; why="$why no spring cut"; }
      why="$why springs cut $cut"
    fi
    printf '%-34s %-5s %-4s %9s %13s %9s %10s  %s\n' "$name" "$mode" "$ok" "$force" "$(value "$s" wall_s_per_scene_s)" \
      "$rt_frames" "$rt_dropped" "$why"
    [ $ok = pass ] || fails+=("$name $mode")
    # the contact sheet: first, middle and last frame, labelled
    frames=("$ls_out"/frames/*.png)
    if [ -e "${frames[0]}" ]; then
      count=${#frames[@]}
      for pick in 0 $((count / 2)) $((count - 1)); do
        sheet=$((sheet + 1))
        ffmpeg -loglevel error -y -i "${frames[$pick]}" -vf "scale=320:-2,drawtext=text='${name//[:\']/_} ${mode} $((pick + 1))/${count}':x=6:y=6:fontsize=14:fontcolor=white:box=1:boxcolor=black@0.6" \
          "$work/sheet/$(printf '%05d' "$sheet").png"
      done
    fi
    rm -rf "$rt_out"
  done
done

rows=$(( (sheet + 2) / 3 ))
if [ "$sheet" -gt 0 ]; then
  ffmpeg -loglevel error -y -framerate 1 -i "$work/sheet/%05d.png" -vf "tile=3x${rows}:padding=2:color=white" -frames:v 1 \
    "$work/contact_sheet.png" && echo "contact sheet: $work/contact_sheet.png (first, middle, last frame per row)"
fi
echo "models accepted $n, refused ${#refused[@]}; model-modes failed ${#fails[@]}"
for r in "${refused[@]}"; do echo "refused: $r"; done
for f in "${fails[@]}"; do echo "FAIL: $f"; done
[ ${#fails[@]} -eq 0 ]
