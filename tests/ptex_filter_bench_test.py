#!/usr/bin/python3
"""build/seamcl_bench_ptex_filter at a tiny size (issue 42, item 5), with or without the Ptex
library: every file and filter has a device and a twin row with finite positive rates, the
device's values within 1e-4 of the twin's, rates per CPU second and cores in use too; the ptex_* rows, when the build has Ptex, within 1e-4
of the device's; a bad --queries exits 2 naming the flag; and examples/ptex_filter_ratios.py makes
the table from two such runs (medians, ratios), and from hand-written runs with known figures.

    tests/ptex_filter_bench_test.py --bench build/seamcl_bench_ptex_filter
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

from script_checks import Checks

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RATIOS = os.path.join(ROOT, "examples", "ptex_filter_ratios.py")
FILES = ("cellnoise", "cube_text")
FILTERS = ("point", "bilinear", "box", "gaussian", "bspline", "catmullrom", "mitchell")


def positive(x):
    return isinstance(x, (int, float)) and math.isfinite(x) and x > 0


def run_bench(bench, out, extra=()):
    return subprocess.run([bench, "--queries=256", "--benchmark_min_time=0.01", "--benchmark_out=" + out,
                           "--benchmark_out_format=json", *extra], capture_output=True, text=True, timeout=900)


def check_run(check, path):
    with open(path) as f:
        data = json.load(f)
    rows = {b["name"].split("/manual_time")[0]: b for b in data["benchmarks"]}
    with_ptex = data["context"].get("ptex_library") == "yes"
    check(data["context"].get("queries") == "256", "context names the query count: %r" % data["context"].get("queries"))
    check(int(data["context"].get("hardware_threads", "0")) >= 1, "context names the hardware threads")
    sides = ["device", "twin"] + (["ptex_1_thread", "ptex_all_cores"] if with_ptex else [])
    for file in FILES:
        for filt in FILTERS:
            for side in sides:
                name = "%s/%s/%s" % (side, file, filt)
                b = rows.get(name)
                if not check(b is not None, name + " is in the run"):
                    continue
                check(not b.get("error_occurred"), "%s ran without error: %s" % (name, b.get("error_message")))
                for key in ("lookups_per_s", "lookups_per_cpu_s", "cpu_per_wall"):
                    check(positive(b.get(key)), "%s: %s finite and positive: %r" % (name, key, b.get(key)))
            device = rows.get("device/%s/%s" % (file, filt), {})
            check(positive(device.get("kernel_lookups_per_s")), "device/%s/%s: kernel_lookups_per_s positive" % (file, filt))
            check(device.get("queries") == 256, "device/%s/%s: 256 queries" % (file, filt))
            d = device.get("max_abs_diff_vs_twin")
            check(isinstance(d, (int, float)) and 0 <= d <= 1e-4, "device/%s/%s: within 1e-4 of the twin: %r" % (file, filt, d))
            if with_ptex:
                for side in ("ptex_1_thread", "ptex_all_cores"):
                    b = rows.get("%s/%s/%s" % (side, file, filt), {})
                    d = b.get("max_abs_diff_vs_device")
                    check(isinstance(d, (int, float)) and 0 <= d <= 1e-4, "%s/%s/%s: within 1e-4 of the device: %r" % (side, file, filt, d))
                check(rows.get("ptex_all_cores/%s/%s" % (file, filt), {}).get("threads") == int(data["context"]["hardware_threads"]),
                      "ptex_all_cores/%s/%s runs one thread per hardware thread" % (file, filt))
    return with_ptex


def check_ratios_by_hand(check, d):
    # Two runs whose medians (means of two) and ratio are known: device 10 and 14 M/s, Ptex on all
    # cores 2 and 4: median 12 / 3 = 4.00.
    paths = []
    for i, (device, every) in enumerate(((10e6, 2e6), (14e6, 4e6))):
        data = {"context": {"ptex_library": "yes", "hardware_threads": "2"}, "benchmarks": [
            {"name": "device/cube_text/box/manual_time", "run_type": "iteration", "lookups_per_s": device,
             "kernel_lookups_per_s": 2 * device, "max_abs_diff_vs_twin": 1e-7, "lookups_per_cpu_s": device / 2,
             "cpu_per_wall": 2.0 - i},
            {"name": "twin/cube_text/box/manual_time", "run_type": "iteration", "lookups_per_s": 1e6},
            {"name": "ptex_1_thread/cube_text/box/manual_time", "run_type": "iteration", "lookups_per_s": every / 2,
             "max_abs_diff_vs_device": 3e-6 * (i + 1)},
            {"name": "ptex_all_cores/cube_text/box/manual_time", "run_type": "iteration", "lookups_per_s": every,
             "lookups_per_cpu_s": every / 4, "cpu_per_wall": 1.5},
            {"name": "device/cube_text/box/manual_time_median", "run_type": "aggregate", "lookups_per_s": 1e15}]}
        paths.append(os.path.join(d, "hand%d.json" % i))
        with open(paths[-1], "w") as f:
            json.dump(data, f)
    r = subprocess.run([sys.executable, RATIOS, *paths], capture_output=True, text=True)
    check(r.returncode == 0, "ratios of hand-written runs exit 0: %s" % r.stderr)
    check("| cube_text.ptx | box | 12.00 | 24.00 | 1.00 | 1.50 | 3.00 | 4.00 | 6.0e-06 |" in r.stdout,
          "medians, ratio 4.00 and the largest difference of hand-written runs: " + r.stdout)
    check("Ptex, 2 threads" in r.stdout, "the header names the thread count: " + r.stdout)
    # Per CPU second: device 6 / Ptex all cores 0.75 = 8.00; cores in use: median of 2 and 1, and 1.5.
    check("| cube_text.ptx | box | 6.00 | n/a | 0.75 | 8.00 | 1.50 | 1.50 |" in r.stdout,
          "per CPU second and cores in use of hand-written runs: " + r.stdout)
    # A run whose benchmark stopped with an error fails the table.
    bad = {"context": {}, "benchmarks": [{"name": "device/cellnoise/box/manual_time", "run_type": "iteration",
                                          "error_occurred": True, "error_message": "differ"}]}
    with open(os.path.join(d, "bad.json"), "w") as f:
        json.dump(bad, f)
    r = subprocess.run([sys.executable, RATIOS, os.path.join(d, "bad.json")], capture_output=True, text=True)
    check(r.returncode == 1 and "differ" in r.stderr, "a run with an error exits 1 naming it (got %d)" % r.returncode)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bench", required=True)
    args = parser.parse_args()
    check = Checks("ptex_filter_bench_test")
    with tempfile.TemporaryDirectory() as d:
        outs = []
        for i in range(2):
            outs.append(os.path.join(d, "run%d.json" % i))
            r = run_bench(args.bench, outs[-1])
            check(r.returncode == 0, "bench run %d exits 0 (got %d): %s" % (i, r.returncode, r.stderr[-2000:]))
        if os.path.exists(outs[0]):
            with_ptex = check_run(check, outs[0])
            print("ptex_filter_bench_test: Ptex library %s" % ("compared" if with_ptex else "not built in"))
        if all(os.path.exists(p) for p in outs):
            r = subprocess.run([sys.executable, RATIOS, *outs], capture_output=True, text=True)
            check(r.returncode == 0, "ratios of the two runs exit 0: %s" % r.stderr)
            wall, _, cpu = r.stdout.partition("Per CPU second")
            for table, text in (("wall", wall), ("CPU", cpu)):
                lines = [l for l in text.splitlines() if l.startswith("| ") and ".ptx |" in l]
                check(len(lines) == len(FILES) * len(FILTERS), "one %s table row per file and filter: %d" % (table, len(lines)))
            check("over 2 run(s)" in r.stdout, "the table counts its runs: " + r.stdout[:200])
        check_ratios_by_hand(check, d)
        r = run_bench(args.bench, os.path.join(d, "never.json"), ["--queries=12x"])
        check(r.returncode == 2 and "--queries" in r.stderr, "a bad --queries exits 2 naming the flag (got %d: %s)" % (r.returncode, r.stderr))
    r = subprocess.run([sys.executable, RATIOS], capture_output=True, text=True)
    check(r.returncode == 2 and "Medians of runs" in r.stdout, "no arguments: usage and exit 2 (got %d)" % r.returncode)
    return check.result()


if __name__ == "__main__":
    sys.exit(main())
