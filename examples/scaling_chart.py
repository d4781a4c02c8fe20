#!/usr/bin/env python3
"""Time against problem size, from `seamcl bench --sweep ... --json` (host/batch/scaling_sweep.h).

One panel per sweep (pixels, faces, msaa, texels), log-log: the median frame time of each method
at each point (min..max as error bars), and dashed ideal lines through each method's first point:
time proportional to x (slope 1: what pixels and samples should cost) and constant time (slope 0:
what faces and texels at equal pixels should cost). The issue's targets, where the sweep has one,
are written under the panel with the measured ratio.

    /usr/bin/python3 examples/scaling_chart.py docs/results/scaling/sweep.json -o docs/results/scaling/scaling.png
"""
import argparse
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

MARKERS = "osD^v<>p*h"


def load(path):
    """The sweeps of one answer, checked field by field (a clear error names the field)."""
    try:
        with open(path) as f:
            answer = json.load(f)
    except (OSError, json.JSONDecodeError) as error:
        raise ValueError(f"{path}: {error}") from error
    if not isinstance(answer, dict) or answer.get("kind") != "scaling_sweep":
        raise ValueError(f"{path}: 'kind' must be \"scaling_sweep\" (seamcl bench --sweep ... --json)")
    sweeps = answer.get("sweeps")
    if not isinstance(sweeps, list) or not sweeps:
        raise ValueError(f"{path}: 'sweeps' must be a non-empty list")
    for s, sweep in enumerate(sweeps):
        for field in ("axis", "x_label", "points", "ratios"):
            if not isinstance(sweep, dict) or field not in sweep:
                raise ValueError(f"{path}: sweeps[{s}].{field} is missing")
        points = sweep["points"]
        if not isinstance(points, list) or len(points) < 2:
            raise ValueError(f"{path}: sweeps[{s}].points must list at least 2 points")
        for p, point in enumerate(points):
            where = f"sweeps[{s}].points[{p}]"
            if not isinstance(point, dict) or not isinstance(point.get("x"), (int, float)) or point["x"] <= 0:
                raise ValueError(f"{path}: {where}.x must be a positive number")
            results = point.get("results")
            if not isinstance(results, list) or not results:
                raise ValueError(f"{path}: {where}.results must be a non-empty list")
            for r, result in enumerate(results):
                ms = result.get("ms") if isinstance(result, dict) else None
                if not isinstance(ms, dict) or not all(isinstance(ms.get(k), (int, float)) for k in ("median", "min", "max")):
                    raise ValueError(f"{path}: {where}.results[{r}].ms needs median, min and max")
                if not isinstance(result.get("method"), str):
                    raise ValueError(f"{path}: {where}.results[{r}].method must be a string")
    return answer, sweeps


def series(sweep):
    """method -> ([x], [median], [min], [max]) in point order."""
    out = {}
    for point in sweep["points"]:
        for result in point["results"]:
            xs, med, lo, hi = out.setdefault(result["method"], ([], [], [], []))
            xs.append(point["x"])
            med.append(result["ms"]["median"])
            lo.append(result["ms"]["min"])
            hi.append(result["ms"]["max"])
    return out


def ratio_text(sweep):
    lines = []
    for r in sweep["ratios"]:
        line = f"{r['method']}: {r['x_ratio']:.1f}x {sweep['axis']} -> {r['time_ratio']:.2f}x time"
        if r.get("max_time_ratio") is not None:
            line += f" (target <= {r['max_time_ratio']:g}x: {'met' if r['met'] else 'MISSED'})"
        lines.append(line)
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("sweep", help="the JSON of seamcl bench --sweep ... --json")
    parser.add_argument("-o", "--output", required=True, help="the PNG to write")
    args = parser.parse_args()
    try:
        answer, sweeps = load(args.sweep)
    except ValueError as error:
        print(f"scaling_chart: {error}", file=sys.stderr)
        return 2

    figure, axes = plt.subplots(1, len(sweeps), figsize=(5.2 * len(sweeps), 5.6), squeeze=False)
    methods = sorted({r["method"] for s in sweeps for p in s["points"] for r in p["results"]})
    colours = {m: plt.get_cmap("tab10")(k % 10) for k, m in enumerate(methods)}
    for panel, sweep in zip(axes[0], sweeps):
        for k, (method, (xs, med, lo, hi)) in enumerate(series(sweep).items()):
            colour = colours[method]
            panel.errorbar(xs, med, yerr=[[m - a for m, a in zip(med, lo)], [b - m for m, b in zip(med, hi)]],
                           color=colour, marker=MARKERS[k % len(MARKERS)], capsize=3, label=f"{method} (median)")
            x0, t0 = xs[0], med[0]
            panel.plot([x0, xs[-1]], [t0, t0 * xs[-1] / x0], color=colour, linestyle="--", alpha=0.6,
                       label=f"{method}: ideal, time ~ x")
            panel.plot([x0, xs[-1]], [t0, t0], color=colour, linestyle=":", alpha=0.6,
                       label=f"{method}: ideal, constant time")
        panel.set_xscale("log")
        panel.set_yscale("log")
        panel.set_xlabel(sweep["x_label"])
        panel.set_ylabel("ms per frame (OpenCL profiling)")
        panel.set_title(f"time against {sweep['axis']}")
        panel.grid(True, which="both", alpha=0.3)
        panel.legend(fontsize=7, loc="upper left")
        panel.text(0.0, -0.2, ratio_text(sweep), transform=panel.transAxes, fontsize=7, va="top")
    options = answer.get("options", {})
    figure.suptitle(f"scaling on '{options.get('scene', '?')}' ({answer.get('device', '?')}), "
                    f"median of {answer.get('repeats', '?')} renders per point (docs/results/scaling/README.md)")
    figure.tight_layout()
    figure.savefig(args.output, dpi=100)
    print(f"scaling_chart: wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
