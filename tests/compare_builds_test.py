#!/usr/bin/python3
"""scripts/compare-builds against seamcl itself: one build against itself gives identical images
(exit 0); the same build with a different option on the after side is reported as different
(exit 1, with the pair and its difference named); `speed` writes both builds' JSON per round and
prints the ratios; bad options are refused.

    tests/compare_builds_test.py --seamcl build/seamcl
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

from script_checks import Checks

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "scripts", "compare-builds")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seamcl", required=True)
    args = ap.parse_args()
    args.seamcl = os.path.abspath(args.seamcl)
    check = Checks("compare_builds_test")

    def compare(*options):
        r = subprocess.run([sys.executable, SCRIPT, *options], capture_output=True, text=True, cwd=ROOT)
        return r.returncode, r.stdout + r.stderr

    with tempfile.TemporaryDirectory() as d:
        small = ["--scenes", "quad2", "--methods", "discard", "--rates", "1,4", "--size", "32x32"]
        rc, out = compare("images", args.seamcl, args.seamcl, os.path.join(d, "same"), *small)
        check(rc == 0, f"a build against itself exits 0 (got {rc}): {out}")
        check(out.count(": identical") == 2 and "0 pair(s) over the tolerance" in out, f"both pairs identical: {out}")

        rc, out = compare("images", args.seamcl, args.seamcl, os.path.join(d, "differ"), *small,
                          "--after-args", "--aniso 1 --filter trilinear")
        check(rc == 1, f"a different after side exits 1 (got {rc}): {out}")
        match = re.search(r"quad2_discard_1: max abs difference ([0-9.e+-]+) > tolerance 0", out)
        check(match is not None and float(match.group(1)) > 0, f"the differing pair and its difference are named: {out}")
        rc, out = compare("images", args.seamcl, args.seamcl, os.path.join(d, "tolerant"), *small,
                          "--after-args", "--aniso 1 --filter trilinear", "--tolerance", "10")
        check(rc == 0 and "0 pair(s) over the tolerance" in out, f"a difference within --tolerance passes: {out}")

        rc, out = compare("speed", args.seamcl, args.seamcl, os.path.join(d, "speed"), "--size", "32x36",
                          "--msaa", "1,2", "--repeat", "1", "--rounds", "2")
        check(rc == 0, f"speed exits 0 (got {rc}): {out}")
        for tag in ("before", "after"):
            for round_index in (1, 2):
                path = os.path.join(d, "speed", f"{tag}_{round_index}.json")
                ok = os.path.exists(path)
                check(ok, f"{path} written")
                if ok:
                    with open(path) as f:
                        rates = sorted({r["msaa"] for r in json.load(f)["results"]})
                    check(rates == [1, 2], f"{path} holds rates 1 and 2 (got {rates})")
        check("traverse / discard" in out and "median over 2 round(s)" in out, f"ratios and medians printed: {out}")

        rc, out = compare("speed", args.seamcl, args.seamcl, os.path.join(d, "bad"), "--rounds", "0")
        check(rc == 2 and "--rounds and --repeat must be at least 1" in out, f"--rounds 0 refused: {out}")
        rc, out = compare("images", "/nonexistent/seamcl", args.seamcl, os.path.join(d, "gone"), *small)
        check(rc != 0 and "/nonexistent/seamcl" in out, f"a missing binary is named: {out}")

    return check.result()


if __name__ == "__main__":
    sys.exit(main())
