#!/usr/bin/env python3
"""Prints `strata bench deep-gbuffer --json` outputs as the markdown rows of docs/benchmarks.md."""
import json
import sys

ORDER = ["single-layer", "peel", "delay", "previous", "predict", "reproject"]
print("| scene | tris | size | method | layer 1 ms | layer 2 ms | layer 2 / layer 1 | multiview total ms | Fig. 3 mismatch % |")
print("|---|---:|---|---|---:|---:|---:|---:|---:|")
for path in sys.argv[1:]:
    d = json.load(open(path))
    rows = {r["method"]: r for r in d["rows"]}
    for m in ORDER:
        r = rows.get(m)
        if r is None:
            continue
        ratio = r["layer2_ms"] / r["layer1_ms"] if m != "single-layer" else 0.0
        mv = "%.1f" % r["multiview_total_ms"] if "multiview_total_ms" in r else "–"
        print("| %s | %s | %dx%d | %s | %.1f | %.1f | %s | %s | %.2f |" % (
            d["scene"], f'{d["triangles"]:,}', d["width"], d["height"], m, r["layer1_ms"], r["layer2_ms"],
            "%.2f" % ratio if m != "single-layer" else "–", mv, r["mismatch_pct"]))
