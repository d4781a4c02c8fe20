#!/usr/bin/python3
"""Charts and the paper's Table 1 from `seamcl bench --json` output.

    build/seamcl bench --scene paper --methods discard,traverse,clamp,guardband --msaa 1,2,4,8 \
        --frames 60 --reference-frames 5 --json > bench.json
    /usr/bin/python3 examples/charts.py bench.json --out docs/results

writes into --out:
  pareto.png    time per frame (median over the orbit) against seam error (mean over the seam
                mask of the reference frames), one point per method (colour) and MSAA rate
                (marker), the Pareto front (no other point both faster and more accurate)
                circled and labelled (labels placed so that none overlaps another);
  figure5.png   the paper's Figure 5: left, the fraction of pixels where ||discard - traverse||
                >= x per MSAA rate (bench's "differences"); right, the fraction of pixels that
                deviate from the reference by >= x, discard and traverse per MSAA rate; log x;
  table.md      the paper's Table 1 (median ms per method and MSAA rate) with the discard /
                traverse time ratio per rate, plus errors, NaN pixels and memory.

Needs matplotlib (Debian: python3-matplotlib); it is not needed to build or test seamcl.
"""
import argparse
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLOURS = {"discard": "tab:blue", "traverse": "tab:orange", "clamp": "tab:green", "guardband": "tab:red",
           "black": "tab:gray", "traverse-edges": "tab:brown"}
MARKERS = {1: "o", 2: "s", 4: "^", 8: "D", 16: "P"}


def load(path):
    with open(path) as f:
        return json.load(f)


def results_by(bench):
    return {(r["method"], r["msaa"]): r for r in bench["results"]}


def pareto_front(points):
    """Indices of the points (x, y) that no other point beats on both (lower is better)."""
    front = []
    for i, (x, y) in enumerate(points):
        dominated = any((x2 <= x and y2 <= y and (x2 < x or y2 < y)) for j, (x2, y2) in enumerate(points) if j != i)
        if not dominated:
            front.append(i)
    return sorted(front, key=lambda i: points[i][0])


def _overlap(a, b):
    """Area shared by two display-space boxes (x0, y0, x1, y1)."""
    w = min(a[2], b[2]) - max(a[0], b[0])
    h = min(a[3], b[3]) - max(a[1], b[1])
    return w * h if w > 0 and h > 0 else 0.0


# Offsets (points) tried for a label, nearest first: right, above, below, left, then farther out.
LABEL_OFFSETS = [(6, 4), (6, -12), (-6, 4), (-6, -12), (0, 10), (0, -16), (12, 12), (12, -20), (-12, 12),
                 (-12, -20), (18, 0), (-18, 0), (0, 22), (0, -28), (24, 18), (24, -26), (-24, 18), (-24, -26)]


def place_labels(ax, points, labels, avoid=(), fontsize=7):
    """Labels the data points without overlaps, deterministically: each label takes the first offset
    (LABEL_OFFSETS) whose box meets no label placed before it, no marker (points and `avoid`) and stays
    inside the axes; where none is free, the offset with the least overlap, joined by a thin line.
    Call after the axes' limits and scales are final."""
    fig = ax.figure
    renderer = fig.canvas.get_renderer()
    ax_box = ax.get_window_extent(renderer)
    to_px = fig.dpi / 72.0
    marker = 5 * to_px
    blocked = [(x - marker, y - marker, x + marker, y + marker)
               for x, y in (ax.transData.transform(p) for p in list(points) + list(avoid))]
    placed = []
    for (x, y), text in zip(points, labels):
        best = None
        for dx, dy in LABEL_OFFSETS:
            t = ax.annotate(text, (x, y), textcoords="offset points", xytext=(dx, dy), fontsize=fontsize,
                            ha="left" if dx >= 0 else "right", va="bottom" if dy >= 0 else "top")
            bb = t.get_window_extent(renderer)
            box = (bb.x0, bb.y0, bb.x1, bb.y1)
            t.remove()
            outside = (box[0] < ax_box.x0 or box[2] > ax_box.x1 or box[1] < ax_box.y0 or box[3] > ax_box.y1)
            cost = sum(_overlap(box, o) for o in blocked + placed) + (1e6 if outside else 0.0)
            if best is None or cost < best[0]:
                best = (cost, dx, dy, box)
            if cost == 0:
                break
        cost, dx, dy, box = best
        ax.annotate(text, (x, y), textcoords="offset points", xytext=(dx, dy), fontsize=fontsize,
                    ha="left" if dx >= 0 else "right", va="bottom" if dy >= 0 else "top",
                    arrowprops=dict(arrowstyle="-", lw=0.5, color="0.4") if abs(dx) + abs(dy) > 14 else None)
        placed.append(box)


def chart_pareto(bench, out, error_key="seam_mean"):
    rs = [r for r in bench["results"] if "error" in r]
    if not rs:
        print("charts: no errors in the bench JSON (--no-errors); skipping pareto.png", file=sys.stderr)
        return None
    pts = [(r["ms"]["median"], r["error"][error_key]) for r in rs]
    front = pareto_front(pts)
    fig, ax = plt.subplots(figsize=(8.5, 5))
    for r, (x, y) in zip(rs, pts):
        ax.scatter(x, y, color=COLOURS.get(r["method"], "k"), marker=MARKERS.get(r["msaa"], "x"), s=50, zorder=3)
        # min..max over the orbit's frames
        ax.plot([r["ms"]["min"], r["ms"]["max"]], [y, y], color=COLOURS.get(r["method"], "k"), alpha=0.25, lw=1)
    fx = [pts[i][0] for i in front]
    fy = [pts[i][1] for i in front]
    ax.step(fx, fy, where="post", color="k", lw=1, ls="--", label="Pareto front")
    ax.scatter(fx, fy, facecolors="none", edgecolors="k", s=140, lw=1.2, zorder=4)
    for m, c in COLOURS.items():
        if any(r["method"] == m for r in rs):
            ax.scatter([], [], color=c, label=m)
    ax.set_xscale("log")
    ax.set_yscale("log")
    for r in sorted({r["msaa"] for r in rs}):
        ax.scatter([], [], color="k", marker=MARKERS.get(r, "x"), facecolors="none", label=f"{r}x MSAA")
    ax.set_xlabel("time per frame, ms (median over the orbit; bar: min..max)")
    ax.set_ylabel(f"error vs reference: {error_key} (2-norm, linear RGB)")
    ax.set_title(f'{bench["scene"]} {bench["size"]}, {bench["frames"]} frames, '
                 f'errors on {len(bench.get("error_frames", []))}')
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1), title="colour: method, marker: rate",
              title_fontsize=7)
    fig.tight_layout()
    place_labels(ax, [pts[i] for i in front], [f'{rs[i]["method"]} {rs[i]["msaa"]}x' for i in front], avoid=pts)
    path = os.path.join(out, "pareto.png")
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def chart_figure5(bench, out, curve_key="curve"):
    by = results_by(bench)
    diffs = sorted(bench.get("differences", []), key=lambda d: d["msaa"])
    rates = sorted({r["msaa"] for r in bench["results"]})
    cmap = plt.get_cmap("viridis")
    colour = {m: cmap(i / max(1, len(rates) - 1)) for i, m in enumerate(rates)}
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.8))
    for d in diffs:
        xs, ys = zip(*d[curve_key])
        left.plot(xs, ys, color=colour.get(d["msaa"], "k"), label=f'{d["msaa"]}x')
    left.set_title("Difference between Traverse and Discard")
    for m in rates:
        for method, ls in (("traverse", "--"), ("discard", "-")):
            r = by.get((method, m))
            if r is None or curve_key not in r:
                continue
            xs, ys = zip(*r[curve_key])
            right.plot(xs, ys, color=colour[m], ls=ls, label=f"{method.capitalize()} {m}x")
    # The controls, at the lowest and highest rate only (every rate would bury the methods).
    for m in sorted({rates[0], rates[-1]}):
        for method, ls in (("clamp", ":"), ("black", "-.")):
            r = by.get((method, m))
            if r is not None and curve_key in r:
                xs, ys = zip(*r[curve_key])
                right.plot(xs, ys, color=colour[m], ls=ls, lw=1, label=f"{method.capitalize()} {m}x (control)")
    right.set_title("Deviation from the reference (solid: Discard, dashed: Traverse)")
    for ax in (left, right):
        ax.set_xscale("log")
        ax.set_xlim(1e-4, 1)
        # log y: the tails (the few pixels with large errors, where seam methods differ) stay visible
        ax.set_yscale("log")
        ax.set_ylim(1e-5, 1.05)
        ax.set_xlabel("x: 2-norm distance in linear RGB")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    where = "pixels near seams" if curve_key == "seam_curve" else "all pixels"
    for ax in (left, right):
        ax.set_ylabel(f"fraction of {where} with distance >= x")
    fig.suptitle(f'{bench["scene"]} {bench["size"]}: {bench["frames"]}-frame orbit '
                 f'(differences on every frame, reference errors on {len(bench.get("error_frames", []))})',
                 fontsize=10)
    fig.tight_layout()
    name = "figure5_seams.png" if curve_key == "seam_curve" else "figure5.png"
    path = os.path.join(out, name)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def table_md(bench):
    by = results_by(bench)
    rates = sorted({r["msaa"] for r in bench["results"]})
    methods = list(dict.fromkeys(r["method"] for r in bench["results"]))
    head = "| method | " + " | ".join(f"{m}x" for m in rates) + " |"
    sep = "| --- |" + " ---: |" * len(rates)
    lines = [f'Median time per frame in ms (OpenCL profiling, {bench["frames"]}-frame orbit of '
             f'`{bench["scene"]}` at {bench["size"]}, aniso {bench["results"][0]["aniso"]}; '
             f'device: {bench.get("device", "?")})', "", head, sep]
    for method in methods:
        cells = [f'{by[(method, m)]["ms"]["median"]:.2f}' if (method, m) in by else "" for m in rates]
        lines.append(f"| {method.capitalize()} | " + " | ".join(cells) + " |")
    if any(("discard", m) in by and ("traverse", m) in by for m in rates):
        cells = []
        for m in rates:
            if ("discard", m) in by and ("traverse", m) in by:
                cells.append(f'**{by[("discard", m)]["ms"]["median"] / by[("traverse", m)]["ms"]["median"]:.2f}**')
            else:
                cells.append("")
        lines.append("| Discard / Traverse | " + " | ".join(cells) + " |")
        lines += ["", "The paper's Table 1 ratios, for comparison: GTX680 0.49 / 0.59 / 0.62 / 0.73, "
                  "Iris Pro 5200 0.35 / 0.46 / 0.46 / 0.60 (1x / 2x / 4x / 8x)."]
    # bench's --seam-mask; a part or bench without the field used the band
    seam = ("the pixels whose texture footprint crosses a face edge, per rate"
            if bench.get("seam_mask", "band") == "footprint" else "within 2 px of a face edge")
    lines += ["", "Per entry: time spread over the frames, errors against the reference (mean over the reference "
              f"frames' pixels; seam = {seam}), NaN/Inf pixels over every frame, temporal change on the "
              "seam pixels (mean per-pixel ||frame k - frame k-1||), memory.", "",
              "| method | msaa | ms median | ms min | ms max | spread | error mean | seam mean | seam p99 | "
              "NaN/Inf px | temporal (seam) | texture bytes | padding | adjacency |",
              "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for r in bench["results"]:
        e = r.get("error")
        err = (f'{e["mean"]:.3e} | {e["seam_mean"]:.3e} | {e["seam_p99"]:.3e}' if e else "- | - | -")
        lines.append(f'| {r["method"]} | {r["msaa"]} | {r["ms"]["median"]:.2f} | {r["ms"]["min"]:.2f} | '
                     f'{r["ms"]["max"]:.2f} | {r["ms"]["spread"]:.2f} | {err} | {r["nan_pixels"]} | '
                     f'{r["temporal"]["seam_mean"]:.3e} | {r["texture_bytes"]} | {r["padding_bytes"]} | '
                     f'{r["adjacency_bytes"]} |')
    if bench.get("differences"):
        lines += ["", "Difference Discard vs Traverse (2-norm per pixel, linear RGB) per MSAA rate, over every frame:", "",
                  "| msaa | mean | seam mean | p99 | seam p99 |", "| ---: | ---: | ---: | ---: | ---: |"]
        for d in sorted(bench["differences"], key=lambda d: d["msaa"]):
            lines.append(f'| {d["msaa"]} | {d["mean"]:.3e} | {d["seam_mean"]:.3e} | {d["p99"]:.3e} | '
                         f'{d["seam_p99"]:.3e} |')
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("bench_json", help="output of seamcl bench --json ('-' for stdin)")
    ap.add_argument("--out", default=".", help="directory for the PNGs and table.md [.]")
    args = ap.parse_args(argv)
    bench = json.load(sys.stdin) if args.bench_json == "-" else load(args.bench_json)
    os.makedirs(args.out, exist_ok=True)
    written = [chart_pareto(bench, args.out), chart_figure5(bench, args.out),
               chart_figure5(bench, args.out, "seam_curve")]
    path = os.path.join(args.out, "table.md")
    with open(path, "w") as f:
        f.write(table_md(bench))
    written.append(path)
    for p in written:
        if p:
            print(p)
    return 0


if __name__ == "__main__":
    sys.exit(main())
