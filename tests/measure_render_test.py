#!/usr/bin/python3
"""examples/measure_render.py against this build, tiny frames: one table row per size and rate in
the order given, stages that add up to no more than the total, the fragment count of a render of
the same cell, the start-up table, and --rounds 0 refused.

    tests/measure_render_test.py --seamcl build/seamcl
"""
import argparse
import json
import os
import subprocess
import sys

from script_checks import Checks

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "examples", "measure_render.py")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seamcl", required=True)
    args = ap.parse_args()
    check = Checks("measure_render_test")

    r = subprocess.run([sys.executable, SCRIPT, "--seamcl", args.seamcl, "--sizes", "32x32,48x32", "--msaa", "1,4",
                        "--repeat", "1", "--rounds", "2"], capture_output=True, text=True, cwd=ROOT)
    check(r.returncode == 0, f"exit 0 (got {r.returncode}): {r.stderr}")
    rows = [line.split("|")[1:-1] for line in r.stdout.splitlines() if line.startswith("| 32x32") or line.startswith("| 48x32")]
    check([(c[0].strip(), c[1].strip()) for c in rows] == [("32x32", "1"), ("32x32", "4"), ("48x32", "1"), ("48x32", "4")],
          f"one row per cell, in order: {r.stdout}")
    for cells in rows:
        total, *stages = (float(c) for c in cells[2:8])
        check(all(s >= 0.0 for s in stages) and total > 0.0, f"positive stage times: {cells}")
        # total runs from the first command's start to the last one's end: it holds every stage.
        check(sum(stages) <= total * 1.001 + 0.01, f"stages within the total: {cells}")
    rendered = json.loads(subprocess.run([args.seamcl, "render", "--json", "--size", "48x32", "--msaa", "4"],
                                         capture_output=True, text=True, check=True).stdout)
    check(len(rows) == 4 and int(rows[3][8]) == rendered["fragments"],
          f"fragments as render --json counts them ({rendered['fragments']}): {rows[3] if len(rows) == 4 else rows}")
    check("over 2 interleaved rounds of the median of 1 renders" in r.stdout, "the statistic is named: " + r.stdout)
    check("| second start (warm cache) |" in r.stdout, "the start-up table: " + r.stdout)
    r = subprocess.run([sys.executable, SCRIPT, "--seamcl", args.seamcl, "--rounds", "0"], capture_output=True, text=True)
    check(r.returncode == 2 and "--rounds" in r.stderr, f"--rounds 0 refused (got {r.returncode}): {r.stderr}")
    return check.result()


if __name__ == "__main__":
    sys.exit(main())
