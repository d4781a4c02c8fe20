#!/usr/bin/python3
"""examples/orbit_claims.py against seamcl itself: a small bench run whole and in two parts; the
script's claims from the whole run and from the parts pooled must agree (means to 1e-12), the
parts' frames must be named, and bad input is refused with exit 2.

    tests/orbit_claims_test.py --seamcl build/seamcl
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

from script_checks import Checks

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "examples", "orbit_claims.py")
BENCH = ["bench", "--scene", "quad2", "--size", "48x48", "--frames", "4", "--methods", "clamp,black,discard,traverse",
         "--msaa", "1,4", "--seam-mask", "footprint", "--json"]


def claims(paths, out):
    r = subprocess.run([sys.executable, SCRIPT, *paths, "-o", out], capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seamcl", required=True)
    args = ap.parse_args()
    check = Checks("orbit_claims_test")

    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, SEAMCL_CACHE_DIR=os.path.join(d, "cache"))
        runs = {}
        for name, extra in (("whole", []), ("part1", ["--shard", "1/2"]), ("part2", ["--shard", "2/2"])):
            r = subprocess.run([args.seamcl, *BENCH, *extra], capture_output=True, text=True, env=env)
            if r.returncode != 0:
                print(r.stderr)
                return 1
            runs[name] = os.path.join(d, name + ".json")
            with open(runs[name], "w") as fh:
                fh.write(r.stdout)
        code, out = claims([runs["whole"]], os.path.join(d, "whole"))
        check(code == 0, f"whole run: exit {code}: {out}")
        code, out = claims([runs["part2"], runs["part1"]], os.path.join(d, "parts"))
        check(code == 0, f"parts: exit {code}: {out}")
        if not check.failures:
            whole = json.load(open(os.path.join(d, "whole", "claims.json")))
            parts = json.load(open(os.path.join(d, "parts", "claims.json")))
            check(parts["covered"] == "0..3" and whole["covered"] == "0..3", f"covered {parts['covered']}")
            check(len(whole["entries"]) == 8, f"{len(whole['entries'])} entries")
            for a, b in zip(whole["entries"], parts["entries"]):
                key = f"{a['method']} x{a['msaa']}"
                check((a["method"], a["msaa"]) == (b["method"], b["msaa"]), key + ": order")
                for k in ("seam_mean", "mean", "off_mean"):
                    check(a[k] is not None and abs(a[k] - b[k]) <= 1e-12 * max(abs(a[k]), 1e-30),
                          f"{key} {k}: whole {a[k]} vs parts {b[k]}")
                check(a["seam_pixels"] == b["seam_pixels"] and a["seam_pixels"] > 0, key + ": seam pixels")
                check(b["seam_p99"] >= a["seam_p99"] - 1e-12, key + ": parts' p99 is an upper bound")
            ratios = whole["analysis"]["ratios"].get("traverse", {})
            check(set(ratios) == {"1", "4"}, f"discard / traverse ratios {ratios}")
            black = whole["analysis"]["controls"]["black"]["over_traverse"]
            check(all(v > 2 for v in black.values()), f"black stands apart from traverse: {black}")
            md = open(os.path.join(d, "parts", "claims.md")).read()
            check("frames 0..3 of the orbit" in md and "seam mask `footprint`" in md, "claims.md header")
        # Refusals: a part twice, parts of different batches, what is not a bench.
        code, out = claims([runs["part1"], runs["part1"]], os.path.join(d, "x"))
        check(code == 2 and "two parts cover the same frames" in out, f"part twice: {code} {out}")
        other = json.load(open(runs["part2"]))
        other["size"] = "16x16"
        bad = os.path.join(d, "other.json")
        json.dump(other, open(bad, "w"))
        code, out = claims([runs["part1"], bad], os.path.join(d, "x"))
        check(code == 2 and "'size' differs" in out, f"different batch: {code} {out}")
        json.dump({"results": []}, open(bad, "w"))
        code, out = claims([bad], os.path.join(d, "x"))
        check(code == 2 and "not a seamcl bench run with errors" in out, f"not a bench: {code} {out}")
    return check.result()


if __name__ == "__main__":
    sys.exit(main())
