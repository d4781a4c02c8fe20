#!/usr/bin/env python3
"""Turns `seamcl cube-metrics --json` (argument 1) into the markdown tables of docs/results/cubemap/."""
import json, sys
d = json.load(open(sys.argv[1]))
rs = d["results"]
print("| n | method | bake | error mean | cube-edge pixels: error mean | p99 | seam step, lod 0 | first-order band | first-order jump | ms / frame | bake ms | cube memory |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for r in rs:
    bake = r["bake"] + (" + averaged edges" if r.get("edges_averaged") else "") + (" + border" if r.get("border") else "")
    print("| %d | %s | %s | %.4f | %.4f | %.3f | %.1e | %.5f | %.5f | %.1f | %.1f | %.0f KiB |" % (
        r["cube_size"], r["cube_method"], bake, r["error"]["mean"], r["edge_error"]["mean"], r["edge_error"]["p99"],
        r["seam_step"][0], r["first_order_band"], r["first_order_jump"], r["ms"]["median"], r["bake_ms"],
        r["cube_bytes"] / 1024))
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
    halves = [r for r in rs if r["cube_size"] == n and r.get("seam_step_half_lod")]
    if halves:
        count = len(halves[0]["seam_step_half_lod"])
        print("Seam step at half lods, n = %d, lod 0.5..%.1f:\n" % (n, count - 0.5))
        print("| method | " + " | ".join("%.1f" % (l + 0.5) for l in range(count)) + " |")
        print("| --- |" + " --- |" * count)
        for r in halves:
            print("| %s | " % r["cube_method"] + " | ".join("%.1e" % s for s in r["seam_step_half_lod"]) + " |")
        print()
