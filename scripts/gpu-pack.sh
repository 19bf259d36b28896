#!/usr/bin/env bash
# Packs what scripts/gpu-check.sh needs on a machine with a real GPU that has no Rust
# toolchain and no network: the release `strata`, the embedded examples and every GPU
# test binary (stripped, xz), the shared scenes the tests read (Cornell, Sponza, bunny;
# the dragon would pass the 64 MiB the device tool carries), and the Vulkan loader's
# Debian packages. Writes .dev/bin.txz, .dev/shared.txz and .gl/*.deb (both ignored).
#
#   bash scripts/gpu-pack.sh            # then, on the device (carry .gl and .dev):
#
#   for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; export XDG_RUNTIME_DIR=/tmp/xdg
#   mkdir -p /tmp/xdg /work /tmp/b; [ "$PWD" = /work/main ] || ln -sfn "$PWD" /work/main
#   tar -xJf .dev/bin.txz -C /tmp/b && tar -xJf .dev/shared.txz -C /work && ln -sfn /work/shared ../shared
#   mkdir -p target/release && cp /tmp/b/strata target/release/
#   G=/tmp/gc; BIN=/tmp/b OUT=$G TEST_S=150 SUITE_S=150 SOAK_FRAMES=3000 timeout 450 bash scripts/gpu-check.sh >$G.log 2>&1
#   cp $G.log $G/; tar -czf $OUT/gc.tgz -C /tmp gc    # the device returns at most 8 files
#
# ONLY="ao embed_soak" packs just those test binaries (and `strata`, no examples) for a
# quick rerun of a few tests: a few MB instead of ~35, and no full A/B or suite.
#
# The CLI's tests use absolute paths under /work/main, hence the link. STRATA_OLD=path
# adds an older `strata` as strata-old (gpu-check's A/B then compares the two builds).
# Takes the first release build's time (3-10 min) plus about 3 min to compress.
set -euo pipefail
cd "$(dirname "$0")/.."
SHARED="${SHARED:-../shared}"
say() { echo "[strata gpu-pack] $*" >&2; }

# the Vulkan loader and GL dispatch libraries, as the device's README asks
if ! ls .gl/libvulkan1_*.deb >/dev/null 2>&1; then
  say "downloading the Vulkan loader packages into .gl/"
  mkdir -p .gl /tmp/amd64/partial
  o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
  # shellcheck disable=SC2086
  apt-get $o update >/dev/null
  # shellcheck disable=SC2086
  (cd .gl && apt-get $o download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2 >/dev/null 2>&1)
fi

say "building (release: the CLI, the examples, the test binaries)"
cargo build --release --workspace --bins --examples
TESTS=$(mktemp)
cargo test --release --workspace --no-run --message-format=json >"$TESTS"

STAGE=$(mktemp -d)
mkdir -p "$STAGE/t" .dev
cp target/release/strata "$STAGE/"
[ -z "${ONLY:-}" ] && for e in embed_ao embed_gi embed_reflect embed_bzb embed_ils; do cp "target/release/examples/$e" "$STAGE/"; done
[ -n "${STRATA_OLD:-}" ] && cp "$STRATA_OLD" "$STAGE/strata-old"
# the integration tests of the crates that drive a GPU, named after their targets
python3 - "$TESTS" "$STAGE/t" <<'EOF'
import json, os, shutil, sys
gpu_crates = {"strata-render", "strata-cli", "strata-eval"}
for line in open(sys.argv[1]):
    try:
        m = json.loads(line)
    except ValueError:
        continue
    if m.get("reason") != "compiler-artifact" or not m.get("executable") or not m["profile"].get("test"):
        continue
    crate = m["package_id"].split("#")[0].rsplit("/", 1)[-1]
    kind = m["target"]["kind"][0]
    name = m["target"]["name"]
    if not any(crate.startswith(c) for c in gpu_crates):
        continue
    if kind in ("lib", "bin"):
        name = f"{name}-{kind}"
    # the viewer's tests need a display; the fuzz regressions and scene parsing no GPU
    if name in ("view", "fuzz_regressions"):
        continue
    only = os.environ.get("ONLY", "").split()
    if only and name not in only:
        continue
    shutil.copy(m["executable"], f"{sys.argv[2]}/{name}")
EOF
rm -f "$TESTS"
strip "$STAGE/strata" "$STAGE"/t/*
[ -z "${ONLY:-}" ] && strip "$STAGE"/embed_*
[ -f "$STAGE/strata-old" ] && strip "$STAGE/strata-old"
say "$(ls "$STAGE/t" | wc -l) test binaries; compressing"
tar -cJf .dev/bin.txz -C "$STAGE" .
rm -rf "$STAGE"
if [ -d "$SHARED/scenes" ]; then
  tar -cJf .dev/shared.txz -C "$SHARED/.." "$(basename "$SHARED")/scenes/cornell_box" \
    "$(basename "$SHARED")/scenes/dabrovic_sponza" "$(basename "$SHARED")/scenes/stanford_bunny"
else
  say "no $SHARED/scenes: the tests that need it will skip on the device"
fi
du -ch .dev/*.txz .gl/*.deb | tail -n 1 | sed 's/^/[strata gpu-pack] packed: /' >&2
say "the working tree travels too: keep it and these under 64 MiB"
