#!/usr/bin/env python3
"""Watertightness against cost for the displacement methods, from `seamcl displacement-metrics --json`.

One figure, three panels:
  left:   crack pixels over the orbit (y, symlog: 0 is drawn) against time per frame (x), one
          colour per method, one marker per tessellation level T;
  middle: the largest position gap between vertices two patches share (exact, not a tolerance),
          per method; watertight methods are exactly 0 and say so;
  right:  time per frame (solid) and of the tessellation stage alone (dashed) against T (log-log),
          one colour per method, the extra bytes in the legend.

    /usr/bin/python3 examples/displacement_chart.py docs/results/displacement/metrics.json \\
        -o docs/results/displacement/methods.png
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
FIELDS = ("method", "tessellation", "max_gap", "crack_pixels", "frame_ms", "tessellate_ms", "extra_bytes")


def load(path):
    """The results of one displacement-metrics answer, checked field by field (errors name the field)."""
    answer, results = load_results(path, "seamcl displacement-metrics --json", FIELDS)
    for k, r in enumerate(results):
        for field in ("tessellation", "max_gap", "frame_ms", "tessellate_ms", "extra_bytes"):
            if not isinstance(r[field], (int, float)) or r[field] < 0:
                raise ValueError(f"{path}: results[{k}].{field} must be a number >= 0")
        if r["crack_pixels"] is not None and (not isinstance(r["crack_pixels"], int) or r["crack_pixels"] < 0):
            raise ValueError(f"{path}: results[{k}].crack_pixels must be null (open mesh) or an integer >= 0")
    return answer, results


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("metrics", help="the JSON of seamcl displacement-metrics --json")
    parser.add_argument("-o", "--output", required=True, help="the PNG to write")
    args = parser.parse_args()
    try:
        answer, results = load(args.metrics)
    except ValueError as error:
        print(f"displacement_chart: {error}", file=sys.stderr)
        return 2

    methods = list(dict.fromkeys(r["method"] for r in results))
    levels = sorted({r["tessellation"] for r in results})
    colours = {m: plt.cm.tab10(i % 10) for i, m in enumerate(methods)}
    markers = {t: MARKERS[i % len(MARKERS)] for i, t in enumerate(levels)}
    counted = any(r["crack_pixels"] is not None for r in results)

    fig, (ax_cracks, ax_gap, ax_time) = plt.subplots(1, 3, figsize=(17, 5.2))
    title = (f"Displacement methods on '{answer.get('scene', '?')}' {answer.get('size', '?')}, "
             f"MSAA {answer.get('msaa', '?')}, map level {answer.get('level', '?')}")
    fig.suptitle(title)

    # Left: speed against cracks.
    for r in results:
        if r["crack_pixels"] is None:
            continue
        ax_cracks.scatter(r["frame_ms"], r["crack_pixels"], color=colours[r["method"]],
                          marker=markers[r["tessellation"]], s=60, edgecolors="black", linewidths=0.5)
    ax_cracks.set_yscale("symlog", linthresh=1)
    ax_cracks.set_xscale("log")
    ax_cracks.set_xlabel("time per frame, ms (median)")
    ax_cracks.set_ylabel(f"crack pixels over {answer.get('crack_frames', '?')} orbit frames")
    ax_cracks.set_title("Cracks against speed (0 = watertight)" if counted else "Open mesh: cracks not counted")
    ax_cracks.grid(True, which="both", alpha=0.3)
    handles = [plt.Line2D([], [], color=colours[m], marker="o", linestyle="", label=m) for m in methods]
    handles += [plt.Line2D([], [], color="grey", marker=markers[t], linestyle="", label=f"T = {t}") for t in levels]
    ax_cracks.legend(handles=handles, fontsize=8, loc="center right")

    # Middle: the exact gap, per method (the largest over every T).
    gaps = [max(r["max_gap"] for r in results if r["method"] == m) for m in methods]
    bars = ax_gap.bar(range(len(methods)), gaps, color=[colours[m] for m in methods])
    for bar, gap in zip(bars, gaps):
        label = "0 (exact)" if gap == 0 else f"{gap:.3g}"
        ax_gap.annotate(label, (bar.get_x() + bar.get_width() / 2, bar.get_height()), ha="center", va="bottom",
                        fontsize=9, xytext=(0, 2), textcoords="offset points")
    ax_gap.set_xticks(range(len(methods)), methods, rotation=20)
    ax_gap.set_ylabel("largest gap between shared vertices (object units)")
    ax_gap.set_title("Position gap at shared edges and corners")
    ax_gap.set_ylim(0, max(max(gaps) * 1.2, 1e-3))

    # Right: time against T.
    for m in methods:
        points = sorted((r["tessellation"], r["frame_ms"], r["extra_bytes"], r["tessellate_ms"])
                        for r in results if r["method"] == m)
        ax_time.plot([p[0] for p in points], [p[1] for p in points], color=colours[m], marker="o",
                     label=f"{m} (+{points[-1][2]} B)")
        stage = [(p[0], p[3]) for p in points if p[3] > 0]
        ax_time.plot([p[0] for p in stage], [p[1] for p in stage], color=colours[m], marker=".", linestyle="--")
    ax_time.set_xscale("log", base=2)
    ax_time.set_yscale("log")
    ax_time.set_xlabel("tessellation level T (patch = (T+1)^2 vertices)")
    ax_time.set_ylabel("ms (median): frame solid, tessellation stage dashed")
    ax_time.set_title("Cost per frame and of the stage; legend: extra bytes")
    ax_time.grid(True, which="both", alpha=0.3)
    ax_time.legend(fontsize=8)

    fig.tight_layout()
    fig.savefig(args.output, dpi=110)
    print(f"displacement_chart: wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
