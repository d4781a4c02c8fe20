#!/usr/bin/python3
"""examples/orbit_claims.py against seamcl itself: a small bench run whole and in two parts; the
script's claims from the whole run and from the parts pooled must agree (means to 1e-12), the
parts' frames must be named, and bad input is refused with exit 2. With the whole run's images
(`bench --images`), examples/orbit_flip.py's FLIP goes beside the errors (`--flip`): every entry
gets its FLIP means, the black control stands apart, and FLIP of other frames is refused.

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
ORBIT_FLIP = os.path.join(ROOT, "examples", "orbit_flip.py")
BENCH = ["bench", "--scene", "quad2", "--size", "48x48", "--frames", "4", "--methods", "clamp,black,discard,traverse",
         "--msaa", "1,4", "--seam-mask", "footprint", "--json"]


def claims(paths, out, extra=()):
    r = subprocess.run([sys.executable, SCRIPT, *paths, "-o", out, *extra], capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def orbit_flip(*arguments):
    r = subprocess.run([sys.executable, ORBIT_FLIP, *arguments], capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seamcl", required=True)
    args = ap.parse_args()
    check = Checks("orbit_claims_test")

    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, SEAMCL_CACHE_DIR=os.path.join(d, "cache"))
        runs = {}
        images = os.path.join(d, "images")
        for name, extra in (("whole", ["--images", images]), ("part1", ["--shard", "1/2"]), ("part2", ["--shard", "2/2"])):
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
        # FLIP of the whole run's frames beside its errors.
        flip = os.path.join(d, "flip.json")
        code, out = orbit_flip("measure", images, "-o", flip, "--jobs", "2")
        check(code == 0, f"orbit_flip measure: exit {code}: {out}")
        code, out = claims([runs["whole"]], os.path.join(d, "flip"), ["--flip", flip])
        check(code == 0 and "discard / traverse seam FLIP 1x" in out, f"claims --flip: exit {code}: {out}")
        if code == 0:
            with_flip = json.load(open(os.path.join(d, "flip", "claims.json")))
            for e in with_flip["entries"]:
                check(all(e.get(k) is not None and 0.0 <= e[k] <= 1.0 for k in ("flip_mean", "flip_seam_mean")),
                      f"{e['method']} x{e['msaa']}: FLIP means in [0, 1]: {e.get('flip_mean')}, {e.get('flip_seam_mean')}")
            by = {(e["method"], e["msaa"]): e for e in with_flip["entries"]}
            # FLIP is bounded by 1 and saturates at black's seams, so it parts the controls less
            # than the error does (which the check above holds to 2x).
            check(by[("black", 1)]["flip_seam_mean"] > 1.5 * by[("traverse", 1)]["flip_seam_mean"],
                  f"FLIP sets the black control apart: {by[('black', 1)]['flip_seam_mean']} against "
                  f"{by[('traverse', 1)]['flip_seam_mean']}")
            check(set(with_flip["analysis"]["flip_ratios"].get("traverse", {})) == {"1", "4"},
                  f"discard / traverse FLIP ratios {with_flip['analysis']['flip_ratios']}")
            md = open(os.path.join(d, "flip", "claims.md")).read()
            check("| seam FLIP mean |" in md and "Discard / traverse seam FLIP per rate" in md, "claims.md FLIP table")
            # FLIP of other frames than the bench's error frames is refused.
            other_frames = json.load(open(flip))
            other_frames["frames"] = [f + 1 for f in other_frames["frames"]]
            bad_flip = os.path.join(d, "other_frames.json")
            json.dump(other_frames, open(bad_flip, "w"))
            code, out = claims([runs["whole"]], os.path.join(d, "x"), ["--flip", bad_flip])
            check(code == 2 and "FLIP of frames" in out, f"FLIP of other frames: {code} {out}")
        code, out = orbit_flip("pool", flip, flip, "-o", os.path.join(d, "twice.json"))
        check(code == 2 and "is also in" in out, f"orbit_flip pool of one part twice: {code} {out}")
        code, out = orbit_flip("measure", d, "-o", os.path.join(d, "none.json"))
        check(code == 2 and "no frame_<k> folders" in out, f"orbit_flip measure without frames: {code} {out}")
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
