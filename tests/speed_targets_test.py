#!/usr/bin/python3
"""scripts/speed-targets against this build, --quick: every target of issue 14 gets a row with a
measured value and a verdict, each command's output is kept, and bad options are refused.

    tests/speed_targets_test.py --build build
"""
import argparse
import json
import os
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
        rc, text = speed_targets("--build", args.build, "--out", out, "--quick", "--rounds", "1")
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
            # The rows whose ratio grows with a stage say what the ratio is made of: the same stage
            # medians as their cells, and the ratio recomputed with those stages as in the base frame.
            cells = report["msaa_cells"]
            bounded = {"discard 16x / 1x": ("discard 16x", ["raster"]), "discard 8x / 1x": ("discard 8x", ["raster"])}
            faces_rows = [t for t in rows if t.startswith("faces x40.0")]
            for t in faces_rows:
                bounded[t] = (None, ["setup", "binning", "raster"])
            for name, (cell, cheap) in bounded.items():
                b = rows.get(name, {}).get("bound")
                check(b is not None, f"{name}: a bound of what the ratio is made of: {rows.get(name)}")
                if b is None:
                    continue
                grown, base = b["grown_ms"], b["base_ms"]
                check(sorted(grown) == ["binning", "raster", "readback", "setup", "shade"],
                      f"{name}: the bound sums every stage: {sorted(grown)}")
                if cell:
                    check(grown == cells[cell]["stage_median_ms"] and base == cells["discard 1x"]["stage_median_ms"],
                          f"{name}: the bound's stages are its cells' ({grown} against {cells[cell]})")
                    check(abs(b["fragment_ratio"] - cells[cell]["fragments"] / cells["discard 1x"]["fragments"]) < 1e-3,
                          f"{name}: fragment ratio {b['fragment_ratio']}")
                with_base = (sum(grown.values()) - sum(grown[s] for s in cheap) + sum(base[s] for s in cheap)) / sum(base.values())
                check(abs(b["ratio_with_stages_as_in_base"] - with_base) < 1e-3,
                      f"{name}: {b['ratio_with_stages_as_in_base']} against {with_base} recomputed")
                check(b["goal_reachable_by_those_stages"] == (with_base <= float(rows[name]["goal"].split()[1])),
                      f"{name}: reachable {b['goal_reachable_by_those_stages']} for {with_base} against {rows[name]['goal']}")
                check(any(line.startswith(f"  {name}: stages") for line in text.splitlines()), f"{name}: its bound printed")
            check(len(faces_rows) == 1, f"one faces row: {faces_rows}")
            paper = rows.get("peak RSS of render --scene paper")
            if paper:
                # The verdict follows the value, not the other way round.
                check(paper["met"] == (paper["values"][0] <= 350), f"paper RSS verdict: {paper}")
            for name in ("sweep.json", "render_quad2_discard.json", "render_paper_traverse.json"):
                check(os.path.getsize(os.path.join(out, name)) > 0, f"{name} kept under --out")
            # Every verdict follows from its value and goal ("<= x" or ">= x").
            for r in report["targets"]:
                op, bound = r["goal"].split()[0], float(r["goal"].split()[1])
                for value in r["values"][:1]:
                    check(r["met"] == (value <= bound if op == "<=" else value >= bound),
                          f"{r['target']}: verdict {r['met']} for {value} against {r['goal']}")
            # One table line per row, each with its verdict.
            lines = [line for line in text.splitlines() if any(line.startswith(r["target"]) for r in report["targets"])]
            check(len(lines) == len(report["targets"]) and all(("met" in l) or ("MISSED" in l) for l in lines),
                  f"a table line with a verdict per target: {lines}")
        rc, text = speed_targets("--build", os.path.join(d, "nowhere"), "--out", out)
        check(rc == 2 and "--build: no seamcl binary" in text, f"a build folder without seamcl: {rc} {text}")
        rc, text = speed_targets("--build", args.build, "--rounds", "0", "--out", out)
        check(rc == 2 and "--rounds must be at least 1" in text, f"--rounds 0: {rc} {text}")

    return check.result()


if __name__ == "__main__":
    sys.exit(main())
