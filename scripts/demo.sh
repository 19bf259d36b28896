#!/usr/bin/env bash
# The main job: renders the default scene (atrium) and writes images + a report
# to out/demo/ (override with OUT=dir). Re-running replaces that folder's files.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
OUT="${OUT:-out/demo}"
W="${W:-640}"; H="${H:-360}"
mkdir -p "$OUT"
echo "[strata demo] building strata (release; the first build takes about 3 min on 2 idle cores, up to 10 min when busy)" >&2
cargo build --release -p strata-cli
S=target/release/strata
echo "[strata demo] device:" >&2
$S info | tee "$OUT/info.txt"
echo "[strata demo] rendering atrium ${W}x${H}: direct + deep-G-buffer radiosity + probes + AO + reflections" >&2
$S render --scene atrium --technique full --preset balanced --layers 2 --frame 10 --warmup 8 \
  --width "$W" --height "$H" --out "$OUT/atrium-full.png" --force --timings
for v in confidence gbuffer-only probe-only blended; do
  $S render --scene atrium --technique full --preset balanced --layers 2 --frame 10 --warmup 8 \
    --width "$W" --height "$H" --debug-view "$v" --out "$OUT/atrium-$v.png" --force
done
# these views measured (issue 14): pixels clipped per view, |blended - probe-only|, ꟻLIP of each
# composite and the banner regions' colour against the path-traced frame with sky (320x180; frame 0,
# the camera the regions are drawn for)
$S eval --scene atrium --technique full --preset balanced --views --layers 2 --width 320 --height 180 \
  --json --quiet > "$OUT/eval-views.json"
cat "$OUT/eval-views.json"
$S render --scene mirror --technique full --layers 2 --warmup 4 --width "$W" --height "$H" --out "$OUT/mirror-full.png" --force
$S render --scene atrium --width "$W" --height "$H" --out "$OUT/atrium.png" --force
$S render --scene atrium --width "$W" --height "$H" --out "$OUT/atrium.exr" --force
for v in csz normal albedo emission direct-diffuse shadow; do
  $S render --scene atrium --width "$W" --height "$H" --debug-view "$v" --out "$OUT/atrium-$v.png" --force
done
$S render --scene cornell --width 256 --height 256 --out "$OUT/cornell.png" --force
$S render --scene warehouse --width "$W" --height "$H" --out "$OUT/warehouse.png" --force
echo "[strata demo] CPU reference (ray-traced AO and GI, small sizes)" >&2
$S reference --scene atrium --kind ao --spp 16 --width 160 --height 90 --out "$OUT/atrium-ref-ao.png" --force --quiet
$S reference --scene cornell --kind gi --spp 64 --bounces 3 --width 96 --height 96 --out "$OUT/cornell-ref-gi.png" --force --quiet
echo "[strata demo] deep-G-buffer AO (2 layers) and its evaluation against the ray-traced obscurance" >&2
$S render --scene atrium --technique ao --layers 2 --width "$W" --height "$H" --out "$OUT/atrium-ao.png" --force
# the references converge to the default noise target (ꟻLIP 0.02 between their two halves)
$S eval --scene atrium --technique ao --layers 2 --width 320 --height 180 --frames 4 \
  --report "$OUT/ao-eval" --force --json --quiet > "$OUT/eval-ao.json"
cat "$OUT/eval-ao.json"
echo "[strata demo] deep-G-buffer radiosity against the path tracer" >&2
# the path tracer converges slowly (ꟻLIP ∝ spp^-0.35): the demo stops at ꟻLIP 0.05 between the
# reference's halves (several hundred spp, minutes) instead of the default 0.02 (thousands of spp,
# most of an hour on 2 cores); the JSON's ref_noise says which it reached
$S eval --scene warehouse --technique gi --layers 2 --width 320 --height 180 --ref-noise 0.05 \
  --report "$OUT/gi-eval" --force --json --quiet > "$OUT/eval-gi.json"
cat "$OUT/eval-gi.json"
echo "[strata demo] interleaved deferred shading of 480 VPLs (ILS), 8x6 sub-buffers" >&2
$S render --scene atrium --technique ils --width "$W" --height "$H" --out "$OUT/atrium-ils.png" --force
# against the brute force of the same VPLs (every VPL at every pixel) and the one-bounce path tracer
# (one bounce converges fast: the default noise target takes about 25 s here, 11 s for bzb-gi below)
$S eval --scene atrium --technique ils --width 320 --height 180 --json --quiet \
  --report "$OUT/ils-eval" --force > "$OUT/eval-ils.json"
cat "$OUT/eval-ils.json"
echo "[strata demo] A-buffer (ABA): OIT and opacity-aware multilayer AO on glasshouse; aba-ao vs single-layer and DGB AO on atrium" >&2
$S render --scene glasshouse --technique oit --width "$W" --height "$H" --out "$OUT/glasshouse-oit.png" --force
$S render --scene glasshouse --technique aba-ao --width "$W" --height "$H" --out "$OUT/glasshouse-aba-ao.png" --force
# OIT against the CPU's compositing of every surface crossing along each pixel's ray
$S eval --scene glasshouse --technique oit --width 320 --height 180 --json --quiet \
  --report "$OUT/oit-eval" --force > "$OUT/eval-oit.json"
cat "$OUT/eval-oit.json"
$S eval --scene atrium --technique aba-ao --width 320 --height 180 --json --quiet \
  --report "$OUT/aba-ao-eval" --force > "$OUT/eval-aba-ao.json"
cat "$OUT/eval-aba-ao.json"
echo "[strata demo] bounced z-buffer AO (BZB) on atrium; bzb-ao vs its additive baseline and DGB AO" >&2
$S render --scene atrium --technique bzb-ao --width "$W" --height "$H" --out "$OUT/atrium-bzb-ao.png" --force
$S eval --scene atrium --technique bzb-ao --width 320 --height 180 --json --quiet \
  --report "$OUT/bzb-ao-eval" --force > "$OUT/eval-bzb-ao.json"
cat "$OUT/eval-bzb-ao.json"
echo "[strata demo] bounced z-buffer GI (BZB) on warehouse against the one-bounce path tracer" >&2
$S render --scene warehouse --technique bzb-gi --width "$W" --height "$H" --out "$OUT/warehouse-bzb-gi.png" --force
$S eval --scene warehouse --technique bzb-gi --width 320 --height 180 --json --quiet \
  --report "$OUT/bzb-gi-eval" --force > "$OUT/eval-bzb-gi.json"
cat "$OUT/eval-bzb-gi.json"
echo "[strata demo] GPU timings" >&2
$S bench gbuffer --scene atrium --width "$W" --height "$H" --frames 5 --json > "$OUT/bench-gbuffer.json"
cat "$OUT/bench-gbuffer.json"
$S bench ao --scene atrium --width "$W" --height "$H" --layers 2 --frames 5 --json > "$OUT/bench-ao.json"
cat "$OUT/bench-ao.json"
$S bench radiosity --scene atrium --width "$W" --height "$H" --layers 2 --frames 5 --preset balanced --json > "$OUT/bench-radiosity.json"
cat "$OUT/bench-radiosity.json"
# each other paper's own timing: ILS Table 4 (speed-up over the brute force), ABA Table I
# (constructions, compressed AO speed-up), BZB Table 1 (visibility's cost over the additive baseline)
$S bench ils --scene atrium --width "$W" --height "$H" --frames 3 --json > "$OUT/bench-ils.json"
cat "$OUT/bench-ils.json"
$S bench abuffer --scene glasshouse --width "$W" --height "$H" --frames 3 --json > "$OUT/bench-abuffer.json"
cat "$OUT/bench-abuffer.json"
$S bench bzb --scene atrium --width "$W" --height "$H" --frames 3 --json > "$OUT/bench-bzb.json"
cat "$OUT/bench-bzb.json"
# BZB Table 1's GI columns (dominoes) at 160x90: a GI splat of 640x360 takes minutes on a CPU adapter
$S bench bzb --technique bzb-gi --scene dominoes --width 160 --height 90 --frames 2 --json > "$OUT/bench-bzb-gi.json"
cat "$OUT/bench-bzb-gi.json"
echo "[strata demo] strata's AO, radiosity, reflections, bounced-z-buffer AO and ILS in an application's own wgpu renderer (strata_render::embed, docs/embed.md)" >&2
cargo build --release -p strata-render --example embed_ao --example embed_gi --example embed_reflect --example embed_bzb --example embed_ils
target/release/examples/embed_ao "$OUT/embed-ao.png" | tee "$OUT/embed-ao.txt"
target/release/examples/embed_gi "$OUT/embed-gi.png" | tee "$OUT/embed-gi.txt"
target/release/examples/embed_reflect "$OUT/embed-reflect.png" | tee "$OUT/embed-reflect.txt"
target/release/examples/embed_bzb "$OUT/embed-bzb.png" | tee "$OUT/embed-bzb.txt"
target/release/examples/embed_ils "$OUT/embed-ils.png" | tee "$OUT/embed-ils.txt"
echo "[strata demo] report: tables and plots of the JSON above, the images, links to the evaluation reports" >&2
$S report --from "$OUT" --out "$OUT/report.html" --title "strata demo report" --force \
  --figures "Renders=atrium-full.png,mirror-full.png,atrium.png,atrium-ao.png,atrium-ils.png,cornell.png,warehouse.png" \
  --figures "A-buffer and bounced z-buffer=glasshouse-oit.png,glasshouse-aba-ao.png,atrium-bzb-ao.png,warehouse-bzb-gi.png" \
  --figures "Fig. 9 views (atrium, full)=atrium-confidence.png,atrium-gbuffer-only.png,atrium-probe-only.png,atrium-blended.png" \
  --figures "atrium G-buffer and lighting targets=atrium-csz.png,atrium-normal.png,atrium-albedo.png,atrium-emission.png,atrium-direct-diffuse.png,atrium-shadow.png" \
  --figures "CPU reference (atrium AO with binary visibility; cornell path-traced GI)=atrium-ref-ao.png,cornell-ref-gi.png" \
  --figures "AO, radiosity and reflections on an application's own G-buffer (examples/embed_ao; examples/embed_gi: direct | direct + indirect; examples/embed_reflect: no reflections | 1 layer | 2 layers; examples/embed_bzb: DGB AO | bounced-z-buffer AO under a table the camera does not see; examples/embed_ils: direct | + DGB radiosity | + ILS of the application's VPLs)=embed-ao.png,embed-gi.png,embed-reflect.png,embed-bzb.png,embed-ils.png"
echo "[strata demo] wrote $OUT/report.html and images in $OUT/" >&2
