#!/usr/bin/python3
"""The paper's claims judged over a whole orbit measured by `seamcl bench` (or a farm's merged.json).

    scripts/farm --shards 20 --workers 1 --out OUT -- --scene paper --frames 1000 --reference-frames 10 \\
        --methods clamp,black,discard,traverse-edges,traverse --msaa 1,2,4,8 --seam-mask footprint
    /usr/bin/python3 examples/orbit_claims.py OUT/merged.json -o docs/results/accuracy/orbit
    /usr/bin/python3 examples/orbit_claims.py OUT/shards/part-*.json -o DIR   # the parts done so far
    /usr/bin/python3 examples/orbit_claims.py OUT/merged.json --flip OUT/flip.json -o DIR   # a farm --flip batch

Reads the bench JSON's pooled errors (every pixel of every error frame) and writes into -o. Given
several parts of one batch (`--shard K/N` runs, e.g. while a farm is still running), it pools them
itself: means weighted by their pixel counts (as `seamcl merge` does), p99 the largest part's (an
upper bound of the pooled p99, as merge's), the time the median of every frame's time; claims.md
says which frames the parts cover. Files:
  claims.md    per method and rate: median ms, seam mean and p99, off-seam and all-pixel mean; the
               Discard / Traverse seam-error ratio per rate and the paper's claims judged by the
               rules of accuracy_study.py; the clamp and black controls over traverse;
  claims.json  the same, with the bench's batch options.
With --flip (examples/orbit_flip.py's pooled figures of the same error frames, e.g. a `farm --flip`
batch's flip.json) every entry also gets its FLIP means (all pixels, seam mask, off it) and the
Discard / Traverse seam FLIP ratio per rate is given beside the error's.
Refuses (exit 2) a JSON that is not a bench run with errors. Needs only the standard library and
accuracy_study.py's rules (it imports matplotlib, like every chart here).
"""
import argparse
import json
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ beside the sources
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import accuracy_study as study  # noqa: E402


BATCH_KEYS = ("scene", "size", "frames", "reference_frames", "seam_mask", "options", "errors")


def weighted(parts, key, weight):
    total = sum(p[weight] for p in parts)
    return sum(p[key] * p[weight] for p in parts) / total if total else None


def entries_of(benches):
    """Per (method, rate), the errors of every bench in `benches` pooled (one bench: its own)."""
    out = []
    for i, r in enumerate(benches[0]["results"]):
        rs = [b["results"][i] for b in benches]
        if any((x["method"], x["msaa"]) != (r["method"], r["msaa"]) for x in rs):
            raise ValueError(f"results[{i}]: the parts list different entries")
        es = [x["error"] for x in rs]
        ms = sorted(t for x in rs for t in x["ms_per_frame"])
        out.append({"method": r["method"], "msaa": r["msaa"],
                    "ms": r["ms"]["median"] if len(rs) == 1 else ms[len(ms) // 2] if len(ms) % 2 else
                    (ms[len(ms) // 2 - 1] + ms[len(ms) // 2]) / 2,
                    "seam_mean": weighted(es, "seam_mean", "seam_pixels"), "seam_p99": max(e["seam_p99"] for e in es),
                    "off_mean": weighted(es, "off_seam_mean", "off_seam_pixels") if all("off_seam_mean" in e for e in es)
                    else None,
                    "mean": weighted(es, "mean", "pixels"), "p99": max(e["p99"] for e in es),
                    "seam_pixels": sum(e["seam_pixels"] for e in es), "pixels": sum(e["pixels"] for e in es),
                    "frames": sum(e["frames"] for e in es), "nan_pixels": sum(x["nan_pixels"] for x in rs)})
    return out


def frame_blocks(benches):
    spans = sorted((b["shard"]["first_frame"], b["shard"]["end_frame"]) for b in benches)
    blocks = []
    for first, end in spans:
        if blocks and blocks[-1][1] == first:
            blocks[-1][1] = end
        else:
            blocks.append([first, end])
    return ", ".join(f"{a}..{e - 1}" for a, e in blocks)


def add_flip(entries, flip, error_frames, path):
    """Each entry's FLIP means from orbit_flip.py's pooled figures; ValueError when they are of
    other entries or other frames."""
    by_entry = {(e["method"], e["msaa"]): e for e in flip["entries"]}
    if sorted(by_entry) != sorted((e["method"], e["msaa"]) for e in entries):
        raise ValueError(f"{path}: FLIP of other entries than the bench's")
    if sorted(flip["frames"]) != sorted(error_frames):
        raise ValueError(f"{path}: FLIP of frames {flip['frames'][:3]}... ({len(flip['frames'])}), "
                         f"the bench's error frames are {sorted(error_frames)[:3]}... ({len(error_frames)})")
    for e in entries:
        f = by_entry[(e["method"], e["msaa"])]
        e.update({key: f[key] for key in ("flip_mean", "flip_seam_mean", "flip_off_mean")})


def claims_md(benches, entries, analysis, source):
    f = study.fmt
    bench = benches[0]
    frames = bench["frames"]
    error_frames = sum(len(b["error_frames"]) for b in benches)
    L = [f"# {bench['scene']}: the paper's claims over a {frames}-frame orbit", "",
         f"From {source}: `seamcl bench` at {bench['size']}, frames {frame_blocks(benches)} of the orbit timed, "
         f"errors on {error_frames} of them (every {bench['reference_frames']}th) against the "
         f"{bench['reference']['method']} 8x reference, seam mask `{bench.get('seam_mask', 'band')}`; device "
         f"{bench['device']}.", "",
         "Off-seam mean: `-` where the bench did not pool it. p99 of several parts: the largest part's (an upper bound).", "",
         "| method | msaa | ms (median) | seam mean | seam p99 | off-seam mean | all mean | all p99 | seam px / frame | NaN px |",
         "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for e in entries:
        L.append(f"| {e['method']} | {e['msaa']} | {e['ms']:.1f} | {f(e['seam_mean'])} | {f(e['seam_p99'])} | "
                 f"{f(e['off_mean'])} | {f(e['mean'])} | {f(e['p99'])} | "
                 f"{e['seam_pixels'] / max(e['frames'], 1):.0f} | {e['nan_pixels']} |")
    L.append("")
    for t, claims in analysis["claims"].items():
        r = analysis["ratios"][t]
        L += [f"Discard / {t} seam error per rate: " + ", ".join(f"{k}x {v:.3f}" for k, v in r.items()), "",
              "| claim | rule | ratio | verdict |", "| --- | --- | ---: | --- |"]
        L += [f"| {c['claim']} | {c['rule'].replace('|', chr(92) + '|')} | {f(c['ratio'], '.3f')} | {c['verdict']} |"
              for c in claims]
        L.append("")
    for c, v in analysis["controls"].items():
        L.append(f"Control {c} / traverse seam error per rate: " +
                 ", ".join(f"{k}x {x:.3f}" for k, x in v["over_traverse"].items()))
    L.append("")
    if any("flip_mean" in e for e in entries):
        L += [f"FLIP (flip-evaluator, LDR, its default viewing condition) of every entry's image against the "
              f"reference on each of the {error_frames} error frames, pooled over their pixels:", "",
              "| method | msaa | FLIP mean | seam FLIP mean | off-seam FLIP mean |", "| --- | ---: | ---: | ---: | ---: |"]
        L += [f"| {e['method']} | {e['msaa']} | {f(e['flip_mean'], '.4f')} | {f(e['flip_seam_mean'], '.4f')} | "
              f"{f(e['flip_off_mean'], '.4f')} |" for e in entries]
        L.append("")
        for t, r in analysis["flip_ratios"].items():
            L.append(f"Discard / {t} seam FLIP per rate: " + ", ".join(f"{k}x {v:.3f}" for k, v in r.items()))
        for c in analysis["controls"]:
            r = study.ratios(entries, c, "traverse", "flip_seam_mean")
            L.append(f"Control {c} / traverse seam FLIP per rate: " + ", ".join(f"{k}x {x:.3f}" for k, x in r.items()))
        L.append("")
    return "\n".join(L)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("bench_json", nargs="+", help="seamcl bench --json output, a farm's merged.json, or parts of one batch")
    ap.add_argument("-o", "--out", required=True, help="directory for claims.md and claims.json")
    ap.add_argument("--flip", help="examples/orbit_flip.py's pooled FLIP of the same error frames (farm --flip: flip.json)")
    args = ap.parse_args(argv)
    benches = []
    for path in args.bench_json:
        try:
            with open(path) as fh:
                bench = json.load(fh)
        except (OSError, ValueError) as e:
            print(f"orbit_claims: {path}: {e}", file=sys.stderr)
            return 2
        if not isinstance(bench, dict) or not isinstance(bench.get("results"), list) or not bench["results"] or \
                not bench.get("errors") or any(not isinstance(r, dict) or "error" not in r for r in bench["results"]):
            print(f"orbit_claims: {path}: not a seamcl bench run with errors (no results[].error)", file=sys.stderr)
            return 2
        for key in BATCH_KEYS:
            if benches and bench.get(key) != benches[0].get(key):
                print(f"orbit_claims: {path}: '{key}' differs from {args.bench_json[0]}'s: parts of different batches",
                      file=sys.stderr)
                return 2
        benches.append(bench)
    try:
        spans = sorted((b["shard"]["first_frame"], b["shard"]["end_frame"]) for b in benches)
        if any(later[0] < earlier[1] for earlier, later in zip(spans, spans[1:])):
            print("orbit_claims: two parts cover the same frames", file=sys.stderr)
            return 2
        entries = entries_of(benches)
        if args.flip:
            with open(args.flip) as fh:
                add_flip(entries, json.load(fh), [k for b in benches for k in b["error_frames"]], args.flip)
    except OSError as e:
        print(f"orbit_claims: {args.flip}: {e.strerror}", file=sys.stderr)
        return 2
    except (KeyError, IndexError, TypeError, ValueError) as e:
        print(f"orbit_claims: {e}", file=sys.stderr)
        return 2
    analysis = study.analyse_run(entries)
    os.makedirs(args.out, exist_ok=True)
    source = ", ".join(f"`{os.path.basename(p)}`" for p in args.bench_json) if len(args.bench_json) <= 3 else \
        f"{len(args.bench_json)} parts (`{os.path.basename(args.bench_json[0])}`, ...)"
    with open(os.path.join(args.out, "claims.md"), "w") as fh:
        fh.write(claims_md(benches, entries, analysis, source))
    study.dump_json({"sources": [os.path.basename(p) for p in args.bench_json], "scene": benches[0]["scene"],
                     "size": benches[0]["size"], "frames": benches[0]["frames"], "covered": frame_blocks(benches),
                     "error_frames": sorted(k for b in benches for k in b["error_frames"]),
                     "seam_mask": benches[0].get("seam_mask", "band"), "options": benches[0]["options"],
                     "entries": entries, "analysis": analysis},
                    os.path.join(args.out, "claims.json"))
    for t, r in analysis["ratios"].items():
        print(f"orbit_claims: discard / {t} seam error " + ", ".join(f"{k}x {v:.3f}" for k, v in r.items()))
    for t, r in analysis["flip_ratios"].items():
        if r:
            print(f"orbit_claims: discard / {t} seam FLIP " + ", ".join(f"{k}x {v:.3f}" for k, v in r.items()))
    for name in ("claims.md", "claims.json"):
        print(os.path.join(args.out, name))
    return 0


if __name__ == "__main__":
    sys.exit(main())
