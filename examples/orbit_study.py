#!/usr/bin/python3
"""The paper's Figure 5 over a camera orbit: frames of an N-frame orbit (the paper used 1000),
each a `seamcl compare --frame K --frames N --images DIR --json`, pooled.

Which frames: --start, --stride and --count (or --frame-list), so a subset of the orbit stands for
it (the paper's 1000 frames take hours here: run with --count 1 first, the script prints the time
per frame and the extrapolated time for the whole orbit). --budget-min stops starting new frames
once the next one would not fit, and says which frames were done.

Pooled over the frames: errors (means weighted by pixel counts, the curves as pixel fractions, p99
read off the pooled curve), FLIP (mean over every pixel of every frame, and over the seam masks),
the Discard / Traverse seam-error ratio per rate and the paper's claims judged by the rules of
accuracy_study.py, the time (median over frames of compare's per-frame medians). Writes into --out:
orbit.json, orbit.md and figure5_orbit.png (left: Discard vs Traverse difference from the images;
middle and right: deviation from the reference over all pixels and over the seam mask).

    nice -n 10 /usr/bin/python3 examples/orbit_study.py --count 1 --out /tmp/orbit     # time one frame
    nice -n 10 /usr/bin/python3 examples/orbit_study.py --frames 1000 --stride 50 --budget-min 20
"""
import argparse
import json
import os
import shlex
import shutil
import statistics
import sys
import tempfile
import time

import numpy as np

sys.dont_write_bytecode = True  # no __pycache__ beside the sources
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import accuracy_study as study  # noqa: E402
from accuracy_study import plt, Line2D  # noqa: E402

log = study.log


class Pool:
    """Pixel-weighted sums of an entry's figures over frames."""

    def __init__(self):
        self.n = self.s = self.o = 0
        self.sum_all = self.sum_seam = self.sum_off = 0.0
        self.curve = self.seam_curve = self.off_curve = None
        self.flip_sum = self.flip_seam_sum = self.flip_off_sum = 0.0
        self.flip_n = self.flip_s = self.flip_o = 0
        self.ms = []
        self.nan = 0

    @staticmethod
    def _add_curve(acc, curve, weight):
        if not curve:
            return acc
        c = np.array(curve, dtype=float)
        c[:, 1] *= weight
        if acc is None:
            return c
        acc[:, 1] += c[:, 1]
        return acc

    def add(self, entry, raw, mask_pixels, all_pixels):
        e = raw.get("error", {})
        n, s = e.get("pixels", all_pixels), e.get("seam_pixels", mask_pixels)
        o = e.get("off_seam_pixels", n - s)  # the footprint mask's boundary pixels are in neither
        self.sum_all += e["mean"] * n
        self.sum_seam += e["seam_mean"] * s
        if entry.get("off_mean") is not None:
            self.sum_off += entry["off_mean"] * o
        self.curve = self._add_curve(self.curve, raw.get("curve"), n)
        self.seam_curve = self._add_curve(self.seam_curve, raw.get("seam_curve"), s)
        self.off_curve = self._add_curve(self.off_curve, entry.get("off_curve"), o)
        self.n, self.s, self.o = self.n + n, self.s + s, self.o + o
        if entry.get("flip_mean") is not None:
            self.flip_sum += entry["flip_mean"] * all_pixels
            self.flip_n += all_pixels
        if entry.get("flip_seam_mean") is not None:
            self.flip_seam_sum += entry["flip_seam_mean"] * mask_pixels
            self.flip_s += mask_pixels
        if entry.get("flip_off_mean") is not None:
            self.flip_off_sum += entry["flip_off_mean"] * o
            self.flip_o += o
        self.ms.append(entry["ms"])
        self.nan += e.get("nan_pixels", 0) or 0

    def figures(self, method, msaa):
        def curve(acc, total):
            if acc is None or total == 0:
                return None
            return [[float(x), float(f / total)] for x, f in acc]

        c, sc, oc = curve(self.curve, self.n), curve(self.seam_curve, self.s), curve(self.off_curve, self.o)
        return {"method": method, "msaa": msaa, "ms": statistics.median(self.ms), "ms_min": min(self.ms),
                "ms_max": max(self.ms), "mean": self.sum_all / self.n if self.n else None,
                "seam_mean": self.sum_seam / self.s if self.s else None,
                "off_mean": self.sum_off / self.o if self.o else None,
                "p99": study.quantile_from_curve(c, 0.99), "seam_p99": study.quantile_from_curve(sc, 0.99),
                "off_p99": study.quantile_from_curve(oc, 0.99), "off_source": "pooled",
                "flip_mean": self.flip_sum / self.flip_n if self.flip_n else None,
                "flip_seam_mean": self.flip_seam_sum / self.flip_s if self.flip_s else None,
                "flip_off_mean": self.flip_off_sum / self.flip_o if self.flip_o else None,
                "nan_pixels": self.nan, "curve": c, "seam_curve": sc, "off_curve": oc}


def chart(res, out):
    entries = res["entries"]
    rates = sorted({e["msaa"] for e in entries})
    colour = study.rate_colours(rates)
    b = study.by_key(entries)
    trav = study.traverse_variants({e["method"] for e in entries})
    trav = trav[0] if trav else None
    fig, axes = plt.subplots(1, 3, figsize=(15, 5))
    for rate in rates:
        d = res["differences"].get(str(rate))
        if d and d.get("curve"):
            xs, ys = zip(*d["curve"])
            axes[0].plot(xs, np.maximum(ys, 1e-7), color=colour[rate])
    axes[0].set_title(f"Difference between Discard and {trav}\n(all pixels; from the 8-bit PNGs)", fontsize=9)
    for ax, key, where in ((axes[1], "curve", "all pixels"), (axes[2], "seam_curve", "seam mask")):
        for rate in rates:
            for m, ls in (("discard", "-"), (trav, "--")):
                e = b.get((m, rate))
                if e and e.get(key):
                    xs, ys = zip(*e[key])
                    ax.plot(xs, np.maximum(ys, 1e-7), color=colour[rate], ls=ls)
        for m, ls in (("clamp", ":"), ("black", "-.")):
            for rate, grey in ((rates[0], "0.35"), (rates[-1], "0.65")):
                e = b.get((m, rate))
                if e and e.get(key):
                    xs, ys = zip(*e[key])
                    ax.plot(xs, np.maximum(ys, 1e-7), color=grey, ls=ls, lw=1)
        ax.set_title(f"Deviation from the {res['reference']} reference\n({where})", fontsize=9)
    for ax in axes:
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(1e-4, 1)
        ax.set_ylim(1e-5, 1.2)
        ax.grid(True, which="both", alpha=0.25)
        ax.set_xlabel("x: 2-norm distance, linear RGB")
        ax.set_ylabel("fraction of pixels with distance >= x")
    handles = [Line2D([], [], color=colour[r], label=f"{r}x MSAA") for r in rates]
    handles += [Line2D([], [], color="k", ls="-", label="Discard"), Line2D([], [], color="k", ls="--", label=f"Traverse ({trav})")]
    if any(e["method"] == "clamp" for e in entries):
        handles += [Line2D([], [], color="0.35", ls=":", label=f"clamp {rates[0]}x"),
                    Line2D([], [], color="0.65", ls=":", label=f"clamp {rates[-1]}x")]
    if any(e["method"] == "black" for e in entries):
        handles += [Line2D([], [], color="0.35", ls="-.", label=f"black {rates[0]}x"),
                    Line2D([], [], color="0.65", ls="-.", label=f"black {rates[-1]}x")]
    fig.legend(handles=handles, loc="lower center", ncol=min(10, len(handles)), fontsize=8)
    frames = res["frames_done"]
    fig.suptitle(f"compare {res['scene_args']}, {res['size']}: Figure 5 of the paper over {len(frames)} frames of a "
                 f"{res['orbit_frames']}-frame orbit ({study.frame_span(frames)}); lower left is better", fontsize=10)
    fig.tight_layout(rect=(0, 0.08, 1, 0.94))
    path = os.path.join(out, "figure5_orbit.png")
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def orbit_md(res):
    L = [f"# Orbit: {len(res['frames_done'])} frames of a {res['orbit_frames']}-frame orbit", "",
         f"Made by `{res['command']}` on {res['device']}: {res['wall_s'] / 60:.1f} min wall, "
         f"{res['frame_wall_s_median']:.1f} s per frame (median; reference included), so the whole "
         f"{res['orbit_frames']}-frame orbit would take about {res['extrapolated_orbit_h']:.1f} h here.", "",
         f"Frames: {study.frame_span(res['frames_done'])}. Each: `{shlex.join(res['frame_command'])}` "
         "(K the frame).", ""]
    if res.get("stopped"):
        L += [f"Stopped early: {res['stopped']}", ""]
    L += ["| method | msaa | ms (median) | seam mean | seam p99 | off mean | all mean | all p99 | FLIP | FLIP seam | NaN px |",
          "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    f = study.fmt
    for e in res["entries"]:
        L.append(f"| {e['method']} | {e['msaa']} | {e['ms']:.1f} | {f(e['seam_mean'])} | {f(e['seam_p99'])} | "
                 f"{f(e['off_mean'])} | {f(e['mean'])} | {f(e['p99'])} | {f(e['flip_mean'], '.4f')} | "
                 f"{f(e['flip_seam_mean'], '.4f')} | {e['nan_pixels']} |")
    L += ["", "p99: read off the pooled curve (log interpolation, 10 thresholds per decade).", ""]
    for t, claims in res["analysis"]["claims"].items():
        r = res["analysis"]["ratios"][t]
        fr = res["analysis"]["flip_ratios"].get(t, {})
        L += [f"Discard / {t} seam error per rate: " + ", ".join(f"{k}x {v:.3f}" for k, v in r.items()) +
              (("; FLIP over the mask: " + ", ".join(f"{k}x {v:.3f}" for k, v in fr.items())) if fr else ""), ""]
        L += ["| claim | rule | ratio | verdict |", "| --- | --- | ---: | --- |"]
        L += [f"| {c['claim']} | {c['rule'].replace('|', chr(92) + '|')} | {f(c['ratio'], '.3f')} | {c['verdict']} |"
              for c in claims]
        L.append("")
    return "\n".join(L) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("--seamcl", default=os.path.join(study.ROOT, "build", "seamcl"))
    ap.add_argument("--out", default=os.path.join(study.ROOT, "docs", "results", "accuracy", "orbit"))
    ap.add_argument("--scene-args", default="--scene paper", help="compare arguments of the scene [--scene paper]")
    ap.add_argument("--frames", type=int, default=1000, help="frames in the orbit [1000, the paper's]")
    ap.add_argument("--start", type=int, default=0)
    ap.add_argument("--stride", type=int, default=50, help="every K-th frame [50]")
    ap.add_argument("--count", type=int, help="at most this many frames")
    ap.add_argument("--frame-list", help="comma list of frames (instead of start/stride)")
    ap.add_argument("--methods", default="clamp,black,discard,traverse-edges,traverse")
    ap.add_argument("--msaa", default="1,2,4,8,16")
    ap.add_argument("--size", default="480x540", help="[480x540, the paper's]")
    ap.add_argument("--reference", help="reference name, where compare offers a choice [its default]")
    ap.add_argument("--repeat", type=int, default=1, help="timed renders per entry and frame [1]")
    ap.add_argument("--budget-min", type=float, help="start no frame that would end past this many minutes")
    ap.add_argument("--cache", help="reference cache (compare's --cache)")
    ap.add_argument("--no-flip", action="store_true")
    args = ap.parse_args(argv)

    if not args.no_flip:
        study.flip_module()
    binary = study.Binary(args.seamcl)
    methods = [m for m in args.methods.split(",") if m in binary.methods]
    frames = ([int(x) for x in args.frame_list.split(",")] if args.frame_list
              else list(range(args.start, args.frames, args.stride)))
    if args.count:
        frames = frames[:args.count]
    if not frames or any(not 0 <= k < args.frames for k in frames):
        ap.error(f"frames must lie in 0..{args.frames - 1}")
    base = shlex.split(args.scene_args) + ["--methods", ",".join(methods), "--msaa", args.msaa, "--size", args.size,
                                          "--repeat", str(args.repeat), "--frames", str(args.frames)]
    if args.reference:
        opt = binary.reference_option()
        if opt is None:
            ap.error("this seamcl compare offers no choice of reference")
        base += [opt, args.reference]
    if args.cache:
        base += ["--cache", args.cache]
    os.makedirs(args.out, exist_ok=True)
    work = tempfile.mkdtemp(prefix="seamcl-orbit-")
    pools, diffs, walls, done, device, stopped = {}, {}, [], [], "?", None
    t0 = time.monotonic()
    for i, k in enumerate(frames):
        elapsed = time.monotonic() - t0
        if args.budget_min and walls and elapsed + max(walls) > args.budget_min * 60:
            stopped = (f"--budget-min {args.budget_min:g}: after {len(done)} of {len(frames)} frames "
                       f"({elapsed / 60:.1f} min), the next would not fit")
            log("orbit: " + stopped)
            break
        eta = f", about {statistics.median(walls) * (len(frames) - i) / 60:.1f} min left" if walls else ""
        log(f"orbit [{i + 1}/{len(frames)}] frame {k} of {args.frames} ({elapsed / 60:.1f} min so far{eta})")
        images = os.path.join(work, str(k))
        os.makedirs(images, exist_ok=True)
        t_frame = time.monotonic()
        cmp, cmd, _ = study.run_compare(binary, base + ["--frame", str(k)], images)
        device = cmp.get("device", device)
        entries = study.measure_run(cmp, images, with_flip=not args.no_flip)
        w, h = (int(v) for v in cmp["size"].split("x"))
        for e, raw in zip(entries, cmp["results"]):
            mask_pixels = int(round(e["mask_coverage"] * w * h))
            pools.setdefault((e["method"], e["msaa"]), Pool()).add(e, raw, mask_pixels, w * h)
        run = {"images_dir": images, "compare": cmp, "entries": entries}
        for rate, d in study.image_differences(run).items():
            acc = diffs.setdefault(rate, {"n": 0, "curve": None, "sum": 0.0})
            n = w * h
            acc["curve"] = Pool._add_curve(acc["curve"], d["curve"], n)
            acc["sum"] += d["mean"] * n
            acc["n"] += n
        shutil.rmtree(images, ignore_errors=True)
        walls.append(time.monotonic() - t_frame)
        done.append(k)
        log(f"orbit   frame {k}: {walls[-1]:.1f} s")
    shutil.rmtree(work, ignore_errors=True)

    entries = [p.figures(m, r) for (m, r), p in pools.items()]
    entries.sort(key=lambda e: (methods.index(e["method"]), e["msaa"]))
    frame_cmd = ["build/seamcl", "compare", "--json", "--images", "DIR"] + base + ["--frame", "K"]
    med = statistics.median(walls) if walls else 0.0
    res = {"command": shlex.join(["python3", "examples/orbit_study.py"] + (argv if argv is not None else sys.argv[1:])),
           "frame_command": frame_cmd, "device": device, "scene_args": args.scene_args, "size": args.size,
           "reference": args.reference or "paper", "orbit_frames": args.frames, "frames_planned": frames,
           "frames_done": done, "stopped": stopped, "frame_wall_s": walls, "frame_wall_s_median": med,
           "extrapolated_orbit_h": med * args.frames / 3600.0, "wall_s": time.monotonic() - t0,
           "entries": entries, "analysis": study.analyse_run(entries),
           "differences": {str(r): {"curve": [[float(x), float(f / d["n"])] for x, f in d["curve"]],
                                    "mean": d["sum"] / d["n"]} for r, d in sorted(diffs.items()) if d["n"]}}
    study.dump_json(res, os.path.join(args.out, "orbit.json"))
    with open(os.path.join(args.out, "orbit.md"), "w") as f:
        f.write(orbit_md(res))
    paths = [os.path.join(args.out, n) for n in ("orbit.json", "orbit.md")]
    if entries:
        paths.append(chart(res, args.out))
    for p in paths:
        print(p)
    log(f"orbit: {len(done)} frames in {res['wall_s'] / 60:.1f} min, {med:.1f} s per frame; "
        f"{args.frames} frames would take about {res['extrapolated_orbit_h']:.1f} h")
    return 0 if done else 1


if __name__ == "__main__":
    sys.exit(main())
