#!/usr/bin/env python3
"""Medians and ratios from one or more runs of the lookup benchmark.

    build/seamcl_bench_lookups --benchmark_out=run1.json --benchmark_out_format=json
    ...
    examples/lookup_ratios.py run1.json run2.json run3.json

Prints the median lookups/s of each benchmark over the files and the ratios
seamcl aniso16 / OIIO aniso, seamcl trilinear / OIIO trilinear, seamcl bilinear / OIIO bilinear
and aniso / (trilinear / mean probe count), for each storage format, as a Markdown table, with
issue 14's goals (those the benchmark itself and scripts/speed-targets print).
"""
import json
import statistics
import sys


def load(paths):
    rates, probes = {}, []
    for path in paths:
        with open(path) as f:
            data = json.load(f)
        for b in data["benchmarks"]:
            if b.get("run_type", "iteration") != "iteration":
                continue
            name = b["name"].split("/iterations:")[0]
            rates.setdefault(name, []).append(float(b["lookups_per_s"]))
            if "mean_probes" in b:
                probes.append(float(b["mean_probes"]))
    return {k: statistics.median(v) for k, v in rates.items()}, (statistics.median(probes) if probes else None)


def main(argv):
    if len(argv) < 2:
        print(__doc__)
        return 2
    rates, probes = load(argv[1:])
    print(f"| benchmark | median lookups/s (M) over {len(argv) - 1} run(s) |")
    print("| --- | ---: |")
    for name in sorted(rates):
        print(f"| `{name}` | {rates[name] / 1e6:.2f} |")
    print()

    def ratio(a, b):
        return f"{rates[a] / rates[b]:.2f}" if a in rates and b in rates else "n/a"

    print(f"mean aniso probe count N = {probes:.2f}" if probes else "mean aniso probe count: n/a")
    print()
    print("| ratio | rgba32f | rgba8 | goal |")
    print("| --- | ---: | ---: | --- |")
    rows = [
        ("seamcl aniso16 / OIIO aniso", "seamcl/aniso16/{}", "oiio/aniso16/f32", ">= 10"),
        ("seamcl trilinear / OIIO trilinear", "seamcl/trilinear/{}", "oiio/trilinear/f32", ">= 25"),
        ("seamcl bilinear / OIIO bilinear (NoMIP)", "seamcl/bilinear/{}", "oiio/bilinear/f32", ""),
    ]
    for label, ours, theirs, goal in rows:
        print(f"| {label} | {ratio(ours.format('rgba32f'), theirs)} | {ratio(ours.format('rgba8'), theirs)} | {goal} |")
    cells = []
    for fmt in ("rgba32f", "rgba8"):
        a, t = rates.get(f"seamcl/aniso16/{fmt}"), rates.get(f"seamcl/trilinear/{fmt}")
        cells.append(f"{a / (t / probes):.2f}" if a and t and probes else "n/a")
    print(f"| seamcl aniso16 / (seamcl trilinear / mean probes) | {cells[0]} | {cells[1]} | >= 1.3 |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
