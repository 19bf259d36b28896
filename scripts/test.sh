#!/usr/bin/env bash
# Runs every strata test (CPU and GPU; GPU tests run on lavapipe when no GPU is present).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
echo "[strata test] building and running all tests (release profile)" >&2
cargo test --release --workspace 2>&1
