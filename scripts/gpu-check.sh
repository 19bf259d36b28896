#!/usr/bin/env bash
# The checks for a machine with a real GPU, in one run: every GPU test binary, an A/B of
# two strata builds on the frame passes, and the bench suite (scripts/bench-gpu.sh).
#
#   BIN=dir OUT=dir bash scripts/gpu-check.sh
#
# BIN holds binaries built elsewhere (`cargo test --release --no-run` and
# `cargo build --release`): `strata`, optionally `strata-old` (the build to compare
# with; without it the A/B is one build's fragment forms, every `*-kernel` set to
# `fragment`, against `auto`), the examples `embed_ao`, `embed_gi`, `embed_reflect`, `embed_bzb`, `embed_ils`
# (and `*-old`), and the test
# binaries under `t/`, named after their test targets. The CLI's tests find the `strata`
# binary where cargo built it, so copy BIN/strata there first. Tests that need
# ../shared skip where it is absent. Each part is bounded (TEST_S, SUITE_S seconds) and
# logs rather than stops on a failure. Results: OUT/tests/*.txt, OUT/ab-*.json,
# OUT/suite/*.json, renders OUT/*.png.
set -uo pipefail
cd "$(dirname "$0")/.."
BIN="${BIN:?BIN: the folder of prebuilt binaries}"
OUT="${OUT:-out/gpu-check}"
mkdir -p "$OUT/tests"
T0=$(date +%s)
"$BIN/strata" info >"$OUT/info.txt" 2>&1
tail -n 8 "$OUT/info.txt"

# every test binary, four at a time (4 threads each)
if [ -d "$BIN/t" ]; then
  ls "$BIN/t" | timeout "${TEST_S:-300}" xargs -P 4 -I{} sh -c \
    "'$BIN/t/{}' --test-threads=4 > '$OUT/tests/{}.txt' 2>&1; echo \"{} rc=\$?\" >> '$OUT/tests/_rc.txt'"
  sort "$OUT/tests/_rc.txt" | tr '\n' ' '
  echo
  grep -h "^test result" "$OUT"/tests/*.txt | awk '{p+=$4; f+=$6; i+=$8} END {print "tests: passed", p, "failed", f, "ignored", i}'
  grep -h -E "^test .* FAILED|panicked" "$OUT"/tests/*.txt | head -n 20
fi
echo "tests done $(($(date +%s) - T0)) s"

# A/B: the two builds alternated, two rounds, at 1080p (AB_SIZE: other --width/--height)
HD="${AB_SIZE:---width 1920 --height 1080}"
builds="frag new"
[ -x "$BIN/strata-old" ] && builds="old new"
for rep in 1 2; do
  for v in $builds; do
    S="$BIN/strata"
    [ "$v" = old ] && S="$BIN/strata-old"
    # frag: the same build with the passes that have both forms forced to fragment
    k() { [ "$v" = frag ] && for n in "$@"; do printf -- '--set %s-kernel=fragment ' "$n"; done; }
    ab() { timeout 60 "$S" "$@" --json >"$OUT/ab-$v-$rep-$name.json" 2>/dev/null; }
    name=full-atrium ab bench technique --technique full --scene atrium $HD --frames 5 $(k ao indirect lighting reflection)
    name=full-mirror ab bench technique --technique full --scene mirror $HD --frames 5 $(k ao indirect lighting reflection)
    name=ao-tech-atrium ab bench technique --technique ao --scene atrium $HD --frames 8 $(k ao)
    name=direct-atrium ab bench technique --technique direct --scene atrium $HD --frames 8 $(k lighting)
    # BZB Table 1's size: the splats' depth test in fragments or in compute (splat-kernel)
    name=bzb-ao-atrium ab bench technique --technique bzb-ao --scene atrium --width 768 --height 512 --frames 5 $(k splat)
    name=bzb-gi-still-life ab bench technique --technique bzb-gi --scene still-life --width 768 --height 512 --frames 3 $(k splat)
    if [ "$v" != frag ]; then # the stage benches take no settings
      name=ao-atrium ab bench ao --scene atrium $HD --layers 2 --frames 8
      name=radiosity-atrium ab bench radiosity --scene atrium $HD --layers 2 --frames 5 --preset balanced
      name=reflections-mirror ab bench reflections --scene mirror $HD --layers 2 --frames 5
    fi
    for e in embed_ao embed_gi embed_reflect embed_bzb embed_ils; do
      [ "$v" = frag ] && continue # the examples take no settings
      X="$BIN/$e"
      [ "$v" = old ] && X="$BIN/$e-old"
      [ -x "$X" ] && timeout 30 "$X" "$OUT/$e-$v.png" >"$OUT/ab-$v-$rep-$e.txt" 2>&1
    done
  done
done
echo "A/B done $(($(date +%s) - T0)) s"

STRATA="$BIN/strata" OUT="$OUT/suite" LIMIT=40 timeout "${SUITE_S:-200}" bash scripts/bench-gpu.sh >/dev/null 2>&1
tail -n 28 "$OUT/suite/log.txt"
for v in $builds; do
  S="$BIN/strata"
  [ "$v" = old ] && S="$BIN/strata-old"
  "$S" render --scene atrium --technique full --preset balanced --layers 2 --width 640 --height 360 --warmup 8 \
    $(k ao indirect lighting reflection) --out "$OUT/atrium-full-$v.png" >/dev/null 2>&1
  "$S" render --scene mirror-sign --technique full --layers 2 --width 640 --height 360 --warmup 4 \
    $(k ao indirect lighting reflection) --out "$OUT/mirror-sign-$v.png" >/dev/null 2>&1
done
# a longer embedded soak (SOAK_FRAMES), waiting for the GPU before each sample
if [ -n "${SOAK_FRAMES:-}" ] && [ -x "$BIN/t/embed_soak" ]; then
  STRATA_SOAK_FRAMES="$SOAK_FRAMES" timeout 120 "$BIN/t/embed_soak" --nocapture >"$OUT/soak.txt" 2>&1
  echo "soak rc=$?"; grep -v "^$" "$OUT/soak.txt" | tail -n 12
fi
echo "total $(($(date +%s) - T0)) s"
