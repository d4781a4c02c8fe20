#!/usr/bin/env python3
"""Speed against accuracy for the cube-map seam methods, from `seamcl cube-metrics --json`.

One figure, one column per cube size n:
  row 1: time per frame (x) against the error on cube-edge pixels (y, log), one marker per method,
         the Pareto front (no other method both faster and more accurate) joined and circled;
  row 2: the seam step per mip level across the 12 edges (log y), one line per method, so the
         zero-order seams of clamp and discard and the 1x1-level jump of every method show.

    /usr/bin/python3 examples/cube_chart.py docs/results/cubemap/cube_metrics.json -o docs/results/cubemap/speed_accuracy.png
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.dont_write_bytecode = True  # no __pycache__ beside the sources
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from metrics_json import load_results  # noqa: E402

MARKERS = "osD^v<>p*h"


def load(path):
    """The results of one cube-metrics answer, checked field by field (a clear error names the field)."""
    answer, results = load_results(path, "seamcl cube-metrics --json",
                                   ("cube_method", "cube_size", "ms", "edge_error", "seam_step"))
    for k, r in enumerate(results):
        if not isinstance(r["seam_step"], list) or not r["seam_step"]:
            raise ValueError(f"{path}: results[{k}].seam_step must be a non-empty list")
    return answer, results


def pareto(points):
    """The points no other point beats in both coordinates (lower is better), by increasing x."""
    front = []
    for x, y, name in sorted(points):
        if not front or y < front[-1][1]:
            front.append((x, y, name))
    return front


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("metrics", help="the JSON of seamcl cube-metrics --json")
    parser.add_argument("-o", "--output", required=True, help="the PNG to write")
    args = parser.parse_args()
    try:
        answer, results = load(args.metrics)
    except ValueError as error:
        print(f"cube_chart: {error}", file=sys.stderr)
        return 2
    sizes = sorted({r["cube_size"] for r in results})
    methods = list(dict.fromkeys(r["cube_method"] for r in results))
    colours = {m: plt.cm.tab10(k % 10) for k, m in enumerate(methods)}
    markers = {m: MARKERS[k % len(MARKERS)] for k, m in enumerate(methods)}
    figure, axes = plt.subplots(2, len(sizes), figsize=(5.2 * len(sizes), 8.5), squeeze=False)
    for column, n in enumerate(sizes):
        rows = [r for r in results if r["cube_size"] == n]
        top, bottom = axes[0][column], axes[1][column]
        points = []
        for r in rows:
            x, y = r["ms"]["median"], r["edge_error"]["mean"]
            points.append((x, y, r["cube_method"]))
            top.scatter([x], [y], color=colours[r["cube_method"]], marker=markers[r["cube_method"]], s=60,
                        label=r["cube_method"], zorder=3)
        front = pareto(points)
        top.plot([p[0] for p in front], [p[1] for p in front], color="0.5", linestyle="--", zorder=2,
                 label="Pareto front")
        top.scatter([p[0] for p in front], [p[1] for p in front], s=220, facecolors="none", edgecolors="0.3", zorder=4)
        top.set_yscale("log")
        top.set_xlabel("ms per frame (median)")
        top.set_ylabel("error on cube-edge pixels (mean RGB 2-norm)")
        top.set_title(f"n = {n}: speed against accuracy")
        top.grid(True, which="both", alpha=0.3)
        for r in rows:
            steps = [max(s, 1e-12) for s in r["seam_step"]]
            bottom.plot(range(len(steps)), steps, color=colours[r["cube_method"]], marker=markers[r["cube_method"]],
                        label=r["cube_method"])
        bottom.set_yscale("log")
        bottom.set_xticks(range(max(len(r["seam_step"]) for r in rows)))
        bottom.set_xlabel("mip level (lod)")
        bottom.set_ylabel("seam step across the 12 edges (mean)")
        bottom.set_title(f"n = {n}: seam step per level")
        bottom.grid(True, which="both", alpha=0.3)
    axes[0][0].legend(fontsize=8, loc="best")
    axes[1][0].legend(fontsize=8, loc="best")
    figure.suptitle(f"cube-map seam methods on '{answer.get('scene', '?')}' at {answer.get('size', '?')}, "
                    f"against the environment itself (docs/results/cubemap/README.md)")
    figure.tight_layout()
    figure.savefig(args.output, dpi=110)
    print(f"cube_chart: wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
