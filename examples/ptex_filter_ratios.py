#!/usr/bin/env python3
"""Medians of runs of build/seamcl_bench_ptex_filter, as the table of docs/benchmarks.md.

    for i in 1 2 3; do
      build/seamcl_bench_ptex_filter --benchmark_out=ptex$i.json --benchmark_out_format=json
    done
    examples/ptex_filter_ratios.py ptex1.json ptex2.json ptex3.json

Prints, per file and filter, the median lookups/s (millions) of the device (upload, kernel and
readback), of the kernel alone, of the scalar twin on one thread and, when the runs were built
against the Ptex library, of PtexFilter on one thread and on every core, with device / Ptex all
cores (issue 42's goal: at least 2) and the largest difference between the two sides' values; then
the same per CPU second of the process, with the cores each side kept busy (CPU s / wall s), which
tell a side's own speed from the share of a machine that other jobs left it.
Exits 1 when a run holds a benchmark that stopped with an error (values that disagree).
"""
import json
import math
import statistics
import sys

SIDES = ("device", "twin", "ptex_1_thread", "ptex_all_cores")


def load(paths):
    """{(side, file, filter): {counter: [value per run]}}, errors, the runs' context."""
    rows, errors, context = {}, [], {}
    for path in paths:
        try:
            with open(path) as f:
                data = json.load(f)
            benchmarks = data["benchmarks"]
        except (OSError, ValueError, KeyError, TypeError) as e:
            raise SystemExit("ptex_filter_ratios: %s: not a Google Benchmark JSON file (%s)" % (path, e))
        context = data.get("context", {})
        for b in benchmarks:
            if b.get("run_type", "iteration") != "iteration":
                continue
            name = b["name"].split("/iterations:")[0].split("/manual_time")[0]
            parts = name.split("/")
            if len(parts) != 3 or parts[0] not in SIDES:
                continue
            if b.get("error_occurred"):
                errors.append("%s: %s: %s" % (path, name, b.get("error_message", "")))
                continue
            slot = rows.setdefault(tuple(parts), {})
            for key in ("lookups_per_s", "kernel_lookups_per_s", "lookups_per_cpu_s", "cpu_per_wall",
                        "max_abs_diff_vs_device", "max_abs_diff_vs_twin"):
                if key in b:
                    slot.setdefault(key, []).append(float(b[key]))
    return rows, errors, context


def median(rows, side, file, filt, key="lookups_per_s"):
    values = rows.get((side, file, filt), {}).get(key)
    return statistics.median(values) if values else None


def worst(rows, side, file, filt, key):
    values = rows.get((side, file, filt), {}).get(key)
    return max(values) if values else None


def main(argv):
    if len(argv) < 2:
        print(__doc__)
        return 2
    rows, errors, context = load(argv[1:])
    # Files in name order, each file's filters in the benchmark's own order (rows keep it).
    seen = list(dict.fromkeys((f, k) for (_, f, k) in rows))
    keys = sorted(seen, key=lambda fk: (fk[0], seen.index(fk)))
    for e in errors:
        print("ERROR:", e, file=sys.stderr)
    if not keys:
        print("ptex_filter_ratios: no device/, twin/ or ptex_*/ benchmarks in %s" % ", ".join(argv[1:]), file=sys.stderr)
        return 1
    cores = context.get("hardware_threads", "?")
    bad_rates = []

    def m(x):
        return "%.2f" % (x / 1e6) if x is not None else "n/a"

    print("Median lookups/s (millions) over %d run(s); Ptex library: %s" % (len(argv) - 1, context.get("ptex_library", "?")))
    print()
    print("| file | filter | seamcl device | kernel alone | twin, 1 thread | Ptex, 1 thread | Ptex, %s threads "
          "| device / Ptex all cores | max abs diff |" % cores)
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for file, filt in keys:
        device = median(rows, "device", file, filt)
        kernel = median(rows, "device", file, filt, "kernel_lookups_per_s")
        twin = median(rows, "twin", file, filt)
        one = median(rows, "ptex_1_thread", file, filt)
        every = median(rows, "ptex_all_cores", file, filt)
        ratio = "%.2f" % (device / every) if device and every else "n/a"
        diffs = [d for d in (worst(rows, "ptex_1_thread", file, filt, "max_abs_diff_vs_device"),
                             worst(rows, "device", file, filt, "max_abs_diff_vs_twin")) if d is not None]
        diff = "%.1e" % max(diffs) if diffs else "n/a"
        for x in (device, kernel, twin, one, every):
            if x is not None and not (math.isfinite(x) and x > 0):
                bad_rates.append("%s/%s: a rate that is not a positive number: %r" % (file, filt, x))
        print("| %s.ptx | %s | %s | %s | %s | %s | %s | %s | %s |" % (file, filt, m(device), m(kernel), m(twin), m(one),
                                                                    m(every), ratio, diff))
    print()
    print("Per CPU second of the process (millions of lookups), and the cores in use (CPU s / wall s):")
    print()
    print("| file | filter | seamcl device | Ptex, 1 thread | Ptex, %s threads | device / Ptex all cores "
          "| cores: device | cores: Ptex all |" % cores)
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for file, filt in keys:
        device = median(rows, "device", file, filt, "lookups_per_cpu_s")
        one = median(rows, "ptex_1_thread", file, filt, "lookups_per_cpu_s")
        every = median(rows, "ptex_all_cores", file, filt, "lookups_per_cpu_s")
        ratio = "%.2f" % (device / every) if device and every else "n/a"
        busy = [median(rows, side, file, filt, "cpu_per_wall") for side in ("device", "ptex_all_cores")]
        print("| %s.ptx | %s | %s | %s | %s | %s | %s | %s |" % (file, filt, m(device), m(one), m(every), ratio,
                                                              *("%.2f" % b if b is not None else "n/a" for b in busy)))
    for e in bad_rates:
        print("ERROR:", e, file=sys.stderr)
    return 1 if errors or bad_rates else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
