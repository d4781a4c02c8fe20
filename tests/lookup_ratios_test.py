#!/usr/bin/python3
"""examples/lookup_ratios.py on two hand-written benchmark runs: medians over the runs' iteration
rows (aggregate rows left out), the ratios from those medians, issue 14's goals, and the usage text
without arguments.

    tests/lookup_ratios_test.py
"""
import json
import os
import subprocess
import sys
import tempfile

from script_checks import Checks

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "examples", "lookup_ratios.py")


def run_file(rates, probes):
    benchmarks = [{"name": name + "/iterations:1/manual_time", "run_type": "iteration", "lookups_per_s": rate}
                  for name, rate in rates.items()]
    benchmarks[0]["mean_probes"] = probes
    # An aggregate row whose rate would move every median if it were counted.
    benchmarks.append({"name": "seamcl/trilinear/rgba8_median", "run_type": "aggregate", "lookups_per_s": 1e12})
    return {"benchmarks": benchmarks}


def main():
    check = Checks("lookup_ratios_test")

    runs = [
        {"seamcl/aniso16/rgba8": 10e6, "seamcl/trilinear/rgba8": 60e6, "oiio/aniso16/f32": 1e6,
         "oiio/trilinear/f32": 4e6, "seamcl/aniso16/rgba32f": 9e6, "seamcl/trilinear/rgba32f": 50e6},
        {"seamcl/aniso16/rgba8": 12e6, "seamcl/trilinear/rgba8": 70e6, "oiio/aniso16/f32": 1e6,
         "oiio/trilinear/f32": 6e6, "seamcl/aniso16/rgba32f": 11e6, "seamcl/trilinear/rgba32f": 54e6},
    ]
    with tempfile.TemporaryDirectory() as d:
        paths = []
        for i, rates in enumerate(runs):
            path = os.path.join(d, f"run{i}.json")
            with open(path, "w") as f:
                json.dump(run_file(rates, 9.0), f)
            paths.append(path)
        r = subprocess.run([sys.executable, SCRIPT, *paths], capture_output=True, text=True)
        out = r.stdout
        check(r.returncode == 0, f"exit 0 (got {r.returncode}): {r.stderr}")
        # Medians of two runs: their means.
        check("| `seamcl/trilinear/rgba8` | 65.00 |" in out, "trilinear rgba8 median 65 M/s, the aggregate row left out: " + out)
        check("| `oiio/trilinear/f32` | 5.00 |" in out, "OIIO trilinear median 5 M/s: " + out)
        check("mean aniso probe count N = 9.00" in out, "mean probes 9: " + out)
        # aniso16 / OIIO: rgba32f 10 / 1, rgba8 11 / 1; trilinear: 52 / 5, 65 / 5.
        check("| seamcl aniso16 / OIIO aniso | 10.00 | 11.00 | >= 10 |" in out, "aniso ratios and goal: " + out)
        check("| seamcl trilinear / OIIO trilinear | 10.40 | 13.00 | >= 25 |" in out, "trilinear ratios and goal: " + out)
        # aniso / (trilinear / probes): 10 / (52 / 9), 11 / (65 / 9).
        check("| seamcl aniso16 / (seamcl trilinear / mean probes) | 1.73 | 1.52 | >= 1.3 |" in out,
              "probe-normalised ratios and goal: " + out)
        check("| seamcl bilinear / OIIO bilinear (NoMIP) | n/a | n/a |" in out, "cases not run read n/a: " + out)
    r = subprocess.run([sys.executable, SCRIPT], capture_output=True, text=True)
    check(r.returncode == 2 and "Medians and ratios" in r.stdout, f"no arguments: usage and exit 2 (got {r.returncode})")
    return check.result()


if __name__ == "__main__":
    sys.exit(main())
