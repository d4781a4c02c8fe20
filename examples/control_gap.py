#!/usr/bin/env python3
"""Why a control does or does not stand apart from Traverse: the gap between the methods' images
against the error floor they share.

For each regime folder that `examples/accuracy_study.py --images DIR` kept (compare's 8-bit sRGB
PNGs), over the seam mask at each MSAA rate: the mean 2-norm (linear RGB) of clamp - traverse-edges
and black - traverse-edges (how far the controls' images are from Traverse's), and of
traverse-edges - reference and clamp - reference. A control's seam error can be 2x Traverse's only
where its gap to Traverse is larger than Traverse's own error (the floor every method shares:
texture resolution, mip filtering, silhouettes). The PNGs are 8-bit, so figures below about 2e-3
are quantisation.

    /usr/bin/python3 examples/control_gap.py DIR [--reference analytic] [--msaa 1,8]
"""
import argparse
import pathlib
import sys

import matplotlib.image
import numpy as np


def linear_rgb(path):
    srgb = matplotlib.image.imread(path)[..., :3].astype(np.float64)
    return np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)


def mask_of(path):
    image = matplotlib.image.imread(path)
    return (image[..., 0] if image.ndim == 3 else image) > 0.5


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("images", type=pathlib.Path, help="the study's --images folder (one subfolder per regime)")
    parser.add_argument("--reference", default="analytic",
                        help="reference_<name>.png to measure against (default analytic; 'paper' is reference.png)")
    parser.add_argument("--msaa", default="1,8", help="rates, comma-separated (default 1,8)")
    args = parser.parse_args()
    try:
        rates = [int(r) for r in args.msaa.split(",")]
    except ValueError:
        parser.error(f"--msaa: '{args.msaa}' is not a comma-separated list of integers")
    regimes = sorted(p for p in args.images.iterdir() if p.is_dir()) if args.images.is_dir() else []
    if not regimes:
        parser.error(f"{args.images}: no regime folders")
    reference_name = "reference.png" if args.reference == "paper" else f"reference_{args.reference}.png"
    print("| regime | MSAA | mask | clamp - traverse | black - traverse | traverse - ref | clamp - ref |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for folder in regimes:
        reference_path = folder / reference_name
        if not reference_path.exists():
            print(f"{folder.name}: no {reference_name}, skipped", file=sys.stderr)
            continue
        reference = linear_rgb(reference_path)
        for rate in rates:
            paths = {m: folder / f"{m}_msaa{rate}.png" for m in ("traverse-edges", "clamp", "black")}
            mask_path = folder / f"seam_mask_msaa{rate}.png"
            missing = [str(p) for p in [mask_path, *paths.values()] if not p.exists()]
            if missing:
                print(f"{folder.name} {rate}x: missing {', '.join(missing)}, skipped", file=sys.stderr)
                continue
            mask = mask_of(mask_path)
            images = {m: linear_rgb(p) for m, p in paths.items()}

            def gap(a, b):
                return float(np.linalg.norm(a - b, axis=2)[mask].mean())

            traverse = images["traverse-edges"]
            print(f"| {folder.name} | {rate}x | {mask.mean():.2f} | {gap(images['clamp'], traverse):.4f} | "
                  f"{gap(images['black'], traverse):.4f} | {gap(traverse, reference):.4f} | "
                  f"{gap(images['clamp'], reference):.4f} |")


if __name__ == "__main__":
    main()
