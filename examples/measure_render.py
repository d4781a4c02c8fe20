#!/usr/bin/env python3
"""Measures the render figures of docs/benchmarks.md with `seamcl render --json`.

Per size and MSAA rate: the median of --repeat N renders (one process, kernels warmed first),
per stage, from OpenCL profiling events; the cells run in turn --rounds times (the order rotated
each round) and each figure is the median over the rounds, because on a shared machine the load
moves between processes more than within one. 11 renders by default: in a process's first few
renders after its warm-up frame, and now and then later, a stage can take up to twice its usual
time (docs/performance.md, "How to measure"), and a median of 5 can land on those. Then the time to a first image in a fresh process
with a cold PoCL kernel cache against a second start that finds the cache warm.

    examples/measure_render.py [--seamcl build/seamcl] [--repeat 11] [--rounds 3] > table.md
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import tempfile
import time


def render(seamcl, args, env=None):
    out = subprocess.run([seamcl, "render", "--json", *args], check=True, capture_output=True, text=True, env=env)
    return json.loads(out.stdout)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seamcl", default="build/seamcl")
    parser.add_argument("--scene", default="paper")
    parser.add_argument("--repeat", type=int, default=11)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--sizes", default="480x540,1920x1080")
    parser.add_argument("--msaa", default="1,2,4,8")
    parser.add_argument("--method", default="discard")
    parser.add_argument("--filter", default="aniso")
    args = parser.parse_args()
    common = ["--scene", args.scene, "--method", args.method, "--filter", args.filter]

    if args.repeat < 1 or args.rounds < 1:
        parser.error("--repeat and --rounds must be at least 1")
    cells = [(size, msaa) for size in args.sizes.split(",") for msaa in args.msaa.split(",")]
    results = {cell: [] for cell in cells}
    for round_index in range(args.rounds):
        shift = round_index % len(cells)
        for size, msaa in cells[shift:] + cells[:shift]:
            results[(size, msaa)].append(
                render(args.seamcl, [*common, "--size", size, "--msaa", msaa, "--repeat", str(args.repeat)]))
    stages = ("total", "setup", "binning", "raster", "shade", "readback")
    print(f"Scene `{args.scene}`, method {args.method}, filter {args.filter} (max anisotropy 16), "
          f"per row the median over {args.rounds} interleaved rounds of the median of {args.repeat} renders "
          f"(ms, OpenCL profiling).\n")
    print("| size | MSAA | " + " | ".join(stages) + " | fragments |")
    print("| --- | --- | " + " | ".join("---" for _ in stages) + " | --- |")
    for size, msaa in cells:
        runs = results[(size, msaa)]
        medians = [statistics.median(r["ms"][stage] for r in runs) for stage in stages]
        print(f"| {size} | {msaa} | " + " | ".join(f"{m:.2f}" for m in medians) + f" | {runs[0]['fragments']} |")
    first = results[cells[0]][0]
    print(f"\nDevice: {first['device']}; {first['triangles']} triangles.\n")

    # First start (empty PoCL cache: the program and each kernel compile) against a second start.
    cache = tempfile.mkdtemp(prefix="seamcl-pocl-cache-")
    env = dict(os.environ, POCL_CACHE_DIR=cache)
    rows = []
    try:
        for label in ("first start (cold PoCL cache)", "second start (warm cache)"):
            begin = time.perf_counter()
            r = render(args.seamcl, [*common, "--size", "480x540", "--msaa", "4"], env=env)
            wall = (time.perf_counter() - begin) * 1000
            rows.append((label, r["kernel_build_ms"], wall))
    finally:
        shutil.rmtree(cache, ignore_errors=True)
    print("| start | program build (ms) | whole process, 480x540 4x (ms) |")
    print("| --- | --- | --- |")
    for label, build, wall in rows:
        print(f"| {label} | {build:.0f} | {wall:.0f} |")


if __name__ == "__main__":
    main()
