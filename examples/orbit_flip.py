#!/usr/bin/python3
"""FLIP over an orbit's error frames, from the images `seamcl bench --images DIR` writes.

    seamcl bench --scene paper --frames 1000 --reference-frames 10 ... --images IMAGES --json > bench.json
    /usr/bin/python3 examples/orbit_flip.py measure IMAGES -o part.flip.json
    /usr/bin/python3 examples/orbit_flip.py pool shards/*.flip.json -o flip.json

`scripts/farm --flip` runs `measure` on each part's images as the part finishes (then deletes them)
and `pool` on every part's figures after the merge.

measure: for every frame folder IMAGES/frame_<k>/ (reference.png, seam_mask_msaa<N>.png,
<method>_msaa<N>.png, as `bench --images` writes them), FLIP (NVIDIA's perceptual difference, PyPI
flip-evaluator, LDR, sRGB inputs, its default viewing condition: accuracy_study.py's `flip_map`) of
every entry's image against the frame's reference. Per entry it keeps sums, so that parts pool
exactly: FLIP summed over every pixel, over the seam mask (white) and over the pixels off every
edge (black; the grey rims are neither, as in accuracy_study.py), with the pixel counts, and each
frame's means.

pool: adds the sums of several `measure` outputs of one batch (they must list the same entries and
no frame twice) and gives each entry's means over all their frames: flip_mean, flip_seam_mean,
flip_off_mean. `examples/orbit_claims.py --flip flip.json` puts them beside the errors.

Exit status 2 with a message naming the file for anything it cannot read or that does not fit.
"""
import argparse
import concurrent.futures
import json
import os
import re
import sys

sys.dont_write_bytecode = True  # no __pycache__ beside the sources
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import accuracy_study as study  # noqa: E402

FRAME_FOLDER = re.compile(r"^frame_(\d+)$")
ENTRY_IMAGE = re.compile(r"^(?!seam_mask_)(?!reference)(.+)_msaa(\d+)\.png$")
SUM_KEYS = ("frames", "pixels", "flip_sum", "seam_pixels", "flip_seam_sum", "off_pixels", "flip_off_sum")


class Unusable(Exception):
    """An input that cannot be measured or pooled; the message names it."""


def frame_folders(images_dir):
    """[(k, path)] of the frame folders, in frame order."""
    try:
        names = os.listdir(images_dir)
    except OSError as e:
        raise Unusable(f"{images_dir}: {e.strerror}")
    folders = sorted((int(m.group(1)), os.path.join(images_dir, n)) for n in names
                     if (m := FRAME_FOLDER.match(n)) and os.path.isdir(os.path.join(images_dir, n)))
    if not folders:
        raise Unusable(f"{images_dir}: no frame_<k> folders (write them with seamcl bench --images)")
    return folders


def entries_in(folder):
    """[(method, msaa)] of the entry images in one frame folder, sorted."""
    found = [(m.group(1), int(m.group(2))) for n in os.listdir(folder) if (m := ENTRY_IMAGE.match(n))]
    if not found:
        raise Unusable(f"{folder}: no <method>_msaa<N>.png images")
    return sorted(found)


def measure_frame(task):
    """One frame's figures per entry: FLIP sums over all pixels, the seam mask and off it."""
    k, folder, entries = task
    reference_path = os.path.join(folder, "reference.png")
    if not os.path.isfile(reference_path):
        raise Unusable(f"{folder}: no reference.png")
    reference = study.read_png(reference_path)
    masks, out = {}, []
    for method, rate in entries:
        path = os.path.join(folder, f"{method}_msaa{rate}.png")
        image = study.read_png(path)
        if image.shape != reference.shape:
            raise Unusable(f"{path}: {image.shape[1]}x{image.shape[0]}, the reference is "
                           f"{reference.shape[1]}x{reference.shape[0]}")
        if rate not in masks:
            seam, off = study.read_masks(None, folder, rate)
            if seam is None or seam.shape != reference.shape[:2]:
                raise Unusable(f"{folder}: no seam_mask_msaa{rate}.png of the reference's size")
            masks[rate] = seam, off
        seam, off = masks[rate]
        fmap, _ = study.flip_map(reference, image)
        seam_px, off_px = int(seam.sum()), int(off.sum())
        figures = {"method": method, "msaa": rate, "frames": 1, "pixels": int(fmap.size),
                   "flip_sum": float(fmap.sum(dtype="float64")), "seam_pixels": seam_px,
                   "flip_seam_sum": float(fmap[seam].sum(dtype="float64")), "off_pixels": off_px,
                   "flip_off_sum": float(fmap[off].sum(dtype="float64"))}
        figures["per_frame"] = [{"frame": k, "flip_mean": figures["flip_sum"] / figures["pixels"],
                                 "flip_seam_mean": figures["flip_seam_sum"] / seam_px if seam_px else None}]
        out.append(figures)
    return out


def with_means(entry):
    entry["flip_mean"] = entry["flip_sum"] / entry["pixels"] if entry["pixels"] else None
    entry["flip_seam_mean"] = entry["flip_seam_sum"] / entry["seam_pixels"] if entry["seam_pixels"] else None
    entry["flip_off_mean"] = entry["flip_off_sum"] / entry["off_pixels"] if entry["off_pixels"] else None
    return entry


def add_into(total, part):
    for key in SUM_KEYS:
        total[key] += part[key]
    total["per_frame"] += part["per_frame"]


def measure(images_dir, jobs):
    folders = frame_folders(images_dir)
    entries = entries_in(folders[0][1])
    for _, folder in folders[1:]:
        if entries_in(folder) != entries:
            raise Unusable(f"{folder}: other entries than {folders[0][1]}")
    tasks = [(k, folder, entries) for k, folder in folders]
    with concurrent.futures.ProcessPoolExecutor(max_workers=jobs) as pool:
        per_frame = list(pool.map(measure_frame, tasks))
    totals = [dict(per_frame[0][i]) for i in range(len(entries))]
    for frame in per_frame[1:]:
        for total, part in zip(totals, frame):
            add_into(total, part)
    return {"frames": [k for k, _ in folders], "flip": flip_settings(), "entries": [with_means(e) for e in totals]}


def flip_settings():
    return {"evaluator": "flip-evaluator", "mode": "LDR", "inputs": "sRGB PNG",
            "parameters": study.FLIP_PARAMETERS or "defaults (67 pixels per degree)"}


def pool(paths):
    parts = []
    for path in paths:
        try:
            with open(path) as f:
                part = json.load(f)
            entries = part["entries"]
            if not isinstance(part["frames"], list) or not entries or \
                    any(not all(key in e for key in (*SUM_KEYS, "method", "msaa", "per_frame")) for e in entries):
                raise KeyError("entries[] with " + ", ".join(SUM_KEYS))
        except (OSError, ValueError, KeyError, TypeError) as e:
            raise Unusable(f"{path}: not an orbit_flip.py measure output ({e})")
        parts.append((path, part))
    first_path, first = parts[0]
    names = [(e["method"], e["msaa"]) for e in first["entries"]]
    seen = {}
    totals = [{**{key: 0 if key in ("frames", "pixels", "seam_pixels", "off_pixels") else 0.0 for key in SUM_KEYS},
               "method": m, "msaa": r, "per_frame": []} for m, r in names]
    for path, part in parts:
        if [(e["method"], e["msaa"]) for e in part["entries"]] != names:
            raise Unusable(f"{path}: other entries than {first_path}")
        for k in part["frames"]:
            if k in seen:
                raise Unusable(f"{path}: frame {k} is also in {seen[k]}")
            seen[k] = path
        for total, e in zip(totals, part["entries"]):
            add_into(total, e)
    for total in totals:
        total["per_frame"].sort(key=lambda f: f["frame"])
    return {"frames": sorted(seen), "flip": first.get("flip", flip_settings()),
            "entries": [with_means(e) for e in totals]}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    sub = ap.add_subparsers(dest="command", required=True)
    m = sub.add_parser("measure", help="FLIP of every entry of every frame folder of one images directory")
    m.add_argument("images", help="a directory of frame_<k>/ folders (seamcl bench --images)")
    m.add_argument("-o", "--out", required=True, help="the figures' JSON")
    m.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="frames measured at once [every core]")
    p = sub.add_parser("pool", help="the figures of several measure outputs added up, with their means")
    p.add_argument("parts", nargs="+", help="measure outputs of one batch")
    p.add_argument("-o", "--out", required=True, help="the pooled JSON")
    args = ap.parse_args(argv)
    if args.command == "measure" and not 1 <= args.jobs <= 256:
        ap.error(f"--jobs must be in 1..256, got {args.jobs}")
    try:
        result = measure(args.images, args.jobs) if args.command == "measure" else pool(args.parts)
    except Unusable as e:
        print(f"orbit_flip: {e}", file=sys.stderr)
        return 2
    tmp = f"{args.out}.tmp-{os.getpid()}"
    with open(tmp, "w") as f:
        json.dump(result, f, indent=1)
        f.write("\n")
    os.replace(tmp, args.out)
    for e in result["entries"]:
        seam = "-" if e["flip_seam_mean"] is None else f"{e['flip_seam_mean']:.4f}"
        print(f"orbit_flip: {e['method']} {e['msaa']}x over {e['frames']} frames: FLIP {e['flip_mean']:.4f}, "
              f"seam {seam}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
