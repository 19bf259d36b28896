#!/usr/bin/env bash
# The benchmark suite at the papers' resolutions, for a machine with a real GPU:
# one JSON per bench (`strata bench … --json`) plus a log, in $OUT (default
# out/bench-gpu). Each bench is bounded by $LIMIT seconds and a failure is
# logged, not fatal, so one broken bench does not hide the others.
#
#   STRATA=target/release/strata OUT=out/bench-gpu bash scripts/bench-gpu.sh
#
# Scenes under ../shared (Sponza) are skipped with a note where it is absent.
# Summarise with `python3 scripts/bench_table.py $OUT/deep-gbuffer-*.json`.
set -uo pipefail
cd "$(dirname "$0")/.."
S="${STRATA:-target/release/strata}"
OUT="${OUT:-out/bench-gpu}"
LIMIT="${LIMIT:-180}"
mkdir -p "$OUT"
LOG="$OUT/log.txt"
: >"$LOG"
SPONZA=scenes/sponza.toml
[ -f ../shared/scenes/dabrovic_sponza/sponza.obj ] || { echo "skip Sponza: ../shared absent" | tee -a "$LOG"; SPONZA=""; }

# run NAME ARGS…: strata ARGS --json > $OUT/NAME.json, timed, errors to the log
run() {
  local name=$1; shift
  local t0=$(date +%s%N)
  if timeout "$LIMIT" "$S" "$@" --json >"$OUT/$name.json" 2>"$OUT/$name.err"; then
    printf '%-40s ok   %6d ms\n' "$name" $((($(date +%s%N) - t0) / 1000000)) | tee -a "$LOG"
  else
    printf '%-40s FAIL (rc %s): %s\n' "$name" "$?" "$(tail -n 2 "$OUT/$name.err" | tr '\n' ' ')" | tee -a "$LOG"
  fi
}

"$S" info >"$OUT/info.txt" 2>&1; head -n 20 "$OUT/info.txt" | tee -a "$LOG"
HD="--width 1920 --height 1080"

# DGB Table 5 / Fig. 3, Table 4 (1080p, as in the paper)
run gbuffer-atrium bench gbuffer --scene atrium $HD --frames 10
for sc in atrium dense $SPONZA; do
  n=$(basename "$sc" .toml)
  run "deep-gbuffer-$n" bench deep-gbuffer --scene "$sc" $HD --frames 8
  run "ao-$n" bench ao --scene "$sc" $HD --layers 2 --frames 8
done
for sc in atrium warehouse $SPONZA; do
  n=$(basename "$sc" .toml)
  for p in high-performance balanced high-quality; do
    run "radiosity-$n-$p" bench radiosity --scene "$sc" $HD --layers 2 --frames 5 --preset "$p"
  done
done
run reflections-mirror bench reflections --scene mirror $HD --layers 2 --frames 5
run technique-full-atrium bench technique --technique full --scene atrium $HD --frames 5

# ILS Table 4 (1024×768, 480 VPLs, 8×6)
ils_scene=${SPONZA:-atrium}
run ils bench ils --scene "$ils_scene" --width 1024 --height 768 --frames 9 \
  --set vpls=480 --set interleave-n=8 --set interleave-m=6

# ABA Table I (1280×720, 16 layers)
run abuffer-glasshouse bench abuffer --scene glasshouse --width 1280 --height 720 --frames 5

# BZB Table 1 (768×512)
run bzb-atrium bench bzb --scene atrium --width 768 --height 512 --frames 5
run bzb-atrium-box bench bzb --scene atrium --width 768 --height 512 --frames 5 --set splat-bounds=box
run bzb-atrium-fragment bench bzb --scene atrium --width 768 --height 512 --frames 5 --set splat-kernel=fragment
run bzb-gi-still-life-fragment bench bzb --technique bzb-gi --scene still-life --width 768 --height 512 --frames 3 --set splat-kernel=fragment
run technique-bzb-gi bench technique --technique bzb-gi --scene still-life --width 768 --height 512 --frames 3
run bzb-gi-still-life bench bzb --technique bzb-gi --scene still-life --width 768 --height 512 --frames 3
run bzb-gi-dominoes bench bzb --technique bzb-gi --scene dominoes --width 768 --height 512 --frames 3

# CPU reference tracer throughput on this machine's cores
run display-atrium bench display --scene atrium --technique full $HD --frames 10
run reference-atrium bench reference --scene atrium --width 256 --height 256
echo "done" | tee -a "$LOG"
