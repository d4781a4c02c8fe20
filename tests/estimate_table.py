#!/usr/bin/env python3
"""Memory estimates against what the runs take (issue 35, "estimates that hold"): runs `seamcl
render --json` and `seamcl compare --json` over a grid of cases and prints, per case, the
"estimate" block's total_bytes (host and device together, each byte once: on PoCL the device is
the CPU), the measured peak growth (the "memory" block's peak_rss_bytes minus the process floor)
and their ratio. The estimate holds when it is at least the growth and at most --max-ratio times it.
Like with like: the floor run holds buffers of its own, so a case's estimate is compared less the
floor run's estimate (a few hundred KiB).

The floor is the peak RSS of the same command's tiniest run in the same binary: `render --scene
quad2 --size 16x16 --msaa 1` for renders, the same as a compare (with the grid's methods) for
compares: PoCL's own baseline with the same programs loaded. Every kernel a case launches is
built into PoCL's kernel cache first, by the tiniest runs and by an unmeasured run of the case
itself (compiling one peaks 100-150 MB above any render, see tests/memory_peak_test.py; PoCL
compiles a kernel again for a launch of another size class, so a 16x16 run is not enough: a
compare's reference downsample at 241x271 compiled in the measured run put it 12 MB over its
estimate); each floor is the smallest of --floor-runs.

    tests/estimate_table.py --seamcl build/seamcl [--grid full|quick] [--check] [--max-ratio 1.5]
                            [--assets tests/assets/ptex] [--json OUT] [--program-cache off|environment]

--grid full: every built-in scene (`seamcl scenes`) and the asset scenes (cube.obj and
ptex_test_object.obj with their .ptx; no .ptx under tests/assets carries its mesh), at msaa 1 and 8; renders at the
default size (480x540) and 1920x1080, compares (discard,clamp, --no-cache) at 241x271 (the
service's default compare size, what the viewer asks for) and at the command line's default
480x540 for five scenes (LARGE_COMPARES; an 8x reference of 1920x1080 would be 15360x8640
pixels). --grid quick: a few
cheap cases for the test. --check exits 1 when a case's ratio is outside [1, --max-ratio]."""
import argparse
import json
import os
import subprocess
import sys

MIB = 1 << 20
COMPARE_METHODS = "discard,clamp"
LARGE_COMPARES = ("paper", "quad2", "envmap", "cube.obj+cube_text.ptx", "ptex_test_object.obj+cellnoise.ptx")


def run_json(command):
    done = subprocess.run(command, capture_output=True, text=True, timeout=1800)
    if done.returncode != 0:
        raise SystemExit(f"estimate_table: {' '.join(command)} exited {done.returncode}: {done.stderr.strip()[-2000:]}")
    answer = json.loads(done.stdout)
    for block, field in (("estimate", "total_bytes"), ("memory", "peak_rss_bytes")):
        if not isinstance(answer.get(block), dict) or not isinstance(answer[block].get(field), int):
            raise SystemExit(f"estimate_table: {' '.join(command)} printed no {block}.{field}")
    return answer


def command_line(seamcl, kind, scene, size, msaa):
    line = [seamcl, kind, *scene, "--size", size, "--msaa", str(msaa), "--json"]
    if kind == "compare":
        line += ["--methods", COMPARE_METHODS, "--no-cache", "--no-progress", "--repeat", "1"]
    return line


def scenes(seamcl, assets):
    listed = subprocess.run([seamcl, "scenes", "--json"], capture_output=True, text=True, check=True)
    out = [(g["name"], ["--scene", g["name"]]) for g in json.loads(listed.stdout)]
    out.append(("cube.obj+cube_text.ptx", ["--scene", os.path.join(assets, "cube.obj"),
                                           "--texture", os.path.join(assets, "cube_text.ptx")]))
    out.append(("ptex_test_object.obj+cellnoise.ptx", ["--scene", os.path.join(assets, "ptex_test_object.obj"),
                                                       "--texture", os.path.join(assets, "cellnoise.ptx")]))
    return out


def grid(seamcl, assets, which):
    every = scenes(seamcl, assets)
    if which == "quick":
        named = dict(every)
        return [("render", "paper", named["paper"], "480x540", 1),
                ("render", "ptex_test_object.obj+cellnoise.ptx", named["ptex_test_object.obj+cellnoise.ptx"], "480x540", 8),
                ("render", "cube.obj+cube_text.ptx", named["cube.obj+cube_text.ptx"], "1920x1080", 1),
                ("compare", "paper", named["paper"], "241x271", 1)]
    cases = []
    for kind, sizes in (("render", ("480x540", "1920x1080")), ("compare", ("241x271", "480x540"))):
        for name, scene in every:
            for size in sizes:
                # A compare at 480x540 takes about a minute on two cores: the five scenes that differ
                # most (two textured meshes, the environment map, the largest and smallest built-in).
                if kind == "compare" and size == "480x540" and name not in LARGE_COMPARES:
                    continue
                for msaa in (1, 8):
                    cases.append((kind, name, scene, size, msaa))
    return cases


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seamcl", required=True)
    parser.add_argument("--assets", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "assets", "ptex"))
    parser.add_argument("--grid", choices=("full", "quick"), default="full")
    parser.add_argument("--kinds", default="render,compare", help="render, compare or both (a comma list)")
    parser.add_argument("--check", action="store_true")
    parser.add_argument("--max-ratio", type=float, default=1.5)
    parser.add_argument("--floor-runs", type=int, default=2)
    parser.add_argument("--json", help="write every case's figures here")
    parser.add_argument("--program-cache", choices=("off", "environment"), default="off",
                        help="off: every run builds its programs from source (the same state on any machine); "
                             "environment: as SEAMCL_PROGRAM_CACHE and SEAMCL_CACHE_DIR say [off]")
    args = parser.parse_args()
    if args.program_cache == "off":
        # A program loaded from seamcl's program cache (written by `seamcl warmup`, or by any build
        # with SEAMCL_PROGRAM_CACHE=1) skips the compiler's memory, which lowers the floor by about
        # 5 MiB more than it lowers a case's peak: the same binary measured in a user's cache and in
        # an empty one gives other ratios (docs/compare.md). Every run inherits this.
        os.environ["SEAMCL_PROGRAM_CACHE"] = "off"
    if args.max_ratio < 1:
        raise SystemExit("estimate_table: --max-ratio must be at least 1")
    if args.floor_runs < 1:
        raise SystemExit("estimate_table: --floor-runs must be at least 1")

    kinds = args.kinds.split(",")
    if not kinds or any(k not in ("render", "compare") for k in kinds):
        raise SystemExit(f"estimate_table: --kinds must name render and/or compare, got '{args.kinds}'")
    cases = [c for c in grid(args.seamcl, args.assets, args.grid) if c[0] in kinds]
    tiny = ["--scene", "quad2"]
    floors, floor_estimates = {}, {}
    for kind in sorted({c[0] for c in cases}):
        # Every variant the grid builds, built once into the kernel cache before anything is measured.
        for msaa in sorted({c[4] for c in cases if c[0] == kind}):
            run_json(command_line(args.seamcl, kind, tiny, "16x16", msaa))
        runs = [run_json(command_line(args.seamcl, kind, tiny, "16x16", 1)) for _ in range(args.floor_runs)]
        floors[kind] = min(r["memory"]["peak_rss_bytes"] for r in runs)
        floor_estimates[kind] = runs[0]["estimate"]["total_bytes"]
    for kind, floor in floors.items():
        print(f"floor ({kind} --scene quad2 --size 16x16 --msaa 1): {floor / MIB:.1f} MiB peak RSS, "
              f"estimate {floor_estimates[kind] / MIB:.2f} MiB")

    # A case may launch kernels quad2 does not (envmap's cube lookups) or at other work sizes (a
    # compare's reference): the same run, unmeasured, builds them first.
    rows, failures = [], []
    print(f"{'case':58} {'estimate MiB':>12} {'measured MiB':>12} {'ratio':>6}")
    for kind, name, scene, size, msaa in cases:
        run_json(command_line(args.seamcl, kind, scene, size, msaa))
        answer = run_json(command_line(args.seamcl, kind, scene, size, msaa))
        estimate = answer["estimate"]["total_bytes"] - floor_estimates[kind]
        growth = answer["memory"]["peak_rss_bytes"] - floors[kind]
        ratio = estimate / growth if growth > 0 else float("inf")
        label = f"{kind} {name} {size} msaa {msaa}"
        held = growth > 0 and 1.0 <= ratio <= args.max_ratio
        print(f"{label:58} {estimate / MIB:12.1f} {growth / MIB:12.1f} {ratio:6.2f}{'' if held else '  <- outside'}",
              flush=True)
        rows.append({"kind": kind, "scene": name, "size": size, "msaa": msaa, "estimate": answer["estimate"],
                     "peak_rss_bytes": answer["memory"]["peak_rss_bytes"], "floor_bytes": floors[kind],
                     "estimate_less_floor_bytes": estimate, "growth_bytes": growth, "ratio": ratio})
        if not held:
            failures.append(label)
    if args.json:
        with open(args.json, "w") as out:
            json.dump({"floors": floors, "floor_estimates": floor_estimates, "cases": rows}, out, indent=1)
    if failures:
        print(f"{len(failures)} of {len(rows)} case(s) outside [1, {args.max_ratio}]: " + "; ".join(failures))
    else:
        print(f"all {len(rows)} case(s) within [1, {args.max_ratio}]")
    return 1 if args.check and failures else 0


if __name__ == "__main__":
    sys.exit(main())
