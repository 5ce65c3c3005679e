#!/usr/bin/env bash
# Real-model check: for every model given (default: assimp's OFF, PLY, STL and OBJ test models and the models
# scripts/make_test_models.py writes: a noisy scan, a thin shell, a flat plate, a sharp-edged CAD part, a scan wound
# inside out, a CAD part with faces turned), writes a touch, a pull and a cut scene with `palpate scene`, records each
# twice, and prints one row per model and mode:
#   triangles     the model's triangles as loaded
#   pass/fail     pass: the tool made contact (max_force_N > 0), no NaN, and for cut the blade cut springs
#   s_per_scene_s wall seconds per scene second of the lockstep recording with frames (PNG, no video)
#   rt_frames     frames written by a realtime recording of the same scene (of the scene's 60 per second),
#                 rt_dropped frames it dropped
#   note          why there was no contact, what the load turned outward, springs cut and triangles added
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

# the row of one model and mode from its summaries, tab-separated: pass/FAIL, triangles, max force, s per scene
# second, realtime frames written and dropped, note (one python start a row: on the loaded machine each start
# took 3-5 s, and the check made nine of them a row)
row() { python3 - "$@" <<'PY'
import json, os, sys
mode, ls, rt = sys.argv[1:4]
s = json.load(open(ls))
r = json.load(open(rt)) if os.path.exists(rt) else {}
def get(j, key):
    for k in key.split("."):
        j = j.get(k, "-") if isinstance(j, dict) else "-"
    return round(j, 3) if isinstance(j, float) else j
force, nans, cut = get(s, "max_force_N"), get(s, "nan_events"), get(s, "cut.springs_cut")
notes = [n for n in (get(s, "no_contact"), get(s, "model.orientation")) if n != "-"]
ok = isinstance(force, (int, float)) and force > 0
if nans != 0:
    ok = False; notes.append("NaN events %s" % nans)
if mode == "cut":
    if not (isinstance(cut, int) and cut > 0):
        ok = False; notes.append("no spring cut")
    notes.append("springs cut %s, triangles added %s" % (cut, get(s, "cut.triangles_added")))
print("\t".join(str(x) for x in ("pass" if ok else "FAIL", get(s, "model.triangles"), force, get(s, "wall_s_per_scene_s"),
                                 get(r, "frames_written"), get(r, "frames_dropped"), "; ".join(notes))))
PY
}

fails=(); refused=(); n=0; sheet=0
printf '%-34s %9s %-5s %-4s %9s %13s %9s %10s  %s\n' model triangles mode ok max_N s_per_scene_s rt_frames rt_dropped note
for f in "${models[@]}"; do
  name=$(basename "$f")
  if ! info=$(timeout "$limit_s" "$palpate" info "$f" 2>&1 >/dev/null); then
    refused+=("$name: $(echo "$info" | tail -1)"); continue
  fi
  n=$((n + 1))
  for mode in $modes; do
    id=$(printf '%03d_%s' "$n" "$mode"); scene="$work/$id.json"
    if ! note=$(timeout "$limit_s" "$palpate" scene "$f" --mode "$mode" --out "$scene" 2>&1 >/dev/null); then
      printf '%-34s %9s %-5s %-4s %s\n' "$name" - "$mode" FAIL "scene: $(echo "$note" | tail -1)"; fails+=("$name $mode"); continue
    fi
    ls_out="$work/$id.lockstep"; rt_out="$work/$id.realtime"
    if ! rec=$(timeout "$limit_s" "$palpate" record "$scene" --mode lockstep --no-video -q -o "$ls_out" 2>&1 >/dev/null); then
      printf '%-34s %9s %-5s %-4s %s\n' "$name" - "$mode" FAIL "record: $(echo "$rec" | tail -1)"; fails+=("$name $mode"); continue
    fi
    [ $realtime = 1 ] && timeout "$limit_s" "$palpate" record "$scene" --mode realtime --no-video -q -o "$rt_out" >/dev/null 2>&1
    IFS=$'\t' read -r ok tris force s_per rt_frames rt_dropped why < <(row "$mode" "$ls_out/summary.json" "$rt_out/summary.json")
    printf '%-34s %9s %-5s %-4s %9s %13s %9s %10s  %s\n' "$name" "$tris" "$mode" "$ok" "$force" "$s_per" "$rt_frames" \
      "$rt_dropped" "$why"
    [ "$ok" = pass ] || fails+=("$name $mode")
    # the contact sheet: a row per model and mode, its first, middle and last frame, labelled
    frames=("$ls_out"/frames/*.png)
    if [ -e "${frames[0]}" ]; then
      count=${#frames[@]}; picks=(0 $((count / 2)) $((count - 1))); label=()
      for k in 0 1 2; do
        label+=("[$k:v]scale=320:-2,drawtext=text='${name//[:\']/_} ${mode} $((picks[k] + 1))/${count}':x=6:y=6:fontsize=14:fontcolor=white:box=1:boxcolor=black@0.6,pad=iw+2:ih+2:0:0:white[p$k]")
      done
      sheet=$((sheet + 1))
      ffmpeg -loglevel error -y -i "${frames[${picks[0]}]}" -i "${frames[${picks[1]}]}" -i "${frames[${picks[2]}]}" \
        -filter_complex "${label[0]};${label[1]};${label[2]};[p0][p1][p2]hstack=inputs=3" \
        "$work/sheet/$(printf '%05d' "$sheet").png"
    fi
    rm -rf "$rt_out"
  done
done

if [ "$sheet" -gt 0 ]; then
  ffmpeg -loglevel error -y -framerate 1 -i "$work/sheet/%05d.png" -vf "tile=1x${sheet}" -frames:v 1 \
    "$work/contact_sheet.png" && echo "contact sheet: $work/contact_sheet.png (first, middle, last frame per row; the rows one by one in $work/sheet/)"
fi
echo "models accepted $n, refused ${#refused[@]}; model-modes failed ${#fails[@]}"
for r in "${refused[@]}"; do echo "refused: $r"; done
for f in "${fails[@]}"; do echo "FAIL: $f"; done
[ ${#fails[@]} -eq 0 ]
