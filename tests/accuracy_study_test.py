#!/usr/bin/python3
"""The accuracy study's Python parts: FLIP behaves, and examples/accuracy_study.py --quick makes
valid results (JSON, Markdown, charts) from the real seamcl.

Usage: accuracy_study_test.py --seamcl build/seamcl

Fails (exit 1), never skips, when matplotlib, numpy or flip-evaluator cannot be imported:
scripts/install-deps installs all three for /usr/bin/python3, which CMake registers this test with.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

sys.dont_write_bytecode = True  # no __pycache__ beside the sources
HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLES = os.path.join(os.path.dirname(HERE), "examples")

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def flip_checks():
    import numpy as np
    sys.path.insert(0, EXAMPLES)
    import accuracy_study as study

    rng = np.random.default_rng(1)
    img = rng.random((40, 56, 3), dtype=np.float32)
    fmap, mean = study.flip_map(img, img.copy())
    check(mean == 0.0 and float(fmap.max()) == 0.0, f"FLIP of an image against itself is 0 (got {mean})")
    black = np.zeros((40, 56, 3), np.float32)
    white = np.ones((40, 56, 3), np.float32)
    fmap, mean = study.flip_map(black, white)
    check(mean > 0.8 and fmap.shape == (40, 56), f"FLIP of black against white is large (> 0.8, got {mean:.3f})")
    noisy = np.clip(img + 0.05 * rng.standard_normal(img.shape).astype(np.float32), 0, 1)
    _, small = study.flip_map(img, noisy)
    check(0.0 < small < mean, f"FLIP of slight noise lies between (0 < {small:.3f} < {mean:.3f})")


def reading_checks():
    """The study reads compare's answer by name: with several references (results[].errors{name},
    references[], seam_mask.by_msaa, reference_<name>.png, seam_mask_msaa<N>.png) as with one
    (results[].error, reference.png, seam_mask.png). A synthetic answer and images, no seamcl."""
    import numpy as np
    import matplotlib.pyplot as plt
    sys.path.insert(0, EXAMPLES)
    import accuracy_study as study

    rng = np.random.default_rng(2)
    ref = rng.random((24, 32, 3)).astype(np.float32)
    box = np.clip(ref * 0.9, 0, 1)
    mask = np.zeros((24, 32, 3), np.float32)
    mask[:, 14:18] = 1
    curve = [[x, 0.5] for x in study.thresholds()]
    err = {"mean": 0.02, "p99": 0.1, "seam_mean": 0.04, "seam_p99": 0.2, "off_seam_mean": 0.015,
           "off_seam_p99": 0.08, "nan_pixels": 0, "pixels": 768, "seam_pixels": 96, "seam_coverage": 0.125}
    with tempfile.TemporaryDirectory() as d:
        plt.imsave(os.path.join(d, "reference.png"), ref)
        plt.imsave(os.path.join(d, "reference_box.png"), box)
        plt.imsave(os.path.join(d, "seam_mask_msaa4.png"), mask)
        plt.imsave(os.path.join(d, "discard_msaa4.png"), ref)
        plt.imsave(os.path.join(d, "traverse_msaa4.png"), np.clip(ref + 0.1, 0, 1))
        results = [{"method": m, "msaa": 4, "ms": {"median": 1.0, "min": 1.0, "max": 1.0}, "error": err,
                    "errors": {"paper": err, "box": dict(err, seam_mean=0.05 if m == "discard" else 0.04)},
                    "curve": curve, "seam_curve": curve} for m in ("discard", "traverse")]
        cmp = {"size": "32x24", "references": [{"name": "paper"}, {"name": "box"}], "results": results,
               "seam_mask": {"definition": "footprint", "by_msaa": {"4": {"pixels": 96, "coverage": 0.125}}}}
        check(study.reference_names(cmp) == ["paper", "box"], "reference names from references[]")
        paper = study.measure_run(cmp, d, "paper")
        boxed = study.measure_run(cmp, d, "box")
        check(paper[0]["curve_source"] == "compare" and boxed[0]["curve_source"] == "png",
              "curves: compare's for the first reference, from the PNGs for the others")
        check(paper[0]["off_mean"] == 0.015 and paper[0]["mask_coverage"] == 0.125,
              "off-seam mean and the mask's coverage read by name")
        check(paper[0]["flip_mean"] == 0.0 and boxed[0]["flip_mean"] > 0.0,
              "FLIP against each reference's own image (discard equals the paper reference here)")
        check(abs(boxed[0]["seam_curve"][0][1] - 1.0) < 1e-9 and boxed[0]["flip_seam_mean"] is not None,
              "the mask of the entry's rate is read (seam_mask_msaa4.png)")
        r = study.analyse_run(boxed)["ratios"]["traverse"]
        check(abs(r["4"] - 1.25) < 1e-9, f"Discard/Traverse ratio against the named reference ({r})")
        one = {"size": "32x24", "reference": {"method": "traverse"}, "seam_pixels": 96,
               "results": [{k: v for k, v in x.items() if k != "errors"} for x in results]}
        old = study.measure_run(one, d)
        check(old[0]["seam_mean"] == 0.04 and study.mask_coverage(one, 4) == 96 / 768.0,
              "a one-reference answer (results[].error, seam_pixels) reads too")


def finite(v):
    return isinstance(v, (int, float)) and math.isfinite(v)


def study_checks(seamcl):
    with tempfile.TemporaryDirectory(prefix="seamcl-study-test-") as out:
        cmd = [sys.executable, os.path.join(EXAMPLES, "accuracy_study.py"), "--quick", "--seamcl", seamcl,
               "--out", out, "--cache", os.path.join(out, "cache")]
        print("running: " + " ".join(cmd), flush=True)
        proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=900)
        sys.stdout.write(proc.stderr[-3000:])
        check(proc.returncode == 0, f"accuracy_study.py --quick exits 0 (got {proc.returncode})")
        if proc.returncode != 0:
            return
        check("study [1/" in proc.stderr, "the study prints its progress on stderr")
        with open(os.path.join(out, "results.json")) as f:
            res = json.load(f)
        regimes = {r["name"]: r for r in res["regimes"]}
        check("cube" in regimes and "cube-constant" in regimes, f"the quick regimes ran: {sorted(regimes)}")
        for s in res["skipped"]:
            print(f"note: skipped {s}")
        methods, rates = res["methods"], res["rates"]
        check({"clamp", "black", "discard", "traverse", "guardband"} <= set(methods), f"every method ran: {methods}")
        check(rates == [1, 2, 4, 8, 16], f"every MSAA rate ran: {rates}")
        for reg in res["regimes"]:
            for run in reg["runs"]:
                where = f"{reg['name']}/{run['reference']}"
                got = {(e["method"], e["msaa"]) for e in run["entries"]}
                check(got == {(m, r) for m in methods for r in rates}, f"{where}: one entry per method x rate")
                keys = ["ms", "seam_mean", "seam_p99", "off_mean", "off_p99", "mean", "flip_mean", "flip_seam_mean"]
                bad = [(e["method"], e["msaa"], k) for e in run["entries"] for k in keys if not finite(e.get(k))]
                check(not bad, f"{where}: every figure is a finite number {bad[:3]}")
                check(all(0.0 <= e["flip_mean"] <= 1.0 for e in run["entries"]), f"{where}: FLIP means in [0, 1]")
                cov = run["mask_coverage"]
                check(sorted(cov, key=int) == [str(r) for r in rates] and all(0.0 < v < 1.0 for v in cov.values()),
                      f"{where}: the seam mask's coverage per rate lies in (0, 1): {cov}")
                ratios = run["analysis"]["ratios"].get("traverse", {})
                check(sorted(ratios, key=int) == [str(r) for r in rates] and all(finite(v) and v > 0 for v in ratios.values()),
                      f"{where}: a Discard/Traverse ratio per rate {ratios}")
                verdicts = [c["verdict"] for c in run["analysis"]["claims"].get("traverse", [])]
                check(len(verdicts) == 4 and set(verdicts) <= {"holds", "fails"}, f"{where}: the 4 claims judged {verdicts}")
                for c in run["analysis"]["claims"]["traverse"]:
                    r = c["ratio"]
                    tie = res["tie_tolerance"]
                    expect = {1: r > 1 + tie, 2: r > 1 + tie, 4: abs(r - 1) <= res["even_tolerance"], 8: r < 1 - tie}[c["rate"]]
                    check((c["verdict"] == "holds") == expect, f"{where}: verdict of '{c['claim']}' follows its ratio {r:.3f}")
        # The constant control: clamp, discard, traverse and guardband carry no texture error at seams,
        # so their errors match exactly (same geometry, same colour).
        const = regimes.get("cube-constant")
        if const:
            e = {(x["method"], x["msaa"]): x for x in const["runs"][0]["entries"]}
            same = all(abs(e[("clamp", r)]["seam_mean"] - e[("traverse", r)]["seam_mean"]) <= 1e-6 for r in rates)
            check(same, "constant colour: clamp's seam error equals traverse's at every rate")
        with open(os.path.join(out, "results.md")) as f:
            md = f.read()
        check("## The paper's claims" in md and "| cube | " in md, "results.md holds the claims table")
        check("build/seamcl compare --json" in md, "results.md shows the compare commands")
        for name in res["figures"]:
            path = os.path.join(out, name)
            with open(path, "rb") as f:
                head = f.read(8)
            check(head == b"\x89PNG\r\n\x1a\n" and os.path.getsize(path) > 10000, f"{name} is a PNG chart")
        for kind in ("pareto", "figure5", "heatmaps"):
            check(any(n.startswith(kind + "_cube") for n in res["figures"]), f"a {kind} chart for cube")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seamcl", required=True)
    args = ap.parse_args()
    try:
        import flip_evaluator  # noqa: F401
        import matplotlib  # noqa: F401
        import numpy  # noqa: F401
    except ImportError as e:
        print(f"FAIL {e}: scripts/install-deps installs python3-matplotlib, python3-numpy and flip-evaluator "
              f"for /usr/bin/python3 (this is {sys.executable})")
        return 1
    flip_checks()
    reading_checks()
    study_checks(os.path.abspath(args.seamcl))
    print(f"{len(failures)} failed" if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
