#!/usr/bin/env python3
"""Zero-order against first-order seam error for the cube-map seam methods, from `seamcl cube-metrics --json`.

One column per cube size n, one marker per method, both axes log:
  row 1: x = the seam step at lod 0 (mean |f(face A) - f(face B)| just either side of the 12 edges),
         y = first_order_band (the lookup's slope against the environment's over one level-0 texel
         either side of the edge, where clamped taps flatten the lookup);
  row 2: the same x against first_order_jump (slope B - slope A from points 0.25 and 0.75 texel
         inside), the older measure, which compares two slopes and misses the flat band.
The post's trade-off (stretch and warp remove the zero-order seam but keep a first-order one) is
a marker that moves left without moving down.

    /usr/bin/python3 examples/cube_orders_chart.py docs/results/cubemap/cube_metrics.json -o docs/results/cubemap/zero_vs_first_order.png
"""
import argparse
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.dont_write_bytecode = True  # no __pycache__ beside the sources
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from metrics_json import load_results  # noqa: E402

MARKERS = "osD^v<>p*hXP"
# A seam step of 0 (bit for bit equal sides) cannot sit on a log axis: it is drawn at this floor.
FLOOR = 1e-7


def load(path):
    """The results of one cube-metrics answer, checked field by field (a clear error names the field)."""
    answer, results = load_results(path, "seamcl cube-metrics --json",
                                   ("cube_method", "cube_size", "seam_step", "first_order_band", "first_order_jump"))
    for k, r in enumerate(results):
        if not isinstance(r["seam_step"], list) or not r["seam_step"]:
            raise ValueError(f"{path}: results[{k}].seam_step must be a non-empty list")
    return answer, results


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("metrics", help="the JSON of seamcl cube-metrics --json")
    parser.add_argument("-o", "--output", required=True, help="the PNG to write")
    args = parser.parse_args()
    try:
        answer, results = load(args.metrics)
    except ValueError as error:
        print(f"cube_orders_chart: {error}", file=sys.stderr)
        return 2
    sizes = sorted({r["cube_size"] for r in results})
    methods = list(dict.fromkeys(r["cube_method"] for r in results))
    colours = {m: plt.cm.tab20(k % 20) for k, m in enumerate(methods)}
    markers = {m: MARKERS[k % len(MARKERS)] for k, m in enumerate(methods)}
    figure, axes = plt.subplots(2, len(sizes), figsize=(5.4 * len(sizes), 9.0), squeeze=False)
    for column, n in enumerate(sizes):
        rows = [r for r in results if r["cube_size"] == n]
        for row, key, label in ((0, "first_order_band", "first-order band error (mean |slope - true slope|, per texel)"),
                                (1, "first_order_jump", "first-order jump (older measure)")):
            ax = axes[row][column]
            # Methods that land on one spot (clamp and discard, seamless and border, ...) share one label.
            spots = {}
            for r in rows:
                x = max(r["seam_step"][0], FLOOR)
                y = max(r[key], FLOOR)
                ax.scatter([x], [y], color=colours[r["cube_method"]], marker=markers[r["cube_method"]], s=70,
                           label=r["cube_method"], zorder=3)
                spot = (round(math.log10(x) * 20), round(math.log10(y) * 20))
                spots.setdefault(spot, (x, y, []))[2].append(r["cube_method"].replace("cube-", ""))
            for x, y, names in spots.values():
                ax.annotate(" / ".join(names), (x, y), textcoords="offset points", xytext=(5, 4), fontsize=7)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel(f"zero order: seam step at lod 0 (mean; {FLOOR:g} = none)")
            ax.set_ylabel(label)
            ax.set_title(f"n = {n}")
            ax.grid(True, which="both", alpha=0.3)
    axes[0][0].legend(fontsize=7, loc="best")
    figure.suptitle(f"zero- against first-order seam error on '{answer.get('scene', '?')}', level 0, trilinear lookups "
                    f"against the environment itself (docs/results/cubemap/README.md)")
    figure.tight_layout()
    figure.savefig(args.output, dpi=110)
    print(f"cube_orders_chart: wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
