#!/usr/bin/python3
"""scripts/speed-targets against this build, --quick: every target of issue 14 gets a row with a
measured value and a verdict, each command's output is kept, and bad options are refused.

    tests/speed_targets_test.py --build build
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile

from script_checks import Checks

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "scripts", "speed-targets")

EXPECTED_TARGETS = [
    "discard 16x / 1x", "discard 8x / 1x", "traverse / discard, every rate",
    "pixels x32.0*", "faces x40.0*", "peak RSS of render --scene paper",
    "peak RSS of paper <= floor + 2x packed", "peak RSS of paper_99k <= floor + 2x packed",
    "reference wall / device time, paper", "compare wall / (reference + entries), paper",
    "reference wall / device time, mixed", "compare wall / (reference + entries), mixed",
    "reference wall / device time, closeup-seam", "compare wall / (reference + entries), closeup-seam",
    "warmup, empty program cache (ms)", "warmup, warm program cache (ms)",
    "first render of a fresh process / a repeated one, paper *",
    "first render of a fresh process / a repeated one, closeup-seam *",
]
LOOKUP_TARGETS = [f"{what}, {texels}" for texels in ("rgba8", "rgba32f")
                  for what in ("aniso16 / OIIO aniso", "trilinear / OIIO trilinear", "aniso16 / (trilinear / *")]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    args = ap.parse_args()
    check = Checks("speed_targets_test")

    def speed_targets(*options):
        r = subprocess.run([sys.executable, SCRIPT, *options], capture_output=True, text=True, cwd=ROOT)
        return r.returncode, r.stdout + r.stderr

    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "targets")
        rc, text = speed_targets("--build", args.build, "--out", out, "--quick", "--rounds", "2")
        check(rc == 0, f"a quick run exits 0 (got {rc}): {text[-2000:]}")
        if rc == 0:
            with open(os.path.join(out, "targets.json")) as f:
                report = json.load(f)
            check(report["kind"] == "speed_targets" and report["quick"] is True, f"report header: {report.keys()}")
            rows = {r["target"]: r for r in report["targets"]}
            expected = list(EXPECTED_TARGETS)
            if os.path.exists(os.path.join(args.build, "seamcl_bench_lookups")):
                expected += LOOKUP_TARGETS
            for name in expected:
                prefix, _, suffix = name.partition("*")  # "*": the mean probe count
                matches = [r for t, r in rows.items() if t.startswith(prefix) and t.endswith(suffix)]
                check(len(matches) == 1, f"one row for {name!r}: {sorted(rows)}")
                for r in matches:
                    check(len(r["values"]) >= 1 and all(isinstance(v, (int, float)) and v > 0 for v in r["values"]),
                          f"{name}: positive measured values, got {r['values']}")
                    check(isinstance(r["met"], bool), f"{name}: a verdict, got {r['met']}")
                    check(isinstance(r["settled"], bool), f"{name}: whether the verdict is settled, got {r.get('settled')}")
            # A first render's row gives its floor on this driver: the driver's start plus one
            # repeated frame, over that frame (above 1 by the start's share).
            for t, r in rows.items():
                if t.startswith("first render"):
                    floor = re.search(r"floor on this driver \(its start ([0-9.]+) ms.*\) ([0-9.]+)$", r["note"])
                    check(floor is not None and float(floor.group(1)) > 0 and float(floor.group(2)) > 1.0,
                          f"{t}: its floor on this driver in the note: {r['note']!r}")
            # The rows whose ratio grows with a stage say what the ratio is made of: the row's own
            # figures, less the growth of those stages between the stage medians of the renders behind
            # them (each cell's, the median over the rounds; the sweep points' own).
            cells = report["msaa_cells"]
            for cell in cells.values():
                for stage, per_round in cell["rounds_stage_ms"].items():
                    check(len(per_round) == 2 and cell["stage_median_ms"][stage] == statistics.median(per_round),
                          f"a cell's stage median is the median over the rounds: {stage} {per_round} {cell['stage_median_ms']}")
            with open(os.path.join(out, "sweep.json")) as f:
                faces_sweep = next(sw for sw in json.load(f)["sweeps"] if sw["axis"] == "faces")
            bounded = {}
            for rate in (16, 8):
                grown, base = cells[f"discard {rate}x"], cells["discard 1x"]
                bounded[f"discard {rate}x / 1x"] = (grown["median_ms"], base["median_ms"], grown["stage_median_ms"],
                                                     base["stage_median_ms"], ["raster"])
            faces_rows = [t for t in rows if t.startswith("faces x40.0")]
            check(len(faces_rows) == 1, f"one faces row: {faces_rows}")
            for t in faces_rows:
                ratio = next(r for r in faces_sweep["ratios"] if r["max_time_ratio"] is not None)
                point = {p["x"]: p["results"][0] for p in faces_sweep["points"]}
                bounded[t] = (point[ratio["to_x"]]["ms"]["median"], ratio["from_ms"], point[ratio["to_x"]]["stages"],
                              point[ratio["from_x"]]["stages"], ["setup", "binning", "raster"])
            for name, (ratio_ms, base_ms, grown, base, cheap) in bounded.items():
                b = rows.get(name, {}).get("bound")
                check(b is not None, f"{name}: a bound of what the ratio is made of: {rows.get(name)}")
                if b is None:
                    continue
                # (msaa_cells round their medians to 3 decimals)
                check(abs(b["ratio_ms"] - ratio_ms) <= 5e-4 and abs(b["base_ms"] - base_ms) <= 5e-4 and
                      b["grown_stage_ms"] == grown and b["base_stage_ms"] == base,
                      f"{name}: the bound's figures are the row's renders' ({b})")
                ratio_ms, base_ms = b["ratio_ms"], b["base_ms"]
                check(abs(b["ratio"] - rows[name]["values"][0]) < 1e-3, f"{name}: the bound explains the row's ratio")
                growth = sum(grown[s] - base[s] for s in cheap)
                with_base = (ratio_ms - growth) / base_ms
                check(abs(b["stage_growth_ms"] - growth) < 1e-3 and abs(b["ratio_without_growth"] - with_base) < 1e-3,
                      f"{name}: {b['stage_growth_ms']}, {b['ratio_without_growth']} against {growth}, {with_base} recomputed")
                check(b["goal_reachable_by_those_stages"] == (with_base <= float(rows[name]["goal"].split()[1])),
                      f"{name}: reachable {b['goal_reachable_by_those_stages']} for {with_base} against {rows[name]['goal']}")
                if name.startswith("discard"):
                    rate = name.split("x")[0].split()[1]
                    fragments = cells[f"discard {rate}x"]["fragments"] / cells["discard 1x"]["fragments"]
                    check(abs(b["fragment_ratio"] - fragments) < 1e-3 and
                          abs(b["shade_ratio"] - grown["shade"] / base["shade"]) < 1e-3,
                          f"{name}: fragments {b['fragment_ratio']} ({fragments}), shade {b['shade_ratio']}")
                check(any(line.startswith(f"  {name}: ") and "ms less" in line for line in text.splitlines()),
                      f"{name}: its bound printed")
            paper = rows.get("peak RSS of render --scene paper")
            if paper:
                # The verdict follows the value, not the other way round.
                check(paper["met"] == (paper["values"][0] <= 350), f"paper RSS verdict: {paper}")
            for name in ("sweep.json", "render_quad2_discard.json", "render_paper_traverse.json"):
                check(os.path.getsize(os.path.join(out, name)) > 0, f"{name} kept under --out")
            # Every verdict follows from its value and goal ("<= x", "< x", ">= x" or "> x").
            compare = {"<=": lambda v, b: v <= b, "<": lambda v, b: v < b, ">=": lambda v, b: v >= b,
                       ">": lambda v, b: v > b}
            for r in report["targets"]:
                op, bound = r["goal"].split()[0], float(r["goal"].split()[1])
                check(op in compare, f"{r['target']}: a goal this test can read, got {r['goal']!r}")
                for value in r["values"][:1]:
                    check(op in compare and r["met"] == compare[op](value, bound),
                          f"{r['target']}: verdict {r['met']} for {value} against {r['goal']}")
            # One table line per row, each with its verdict.
            lines = [line for line in text.splitlines() if any(line.startswith(r["target"]) for r in report["targets"])]
            check(len(lines) == len(report["targets"]) and all(("met" in l) or ("MISSED" in l) for l in lines),
                  f"a table line with a verdict per target: {lines}")
        bench = os.path.join(args.build, "seamcl_bench_lookups")
        if os.path.exists(bench):
            for bad in ("0", "1023", "16777217", "4k", ""):
                r = subprocess.run([bench, f"--lookups={bad}"], capture_output=True, text=True)
                check(r.returncode == 2 and f"--lookups must be a whole number from 1024 to 16777216, got '{bad}'" in r.stderr,
                      f"seamcl_bench_lookups --lookups={bad}: {r.returncode} {r.stderr[-300:]}")
        rc, text = speed_targets("--build", os.path.join(d, "nowhere"), "--out", out)
        check(rc == 2 and "--build: no seamcl binary" in text, f"a build folder without seamcl: {rc} {text}")
        rc, text = speed_targets("--build", args.build, "--rounds", "0", "--out", out)
        check(rc == 2 and "--rounds must be at least 1" in text, f"--rounds 0: {rc} {text}")

    return check.result()


if __name__ == "__main__":
    sys.exit(main())
