#!/usr/bin/env python3
"""Turns `seamcl cube-metrics --json` (argument 1) into the markdown tables of docs/results/cubemap/."""
import json, sys
d = json.load(open(sys.argv[1]))
rs = d["results"]
print("| n | method | bake | error mean | cube-edge pixels: error mean | p99 | first-order jump | ms / frame | cube memory |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for r in rs:
    print("| %d | %s | %s | %.4f | %.4f | %.3f | %.5f | %.1f | %.0f KiB |" % (
        r["cube_size"], r["cube_method"], r["bake"], r["error"]["mean"], r["edge_error"]["mean"], r["edge_error"]["p99"],
        r["first_order_jump"], r["ms"]["median"], r["cube_bytes"] / 1024))
print()
for n in sorted({r["cube_size"] for r in rs}):
    levels = len([r for r in rs if r["cube_size"] == n][0]["seam_step"])
    print("Seam step (mean over the 12 edges), n = %d, lod 0..%d:\n" % (n, levels - 1))
    print("| method | " + " | ".join(str(l) for l in range(levels)) + " |")
    print("| --- |" + " --- |" * levels)
    for r in rs:
        if r["cube_size"] != n: continue
        print("| %s | " % r["cube_method"] + " | ".join("%.1e" % s for s in r["seam_step"]) + " |")
    print()
