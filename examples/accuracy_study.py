#!/usr/bin/python3
"""The accuracy study: which seam method is best where, against which reference, at what cost.

For each regime (a scene and texture content, see REGIMES) x reference (the ones `seamcl compare`
offers, see REFERENCES), runs one `seamcl compare --json --images DIR` with every method at every
MSAA rate, then adds, in Python:

  - FLIP (NVIDIA's perceptual difference, PyPI `flip-evaluator`) of each method's image against
    the reference image, both 8-bit sRGB PNGs as compare writes them (LDR, 67 pixels per degree,
    FLIP's defaults); its mean over all pixels, over the seam mask and over the mask's complement;
  - the Discard / Traverse seam-error ratio per rate (against every traverse variant present);
  - whether the paper's claims hold (Discard worse than Traverse at 1x and 2x, even at 4x, better
    at 8x), decided from those ratios by fixed rules (CLAIMS), never written by hand;
  - the controls: black's and clamp's seam error over traverse's (they must stand apart).

Writes into --out (default docs/results/accuracy): results.json (every figure and the exact
commands), results.md (the tables), and per regime pareto_<regime>.png, figure5_<regime>.png and
heatmaps_<regime>.png. Progress goes to stderr.

    nice -n 10 /usr/bin/python3 examples/accuracy_study.py --quick --out /tmp/acc   # a minute
    nice -n 10 /usr/bin/python3 examples/accuracy_study.py                          # the full study

The JSON of `seamcl compare` that this reads, by name (anything missing is derived or left out,
and results.json says which):
  top level: scene, size, device, reference_method, reference{...} (copied as is), seam_pixels,
    results[], images; optional: mask{coverage|pixels}, reference_name / reference{name}.
  results[]: method, msaa, ms{median,min,max}, error{mean, p99, seam_mean, seam_p99,
    nan_pixels, pixels, seam_pixels}, curve, seam_curve ([[x, fraction of pixels >= x], ...]);
    optional errors over the mask's complement: error{off_mean|off_seam_mean|complement_mean,
    off_p99|...}, off_curve|complement_curve. Without them they are derived exactly for the mean
    (from mean, seam_mean and the pixel counts) and from the curves for p99 (log interpolation).
  images: <method>_msaa<N>.png, reference.png and seam_mask.png in the --images folder (or the
    paths in results[].images{image} and top-level reference_image / mask_image when given).
"""
import argparse
import json
import math
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.patches  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import colors as mcolors  # noqa: E402
from matplotlib import ticker as mticker  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

sys.dont_write_bytecode = True  # no __pycache__ beside the sources
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import charts  # noqa: E402  (pareto_front, place_labels)

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

METHODS = ["clamp", "black", "discard", "traverse", "traverse-edges", "guardband"]
RATES = [1, 2, 4, 8, 16]
# Names `seamcl compare` gives its references (the accuracy work): the paper's (traverse at 8x the
# width and height, Mitchell-Netravali downsample), the same with a box downsample, the texture
# function evaluated at every subsample, and one continuous texture where the faces make one.
REFERENCES = ["paper", "box", "analytic", "seamless"]

# A regime: a name, what it is for, the compare arguments, and what the binary must offer for it
# (scenes it must list, compare options it must accept). `controls`: False where black and clamp
# equal traverse by construction (a constant colour carries no seam error).
REGIMES = [
    {"name": "paper", "what": "the paper's Figure 1 scene: minified, smooth texture (features 0.2-0.5 units)",
     "args": ["--scene", "paper"], "scenes": ["paper"]},
    {"name": "detail", "what": "the paper's scene with texel-scale detail (features of 2-4 texels)",
     "content": ("paper", "detail"), "scenes": ["paper"]},
    {"name": "closeup-seam", "what": "magnified close-up of a seam", "args": ["--scene", "closeup-seam"],
     "scenes": ["closeup-seam"]},
    {"name": "closeup-corner", "what": "magnified close-up of a corner where faces meet",
     "args": ["--scene", "closeup-corner"], "scenes": ["closeup-corner"]},
    {"name": "grazing", "what": "a plane of 64x64 small faces at a grazing angle (anisotropic footprints)",
     "args": ["--scene", "plane"], "scenes": ["plane"]},
    {"name": "grazing-detail", "what": "the grazing plane with texel-scale detail", "content": ("plane", "detail"),
     "scenes": ["plane"]},
    {"name": "mixed", "what": "closed mesh, mixed resolutions, rotated and mirrored neighbours, valence 3/4/5",
     "args": ["--scene", "mixed"], "scenes": ["mixed"]},
    {"name": "mixed-detail", "what": "the mixed mesh with texel-scale detail",
     "content": ("mixed", "detail"), "scenes": ["mixed"]},
    {"name": "constant", "what": "control: the paper's scene in one colour, so seams carry no texture error",
     "args": ["--scene", "paper", "--constant-color", "0.5,0.4,0.3"], "scenes": ["paper"],
     "options": ["--constant-color"], "controls": False},
]
# --quick: small scenes at a tiny size, for the test (about a minute on two shared cores).
QUICK_REGIMES = [
    {"name": "cube", "what": "a closed cube of six 64x64-textured faces, seen obliquely",
     "args": ["--scene", "cube"], "scenes": ["cube"]},
    {"name": "cube-detail", "what": "the cube with texel-scale detail", "content": ("cube", "detail"),
     "scenes": ["cube"]},
    {"name": "cube-constant", "what": "control: the cube in one colour",
     "args": ["--scene", "cube", "--constant-color", "0.5,0.4,0.3"], "scenes": ["cube"],
     "options": ["--constant-color"], "controls": False},
]
PRESETS = {
    "full": {"regimes": REGIMES, "size": "480x540", "rates": RATES, "repeat": 3},
    "quick": {"regimes": QUICK_REGIMES, "size": "48x54", "rates": RATES, "repeat": 1},
}

# The paper's claims (section 4 and Figure 5 right), as rules on the Discard / Traverse seam-error
# ratio r at a rate: "worse" r > 1 + TIE, "even" |r - 1| <= EVEN, "better" r < 1 - TIE.
EVEN = 0.10
TIE = 0.01  # a ratio within 1% of 1 is a tie: neither worse nor better
CLAIMS = [
    {"id": "worse_1x", "rate": 1, "short": "worse at 1x", "says": "Discard worse than Traverse at 1x",
     "rule": f"ratio > {1 + TIE:.2f}"},
    {"id": "worse_2x", "rate": 2, "short": "worse at 2x", "says": "Discard worse than Traverse at 2x",
     "rule": f"ratio > {1 + TIE:.2f}"},
    {"id": "even_4x", "rate": 4, "short": "even at 4x", "says": "Discard and Traverse about even at 4x",
     "rule": f"|ratio - 1| <= {EVEN:.2f}"},
    {"id": "better_8x", "rate": 8, "short": "better at 8x", "says": "Discard slightly better than Traverse at 8x",
     "rule": f"ratio < {1 - TIE:.2f}"},
]

COLOURS = {"clamp": "tab:green", "black": "tab:gray", "discard": "tab:blue", "traverse": "tab:orange",
           "traverse-edges": "tab:brown", "guardband": "tab:red"}
MARKERS = {1: "o", 2: "s", 4: "^", 8: "D", 16: "P"}
# FLIP's viewing condition: its default, 67 pixels per degree (a 0.7 m distance from a 24" 4K screen).
FLIP_PARAMETERS = {}


def log(msg):
    print(msg, file=sys.stderr, flush=True)


# ---------------------------------------------------------------------------------------------
# What the binary offers


class Binary:
    def __init__(self, path):
        self.path = path
        self.scenes = self._scenes()
        self.compare_help = self._run(["compare", "--help"])
        self.render_help = self._run(["render", "--help"])
        self.methods = self._methods()

    def _run(self, args):
        return subprocess.run([self.path] + args, check=True, capture_output=True, text=True).stdout

    def _scenes(self):
        return [line.split()[0] for line in self._run(["scenes"]).splitlines() if line.strip()]

    def _methods(self):
        # render --help: "--method TEXT  Seam method: clamp, black, discard, traverse, guardband [discard]"
        m = re.search(r"--method\s+TEXT\s+Seam method:\s*([^\[\n]+)", self.render_help)
        if not m:
            return list(METHODS)
        return [x.strip() for x in m.group(1).split(",") if x.strip()]

    def has_option(self, name):
        return re.search(r"(^|\s|,)" + re.escape(name) + r"(\s|,|=|$)", self.compare_help, re.M) is not None

    def reference_option(self):
        """The compare option that names the reference, when there is one."""
        for opt in ("--reference", "--references"):
            if self.has_option(opt):
                return opt
        return None

    def references(self):
        opt = self.reference_option()
        if opt is None:
            return ["paper"]  # today's compare: the paper's reference only
        line = next((ln for ln in self.compare_help.splitlines() if re.search(re.escape(opt) + r"(\s|,|=|$)", ln)), "")
        found = [r for r in REFERENCES if re.search(r"\b" + r + r"\b", line)]
        return found or list(REFERENCES)

    def has_content(self, content):
        """Whether scene files take {"options": {"content": ...}}: a tiny render of the cube with it."""
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "probe.json")
            with open(path, "w") as f:
                json.dump({"generator": "cube", "options": {"content": content}}, f)
            probe = subprocess.run([self.path, "render", "--scene", path, "--size", "8x8"], capture_output=True, text=True)
            return probe.returncode == 0

    def version(self):
        try:
            return self._run(["--version"]).strip().splitlines()[0]
        except (subprocess.CalledProcessError, IndexError):
            return "?"


def regime_missing(binary, regime):
    """Why the binary cannot run the regime, or None."""
    for s in regime.get("scenes", []):
        if s not in binary.scenes:
            return f"scene '{s}' not in `seamcl scenes`"
    for o in regime.get("options", []):
        if not binary.has_option(o):
            return f"`seamcl compare` has no {o}"
    if "content" in regime and not binary.has_content(regime["content"][1]):
        return f"this seamcl's scene files take no \"content\": \"{regime['content'][1]}\""
    return None


def regime_args(regime, work):
    """compare's scene arguments. A texture content is a scene file (docs/scene-format.md):
    {"generator": G, "options": {"content": C}}, written into the work folder."""
    if "content" not in regime:
        return list(regime["args"])
    generator, content = regime["content"]
    path = os.path.join(work, f"{generator}_{content}.json")
    with open(path, "w") as f:
        json.dump({"generator": generator, "options": {"content": content}}, f)
    return ["--scene", path]


def shown_args(regime):
    if "content" not in regime:
        return list(regime["args"])
    generator, content = regime["content"]
    return ["--scene", f"{generator}_{content}.json"]


# ---------------------------------------------------------------------------------------------
# Images and FLIP


def read_png(path):
    """An 8-bit PNG as float RGB in [0, 1] (sRGB encoded, as compare writes it)."""
    img = plt.imread(path)
    if img.dtype != np.float32 and img.dtype != np.float64:
        img = img.astype(np.float32) / 255.0
    if img.ndim == 2:
        img = np.stack([img] * 3, axis=-1)
    return np.ascontiguousarray(img[..., :3], dtype=np.float32)


def srgb_to_linear(c):
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def distance_linear(a_srgb, b_srgb):
    """Per-pixel 2-norm in linear RGB between two sRGB images (quantised to 8 bits by the PNGs)."""
    return np.sqrt(np.sum((srgb_to_linear(a_srgb) - srgb_to_linear(b_srgb)) ** 2, axis=-1))


def flip_module():
    import flip_evaluator  # PyPI flip-evaluator; scripts/install-deps installs it
    return flip_evaluator


def flip_map(reference_srgb, test_srgb):
    """FLIP per pixel (H x W, 0 = identical, 1 = most different) and its mean, LDR sRGB inputs."""
    flip = flip_module()
    error_map, mean, _ = flip.evaluate(reference_srgb, test_srgb, "LDR", inputsRGB=True, applyMagma=False,
                                       computeMeanError=True, parameters=dict(FLIP_PARAMETERS))
    m = np.asarray(error_map, dtype=np.float32)
    if m.ndim == 3:
        m = m[..., 0]
    return m, float(mean)


def thresholds():
    return [10 ** (-4 + 0.1 * i) for i in range(41)]  # compare's curve: 1e-4 .. 1, 10 per decade


def curve_of(values):
    values = np.asarray(values).ravel()
    if values.size == 0:
        return []
    return [[x, float(np.count_nonzero(values >= x)) / values.size] for x in thresholds()]


# ---------------------------------------------------------------------------------------------
# compare's JSON, read by name


def first_key(d, names, default=None):
    for n in names:
        if isinstance(d, dict) and n in d and d[n] is not None:
            return d[n]
    return default


def quantile_from_curve(curve, q):
    """The x where the fraction >= x falls to 1 - q (log interpolation between thresholds)."""
    if not curve:
        return None
    target = 1.0 - q
    prev = None
    for x, f in curve:
        if f <= target:
            if prev is None or prev[1] == f:
                return x
            (x0, f0) = prev
            t = (f0 - target) / (f0 - f)
            return 10 ** (math.log10(x0) + t * (math.log10(x) - math.log10(x0)))
        prev = (x, f)
    return curve[-1][0]


def off_mask_figures(e, result, curves_ok):
    """Mean, p99 and curve over the complement of the seam mask, and where they came from.
    `e`: the error object of one reference; `result`'s curves only when they belong to it."""
    mean = first_key(e, ["off_seam_mean", "off_mean", "complement_mean"])
    p99 = first_key(e, ["off_seam_p99", "off_p99", "complement_p99"])
    curve = first_key(result, ["off_seam_curve", "off_curve"]) if curves_ok else None
    source = "compare" if mean is not None and p99 is not None else "derived"
    n, s = e.get("pixels"), e.get("seam_pixels")
    if mean is None and n is not None and s is not None and n > s:
        mean = (e["mean"] * n - e["seam_mean"] * s) / (n - s)
    if curve is None and curves_ok and n and s is not None and n > s and result.get("curve") and result.get("seam_curve"):
        curve = [[x, max(0.0, (fa * n - fs * s) / (n - s))] for (x, fa), (_, fs) in zip(result["curve"], result["seam_curve"])]
    if p99 is None and curve:
        p99 = quantile_from_curve(curve, 0.99)
    return mean, p99, curve, source


def mask_definition(cmp):
    sm = cmp.get("seam_mask")
    if isinstance(sm, dict) and "definition" in sm:
        return sm["definition"]
    return f"within {cmp.get('seam_radius', 2)} px of a face edge (from a 1-sample face map)"


def image_size(cmp):
    w, h = (int(v) for v in cmp["size"].split("x"))
    return w, h


def mask_coverage(cmp, msaa):
    """The seam mask's share of the pixels at a rate: seam_mask.by_msaa (the footprint mask, one per
    rate) where compare gives it, else the one mask of seam_pixels."""
    by = (cmp.get("seam_mask") or {}).get("by_msaa") if isinstance(cmp.get("seam_mask"), dict) else None
    if by and str(msaa) in by:
        return float(by[str(msaa)]["coverage"])
    w, h = image_size(cmp)
    return cmp.get("seam_pixels", 0) / float(w * h)


def reference_names(cmp):
    """The references of one compare answer, the first (whose curves compare gives) first."""
    refs = cmp.get("references")
    if isinstance(refs, list) and refs and all(isinstance(r, dict) and "name" in r for r in refs):
        return [r["name"] for r in refs]
    ref = cmp.get("reference")
    return [ref["name"]] if isinstance(ref, dict) and "name" in ref else ["paper"]


def errors_for(result, name, first):
    """results[].errors[name] with several references, else results[].error (the first's)."""
    errs = result.get("errors")
    if isinstance(errs, dict) and name in errs:
        return errs[name]
    return result.get("error", {}) if name == first else None


def image_paths(cmp, images_dir, method, msaa):
    for r in cmp["results"]:
        if r["method"] == method and r["msaa"] == msaa and isinstance(r.get("images"), dict) and "image" in r["images"]:
            return r["images"]["image"]
    return os.path.join(images_dir, f"{method}_msaa{msaa}.png")


def reference_image_path(cmp, images_dir, name="paper", msaa=1):
    """reference.png (the paper's, or the only one), reference_<name>.png, and for seamless, which
    is rendered at the measured rate, reference_seamless_msaa<N>.png."""
    candidates = [f"reference_{name}_msaa{msaa}.png", f"reference_{name}.png"]
    if name == "paper" or len(reference_names(cmp)) == 1:
        candidates.append("reference.png")
    for c in candidates:
        if os.path.exists(os.path.join(images_dir, c)):
            return os.path.join(images_dir, c)
    return os.path.join(images_dir, candidates[-1])


def mask_image_path(cmp, images_dir, msaa=1):
    """seam_mask_msaa<N>.png (one footprint mask per rate), else seam_mask.png."""
    p = os.path.join(images_dir, f"seam_mask_msaa{msaa}.png")
    return p if os.path.exists(p) else os.path.join(images_dir, "seam_mask.png")


def read_masks(cmp, images_dir, msaa):
    """(seam, off) boolean masks from the mask PNG: white = seam; black = off every edge; grey
    (0.2 linear, the footprint mask's boundary pixels: silhouette rims) = neither. A two-level
    mask (older binaries) has off = not seam."""
    p = mask_image_path(cmp, images_dir, msaa)
    if not os.path.exists(p):
        return None, None
    v = read_png(p)[..., 0]
    return v > 0.9, v < 0.1


def read_mask(cmp, images_dir, msaa):
    return read_masks(cmp, images_dir, msaa)[0]


# ---------------------------------------------------------------------------------------------
# One compare run


def run_compare(binary, args, images_dir, timeout=None):
    """Runs compare, passing its progress lines through to stderr. RuntimeError with the last
    lines of stderr when it fails."""
    cmd = [binary.path, "compare", "--json", "--images", images_dir] + args
    t0 = time.monotonic()
    with tempfile.TemporaryFile("w+") as out:
        proc = subprocess.Popen(cmd, stdout=out, stderr=subprocess.PIPE, text=True)
        tail = []
        for line in proc.stderr:
            sys.stderr.write("  " + line)
            tail = (tail + [line.rstrip()])[-5:]
        proc.wait(timeout=timeout)
        out.seek(0)
        text = out.read()
    wall = time.monotonic() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"{shlex.join(cmd)} exited with {proc.returncode}: " + " / ".join(tail))
    cmp = json.loads(text)
    with open(os.path.join(images_dir, "compare.json"), "w") as f:  # for --reuse
        json.dump({"command": cmd, "wall_s": wall, "answer": cmp}, f)
    return cmp, cmd, wall


def compare_with_references(binary, args, images_dir, references, reuse=False):
    """compare with as many of `references` as the scene allows: a reference the scene cannot
    have (compare refuses it by name before rendering) is dropped and the run retried.
    Returns (answer, command, wall seconds, [(reference, why dropped)])."""
    saved = os.path.join(images_dir, "compare.json")
    if reuse and os.path.exists(saved):
        with open(saved) as f:
            got = json.load(f)
        log(f"study   reusing {saved}")
        return got["answer"], got["command"], got["wall_s"], []
    refs, dropped = list(references), []
    opt = binary.reference_option()
    while True:
        extra = [opt, ",".join(refs)] if opt else []
        try:
            cmp, cmd, wall = run_compare(binary, args + extra, images_dir)
            return cmp, cmd, wall, dropped
        except RuntimeError as e:
            msg = str(e).split(": ", 1)[-1]
            named = re.findall(r"\bthe (\w+) reference\b", msg)  # "the seamless reference needs ..."
            bad = [r for r in refs if r in named] if named else \
                [r for r in refs if re.search(r"\b" + re.escape(r) + r"\b", msg)]
            bad = bad if opt else []
            if not bad or len(bad) == len(refs):
                raise
            for r in bad:
                refs.remove(r)
                dropped.append((r, msg))
                log(f"study   reference {r} dropped: {msg}")


def png_curves(dist, mask, off):
    return {"curve": curve_of(dist), "seam_curve": curve_of(dist[mask]) if mask is not None else None,
            "off_curve": curve_of(dist[off]) if off is not None else None}


def measure_run(cmp, images_dir, name=None, with_flip=True):
    """Per entry figures against reference `name` (default: the first), compare's and FLIP's, in
    compare's order. Curves: compare's for its first reference; for the others, from the PNGs."""
    names = reference_names(cmp)
    first = names[0]
    name = name or first
    curves_ok = name == first
    entries, ref_cache, mask_cache = [], {}, {}
    for r in cmp["results"]:
        e = errors_for(r, name, first)
        if e is None:
            continue
        rate = r["msaa"]
        off_mean, off_p99, off_curve, off_source = off_mask_figures(e, r, curves_ok)
        item = {"method": r["method"], "msaa": rate, "ms": r["ms"]["median"], "ms_min": r["ms"]["min"],
                "ms_max": r["ms"]["max"], "mean": e.get("mean"), "p99": e.get("p99"),
                "seam_mean": e.get("seam_mean"), "seam_p99": e.get("seam_p99"), "off_mean": off_mean,
                "off_p99": off_p99, "off_source": off_source, "nan_pixels": e.get("nan_pixels"),
                "mask_coverage": first_key(e, ["seam_coverage"], mask_coverage(cmp, rate)),
                "curve": r.get("curve") if curves_ok else None, "seam_curve": r.get("seam_curve") if curves_ok else None,
                "off_curve": off_curve, "curve_source": "compare" if curves_ok else "png"}
        need_png = with_flip or not curves_ok
        if need_png:
            ref_path = reference_image_path(cmp, images_dir, name, rate)
            if ref_path not in ref_cache:
                ref_cache[ref_path] = read_png(ref_path)
            ref = ref_cache[ref_path]
            if rate not in mask_cache:
                mask_cache[rate] = read_masks(cmp, images_dir, rate)
            mask, off = mask_cache[rate]
            img = read_png(image_paths(cmp, images_dir, r["method"], rate))
            if not curves_ok:
                item.update(png_curves(distance_linear(img, ref), mask, off))
        if with_flip:
            fmap, fmean = flip_map(ref, img)
            item["flip_mean"] = fmean
            if mask is not None and mask.shape == fmap.shape:
                item["flip_seam_mean"] = float(fmap[mask].mean()) if mask.any() else None
                item["flip_off_mean"] = float(fmap[off].mean()) if off.any() else None
        entries.append(item)
    return entries


def by_key(entries):
    return {(e["method"], e["msaa"]): e for e in entries}


def ratios(entries, num, den, key="seam_mean"):
    b = by_key(entries)
    out = {}
    for (m, rate), e in sorted(b.items(), key=lambda kv: kv[0][1]):
        if m != num or (den, rate) not in b:
            continue
        a, d = e.get(key), b[(den, rate)].get(key)
        if a is not None and d:
            out[str(rate)] = a / d
    return out


def judge_claims(ratio_by_rate):
    out = []
    for c in CLAIMS:
        r = ratio_by_rate.get(str(c["rate"]))
        if r is None:
            verdict = "not measured"
        elif c["id"].startswith("worse"):
            verdict = "holds" if r > 1 + TIE else "fails"
        elif c["id"].startswith("even"):
            verdict = "holds" if abs(r - 1) <= EVEN else "fails"
        else:
            verdict = "holds" if r < 1 - TIE else "fails"
        out.append({"claim": c["says"], "rule": c["rule"], "rate": c["rate"], "ratio": r, "verdict": verdict})
    return out


def traverse_variants(methods):
    return [m for m in ("traverse-edges", "traverse") if m in methods]


def analyse_run(entries, controls=True):
    methods = list(dict.fromkeys(e["method"] for e in entries))
    out = {"ratios": {}, "flip_ratios": {}, "claims": {}, "controls": {}}
    if "discard" in methods:
        for t in traverse_variants(methods):
            out["ratios"][t] = ratios(entries, "discard", t)
            out["flip_ratios"][t] = ratios(entries, "discard", t, "flip_seam_mean")
            out["claims"][t] = judge_claims(out["ratios"][t])
    if "traverse" in methods:
        for c in ("black", "clamp"):
            if c in methods:
                r = ratios(entries, c, "traverse")
                out["controls"][c] = {"over_traverse": r, "min": min(r.values()) if r else None,
                                      "separated_2x": (min(r.values()) >= 2.0) if r else None,
                                      "expected": controls}
    return out


# ---------------------------------------------------------------------------------------------
# Charts


def method_handles(methods):
    return [Line2D([], [], color=COLOURS.get(m, "k"), marker="o", ls="", label=m) for m in methods]


def rate_handles(rates):
    return [Line2D([], [], color="k", marker=MARKERS.get(r, "x"), ls="", mfc="none", label=f"{r}x MSAA")
            for r in rates]


def readable_log_axis(axis):
    """Ticks at 1, 2 and 5 per decade with plain numbers: a log axis spanning less than a decade
    otherwise shows a single label."""
    axis.set_major_locator(mticker.LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(mticker.FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(mticker.NullFormatter())


def chart_pareto(regime, runs, out, key="seam_mean"):
    """Time against seam error per reference (one panel each), the Pareto front drawn."""
    runs = [r for r in runs if r.get("entries")]
    if not runs:
        return None
    n = len(runs)
    legend_w = 1.9  # inches on the right for the legend
    fig_w = 5.0 * n + legend_w
    fig, axes = plt.subplots(1, n, figsize=(fig_w, 5.0), squeeze=False)
    methods, rates = set(), set()
    for ax, run in zip(axes[0], runs):
        es = [e for e in run["entries"] if e.get(key) is not None and e[key] > 0]
        pts = [(e["ms"], e[key]) for e in es]
        for e, (x, y) in zip(es, pts):
            methods.add(e["method"])
            rates.add(e["msaa"])
            ax.scatter(x, y, color=COLOURS.get(e["method"], "k"), marker=MARKERS.get(e["msaa"], "x"), s=42, zorder=3)
        front = charts.pareto_front(pts)
        fx, fy = [pts[i][0] for i in front], [pts[i][1] for i in front]
        ax.step(fx, fy, where="post", color="k", lw=1, ls="--", zorder=2)
        ax.scatter(fx, fy, facecolors="none", edgecolors="k", s=130, lw=1.1, zorder=4)
        ax.set_xscale("log")
        ax.set_yscale("log")
        readable_log_axis(ax.xaxis)
        readable_log_axis(ax.yaxis)
        ax.grid(True, which="both", alpha=0.3)
        ax.set_xlabel("time per frame, ms (median of the timed renders)")
        ax.set_ylabel(f"seam error: mean 2-norm over the seam mask\n(linear RGB, against the {run['reference']} reference)")
        ax.set_title(f"reference: {run['reference']}")
    order = [m for m in METHODS if m in methods] + sorted(methods - set(METHODS))
    fig.legend(handles=method_handles(order) + rate_handles(sorted(rates)) +
               [Line2D([], [], color="k", ls="--", marker="o", mfc="none", ms=10, label="Pareto front (labelled)")],
               loc="center right", fontsize=8, title="colour: method\nmarker: MSAA", title_fontsize=8)
    fig.suptitle(f"{regime['name']} ({runs[0]['size']}): speed against seam error, lower left is better\n"
                 f"circled: the Pareto front (no other point is both faster and more accurate)", fontsize=10)
    fig.subplots_adjust(left=0.95 / fig_w, right=1 - (legend_w + 0.2) / fig_w, bottom=0.11, top=0.84,
                        wspace=1.0 / 5.0)
    for ax, run in zip(axes[0], runs):  # labels last: they are placed in the final layout
        es = [e for e in run["entries"] if e.get(key) is not None and e[key] > 0]
        pts = [(e["ms"], e[key]) for e in es]
        front = charts.pareto_front(pts)
        charts.place_labels(ax, [pts[i] for i in front], [f"{es[i]['method']} {es[i]['msaa']}x" for i in front],
                            avoid=pts)
    path = os.path.join(out, f"pareto_{regime['name']}.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def rate_colours(rates):
    cmap = plt.get_cmap("viridis")
    return {r: cmap(i / max(1, len(rates) - 1) * 0.9) for i, r in enumerate(rates)}


def chart_figure5(regime, runs, out, differences):
    """The paper's Figure 5 per regime. Row 1: all pixels, row 2: the seam mask. Column 1: the
    difference between Discard and Traverse (no reference); then one column per reference:
    Discard (solid) and Traverse (dashed) per rate, with clamp and black (the controls, thin
    grey) at the lowest and highest rate. Log-log: the tails show."""
    runs = [r for r in runs if r.get("entries")]
    if not runs:
        return None
    rates = sorted({e["msaa"] for e in runs[0]["entries"]})
    colour = rate_colours(rates)
    trav = traverse_variants({e["method"] for e in runs[0]["entries"]})
    trav = trav[0] if trav else None
    ncol = 1 + len(runs)
    fig, axes = plt.subplots(2, ncol, figsize=(4.3 * ncol, 8.2), squeeze=False)
    for row, (ckey, where) in enumerate((("curve", "all pixels"), ("seam_curve", "seam mask"))):
        ax = axes[row][0]
        for rate in rates:
            d = differences.get(rate, {}).get(ckey)
            if d:
                xs, ys = zip(*d)
                ax.plot(xs, np.maximum(ys, 1e-7), color=colour[rate], label=f"{rate}x")
        ax.set_title(f"Discard vs {trav}: difference\n({where}; from the 8-bit PNGs)", fontsize=9)
        for col, run in enumerate(runs, start=1):
            ax = axes[row][col]
            b = by_key(run["entries"])
            for rate in rates:
                for m, ls in (("discard", "-"), (trav, "--")):
                    e = b.get((m, rate))
                    if e and e.get(ckey):
                        xs, ys = zip(*e[ckey])
                        ax.plot(xs, np.maximum(ys, 1e-7), color=colour[rate], ls=ls, lw=1.4)
            for m, ls in (("clamp", ":"), ("black", "-.")):
                for rate in (rates[0], rates[-1]):
                    e = b.get((m, rate))
                    if e and e.get(ckey):
                        xs, ys = zip(*e[ckey])
                        ax.plot(xs, np.maximum(ys, 1e-7), color="0.35" if rate == rates[0] else "0.65", ls=ls, lw=1.0)
            src = " (from the 8-bit PNGs)" if run["entries"] and run["entries"][0].get("curve_source") == "png" else ""
            ax.set_title(f"deviation from the {run['reference']} reference\n({where}){src}", fontsize=9)
    for ax in axes.ravel():
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(1e-4, 1)
        ax.set_ylim(1e-5, 1.2)
        ax.grid(True, which="both", alpha=0.25)
        ax.set_xlabel("x: 2-norm distance, linear RGB", fontsize=8)
        ax.set_ylabel("fraction of pixels with distance >= x", fontsize=8)
        ax.tick_params(labelsize=7)
    handles = [Line2D([], [], color=colour[r], label=f"{r}x MSAA") for r in rates]
    handles += [Line2D([], [], color="k", ls="-", label="Discard"), Line2D([], [], color="k", ls="--", label=f"Traverse ({trav})"),
                Line2D([], [], color="0.35", ls=":", label=f"clamp {rates[0]}x (control)"),
                Line2D([], [], color="0.65", ls=":", label=f"clamp {rates[-1]}x"),
                Line2D([], [], color="0.35", ls="-.", label=f"black {rates[0]}x (control)"),
                Line2D([], [], color="0.65", ls="-.", label=f"black {rates[-1]}x")]
    fig.legend(handles=handles, loc="lower center", ncol=min(6, len(handles)), fontsize=8)
    fig.suptitle(f"{regime['name']} ({runs[0]['size']}): Figure 5 of the paper, the fraction of pixels whose "
                 f"error is at least x (lower left is better)", fontsize=10)
    fig.tight_layout(rect=(0, 0.07, 1, 0.96))
    path = os.path.join(out, f"figure5_{regime['name']}.png")
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def box_blur(a, r):
    """Mean over a (2r+1)^2 window (edges clamped), by summed-area table."""
    p = np.pad(a, r + 1, mode="edge").cumsum(0).cumsum(1)
    k = 2 * r + 1
    return (p[k:, k:] - p[:-k, k:] - p[k:, :-k] + p[:-k, :-k])[: a.shape[0], : a.shape[1]] / (k * k)


def crop_window(cmp, d, rate, shape, methods):
    """A square around where Discard and Traverse differ most (box-filtered), else the centre."""
    h, w = shape
    side = max(16, min(128, h // 3, w // 3))
    cy, cx = h // 2, w // 2
    trav = traverse_variants(methods)
    try:
        if "discard" in methods and trav:
            dist = distance_linear(read_png(image_paths(cmp, d, "discard", rate)), read_png(image_paths(cmp, d, trav[0], rate)))
            cy, cx = np.unravel_index(np.argmax(box_blur(dist, side // 4)), dist.shape)
    except FileNotFoundError:
        pass
    y0 = int(min(max(0, cy - side // 2), h - side))
    x0 = int(min(max(0, cx - side // 2), w - side))
    return y0, x0, side


def chart_heatmaps(regime, run, out, rate):
    """One reference, one rate: per method its image, its 2-norm error against the reference (log
    colour scale) and its FLIP map, full frame and a close-up (a square around where Discard and
    Traverse differ most), with the reference and the seam mask in the first column."""
    d = run["images_dir"]
    cmp = run["compare"]
    methods = [m for m in METHODS if any(e["method"] == m and e["msaa"] == rate for e in run["entries"])]
    ref_path = reference_image_path(cmp, d, run["reference"], rate)
    if not methods or not os.path.exists(ref_path):
        return None
    ref = read_png(ref_path)
    mask_path = mask_image_path(cmp, d, rate)
    h, w = ref.shape[:2]
    y0, x0, side = crop_window(cmp, d, rate, (h, w), methods)
    crop = (slice(y0, y0 + side), slice(x0, x0 + side))
    ncol = len(methods) + 1
    panel = 2.4
    fig, axes = plt.subplots(5, ncol, figsize=(panel * ncol * max(0.8, min(1.3, w / h)) + 1.0, panel * 5 + 0.6),
                             squeeze=False, layout="constrained")
    axes[0][0].imshow(ref, interpolation="nearest")
    axes[0][0].add_patch(matplotlib.patches.Rectangle((x0 - 0.5, y0 - 0.5), side, side, fill=False, ec="w", lw=1.2))
    axes[0][0].set_title(f"reference: {run['reference']}\n(box: the close-up below)", fontsize=8)
    mask = None
    if os.path.exists(mask_path):
        mask = read_png(mask_path)[..., 0]
        axes[1][0].imshow(mask, cmap="gray", vmin=0, vmax=1, interpolation="nearest")
        axes[1][0].set_title(f"seam mask at {rate}x\n({run['mask_coverage'][str(rate)] * 100:.0f}% of the pixels)", fontsize=8)
        axes[4][0].imshow(mask[crop], cmap="gray", vmin=0, vmax=1, interpolation="nearest")
        axes[4][0].set_title("seam mask, close-up", fontsize=8)
    axes[3][0].imshow(ref[crop], interpolation="nearest")
    axes[3][0].set_title("reference, close-up", fontsize=8)
    axes[2][0].axis("off")
    axes[2][0].text(0.5, 0.5, "FLIP against the\nreference, per pixel\n(magma, as FLIP\nshows it)",
                    ha="center", va="center", fontsize=8, transform=axes[2][0].transAxes)
    norm = mcolors.LogNorm(vmin=1e-3, vmax=1.0)
    err_im = flip_im = None
    b = by_key(run["entries"])
    for col, method in enumerate(methods, start=1):
        img = read_png(image_paths(cmp, d, method, rate))
        e = b[(method, rate)]
        dist = np.maximum(distance_linear(img, ref), 1e-3)
        fmap, fmean = flip_map(ref, img)
        axes[0][col].imshow(img, interpolation="nearest")
        axes[0][col].set_title(f"{method} {rate}x ({e['ms']:.3g} ms)", fontsize=8)
        err_im = axes[1][col].imshow(dist, cmap="viridis", norm=norm, interpolation="nearest")
        axes[1][col].set_title(f"2-norm error\nseam mean {e['seam_mean']:.2e}", fontsize=8)
        flip_im = axes[2][col].imshow(fmap, cmap="magma", vmin=0, vmax=1, interpolation="nearest")
        fs = e.get("flip_seam_mean")
        axes[2][col].set_title(f"FLIP: mean {fmean:.3f}" + (f"\nover the mask {fs:.3f}" if fs is not None else ""), fontsize=8)
        axes[3][col].imshow(img[crop], interpolation="nearest")
        axes[3][col].set_title(f"{method} {rate}x, close-up", fontsize=8)
        axes[4][col].imshow(dist[crop], cmap="viridis", norm=norm, interpolation="nearest")
        axes[4][col].set_title("2-norm error, close-up", fontsize=8)
    for ax in axes.ravel():
        ax.set_xticks([])
        ax.set_yticks([])
    for row, label in enumerate(["image (sRGB)", "error vs reference", "", "close-up", "error, close-up"]):
        if label:
            axes[row][0].set_ylabel(label, fontsize=8)
    if err_im is not None:
        for row in (1, 4):
            fig.colorbar(err_im, ax=list(axes[row]), shrink=0.9, pad=0.01).set_label("2-norm, linear RGB", fontsize=8)
        fig.colorbar(flip_im, ax=list(axes[2]), shrink=0.9, pad=0.01).set_label("FLIP", fontsize=8)
    fig.suptitle(f"{regime['name']} at {rate}x MSAA, {run['size']}, against the {run['reference']} reference: each "
                 f"method's image, its per-pixel 2-norm error in linear RGB\n(log scale, from the 8-bit PNGs) and FLIP "
                 f"(0 = same, 1 = most different); rows 4-5: a {side}x{side} close-up where Discard and Traverse differ most",
                 fontsize=9)
    path = os.path.join(out, f"heatmaps_{regime['name']}.png")
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def image_differences(run, num="discard"):
    """Discard vs Traverse per rate from the PNGs: curves over all pixels and over the mask."""
    d, cmp = run["images_dir"], run["compare"]
    methods = {e["method"] for e in run["entries"]}
    trav = traverse_variants(methods)
    if num not in methods or not trav:
        return {}
    out = {}
    for rate in sorted({e["msaa"] for e in run["entries"]}):
        mask = read_mask(cmp, d, rate)
        try:
            a = read_png(image_paths(cmp, d, num, rate))
            b = read_png(image_paths(cmp, d, trav[0], rate))
        except FileNotFoundError:
            continue
        dist = distance_linear(a, b)
        out[rate] = {"curve": curve_of(dist), "seam_curve": curve_of(dist[mask]) if mask is not None else None,
                     "mean": float(dist.mean()), "seam_mean": float(dist[mask].mean()) if mask is not None and mask.any() else None}
    return out


# ---------------------------------------------------------------------------------------------
# Tables


def _rounded(v):
    if isinstance(v, float):
        return float(f"{v:.6g}")
    if isinstance(v, list):
        return [_rounded(x) for x in v]
    if isinstance(v, dict):
        return {k: _rounded(x) for k, x in v.items()}
    return v


def dump_json(obj, path):
    """Indented JSON with numbers to 6 significant digits and every curve on one line."""
    curves = []

    def strip(v):
        if isinstance(v, dict):
            out = {}
            for k, x in v.items():
                if k.endswith("curve") and isinstance(x, list):
                    curves.append(json.dumps(_rounded(x), separators=(",", ":")))
                    out[k] = f"@@curve{len(curves) - 1}@@"
                else:
                    out[k] = strip(x)
            return out
        if isinstance(v, list):
            return [strip(x) for x in v]
        return _rounded(v)

    text = json.dumps(strip(obj), indent=1)
    text = re.sub(r'"@@curve(\d+)@@"', lambda m: curves[int(m.group(1))], text)
    with open(path, "w") as f:
        f.write(text + "\n")


def frame_span(frames):
    """'0, 50, ..., 950 (every 50th)' for an even stride, else the list."""
    if len(frames) > 2 and len({b - a for a, b in zip(frames, frames[1:])}) == 1:
        return f"frames {frames[0]}, {frames[1]}, ..., {frames[-1]} (every {frames[1] - frames[0]}th)"
    return "frames " + ", ".join(map(str, frames))


def p99_cell(v):
    """A p99 read off a curve at its first threshold (1e-4) is only known to be at most that."""
    return "<= 1e-04" if v is not None and v <= thresholds()[0] * (1 + 1e-9) else fmt(v)


def coverage_span(run):
    """The seam mask's coverage: one figure, or its range over the rates (one mask per rate)."""
    v = sorted(run["mask_coverage"].values())
    if not v:
        return "-"
    return f"{v[0] * 100:.1f}%" if v[-1] - v[0] < 5e-4 else f"{v[0] * 100:.1f}-{v[-1] * 100:.1f}%"


def fmt(v, spec=".3e"):
    return "-" if v is None else format(v, spec)


def results_md(study):
    L = [f"# Accuracy study ({study['preset']} preset)", "",
         f"Made by `{study['command']}` on {study['device']}, {study['wall_s'] / 60:.1f} min wall.", "",
         "Errors: per-pixel 2-norm in linear RGB against the reference, over the seam mask, over its "
         "complement (off), and over all pixels. FLIP: NVIDIA's perceptual difference (flip-evaluator, LDR, "
         "67 pixels per degree) between the 8-bit sRGB images. Time: median of compare's timed renders.", ""]
    if study["skipped"]:
        L += ["Not run (the binary lacks what they need):", ""]
        L += [f"- {s['regime']}" + (f" / {s['reference']}" if s.get("reference") else "") + f": {s['why']}"
              for s in study["skipped"]]
        L.append("")
    L += ["## Summary: Discard / Traverse per rate, and FLIP", "",
          "Seam error ratio r = Discard's seam mean / Traverse's (below 1: Discard better). FLIP over the seam mask, "
          "Discard and Traverse, at 1x and 8x.", "",
          "| regime | reference | traverse | r 1x | r 4x | r 8x | r 16x | FLIP 1x D / T | FLIP 8x D / T |",
          "| --- | --- | --- | ---: | ---: | ---: | ---: | --- | --- |"]
    for reg in study["regimes"]:
        for run in reg["runs"]:
            b = by_key(run["entries"])
            for t, r in run["analysis"]["ratios"].items():
                def fl(rate):
                    d, tr = b.get(("discard", rate), {}), b.get((t, rate), {})
                    return f"{fmt(d.get('flip_seam_mean'), '.4f')} / {fmt(tr.get('flip_seam_mean'), '.4f')}"
                L.append(f"| {reg['name']} | {run['reference']} | {t} | " +
                         " | ".join(fmt(r.get(k), ".3f") for k in ("1", "4", "8", "16")) + f" | {fl(1)} | {fl(8)} |")
    L.append("")
    L += ["## The paper's claims, per regime and reference", "",
          f"Rules on the Discard / Traverse seam-error ratio r (seam mean): worse r > {1 + TIE:.2f}, even |r - 1| <= {EVEN}, "
          f"better r < {1 - TIE:.2f} (within {TIE * 100:.0f}% of 1 is a tie). Traverse is the paper's (`traverse-edges`, McDonald's) where present, and `traverse` "
          "(with corners) too.", "",
          "| regime | reference | traverse | " + " | ".join(f"r {c['rate']}x" for c in CLAIMS) + " | r 16x | " +
          " | ".join(c["short"] for c in CLAIMS) + " |",
          "| --- | --- | --- |" + " ---: |" * (len(CLAIMS) + 1) + " --- |" * len(CLAIMS)]
    for reg in study["regimes"]:
        for run in reg["runs"]:
            for t, claims in run["analysis"]["claims"].items():
                r = run["analysis"]["ratios"][t]
                L.append(f"| {reg['name']} | {run['reference']} | {t} | " +
                         " | ".join(fmt(r.get(str(c["rate"])), ".3f") for c in CLAIMS) + f" | {fmt(r.get('16'), '.3f')} | " +
                         " | ".join(c["verdict"] for c in claims) + " |")
    L += ["", "## Controls: black and clamp seam error over traverse's (min over rates)", "",
          "| regime | reference | mask coverage | black / traverse | clamp / traverse | apart by 2x |",
          "| --- | --- | ---: | ---: | ---: | --- |"]
    for reg in study["regimes"]:
        for run in reg["runs"]:
            c = run["analysis"]["controls"]
            bl, cl = c.get("black", {}).get("min"), c.get("clamp", {}).get("min")
            apart = "-" if bl is None or cl is None else ("yes" if min(bl, cl) >= 2 else "no")
            if not reg.get("controls", True):
                apart += " (control: a constant colour carries no seam error, so clamp equals traverse by construction)"
            L.append(f"| {reg['name']} | {run['reference']} | {coverage_span(run)} | {fmt(bl, '.2f')} | "
                     f"{fmt(cl, '.2f')} | {apart} |")
    for reg in study["regimes"]:
        L += ["", f"## {reg['name']}: {reg['what']}", "", f"compare arguments: `{shlex.join(reg['args'])}`" +
              (f" (the scene file: `{json.dumps({'generator': reg['args'][1].split('_')[0], 'options': {'content': 'detail'}})}`)"
               if reg['args'][1].endswith("_detail.json") else ""), ""]
        for run in reg["runs"]:
            L += [f"### reference `{run['reference']}` ({run['size']}, seam mask {coverage_span(run)} of the pixels)",
                  "", f"`{shlex.join(run['command'])}`", "",
                  "| method | msaa | ms | seam mean | seam p99 | off mean | off p99 | all mean | FLIP | FLIP seam | FLIP off | NaN px |",
                  "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
            for e in run["entries"]:
                L.append(f"| {e['method']} | {e['msaa']} | {e['ms']:.2f} | {fmt(e['seam_mean'])} | {fmt(e['seam_p99'])} | "
                         f"{fmt(e['off_mean'])} | {p99_cell(e['off_p99'])} | {fmt(e['mean'])} | {fmt(e.get('flip_mean'), '.4f')} | "
                         f"{fmt(e.get('flip_seam_mean'), '.4f')} | {fmt(e.get('flip_off_mean'), '.4f')} | {e['nan_pixels']} |")
            derived = {e["off_source"] for e in run["entries"]}
            if "derived" in derived:
                L += ["", "off mean: exact, from the all-pixel and seam means and the pixel counts; off p99: from the "
                      "curves (log interpolation between compare's thresholds, 10 per decade)."]
            for t, r in run["analysis"]["ratios"].items():
                fr = run["analysis"]["flip_ratios"].get(t, {})
                L += ["", f"Discard / {t}, per rate: seam error " +
                      ", ".join(f"{k}x {v:.3f}" for k, v in r.items()) +
                      ("; FLIP over the mask " + ", ".join(f"{k}x {v:.3f}" for k, v in fr.items()) if fr else "")]
    return "\n".join(L) + "\n"


# ---------------------------------------------------------------------------------------------


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("--seamcl", default=os.path.join(ROOT, "build", "seamcl"), help="the binary [build/seamcl]")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "accuracy"), help="results folder")
    ap.add_argument("--quick", action="store_true", help="tiny preset (the cube regimes at 48x54, one timed render): for the test")
    ap.add_argument("--regimes", help="comma list of regime names (default: the preset's)")
    ap.add_argument("--references", help="comma list of references (default: every one compare offers)")
    ap.add_argument("--methods", default=",".join(METHODS), help="comma list; those the binary lacks are left out")
    ap.add_argument("--msaa", help="comma list of MSAA rates (default: the preset's)")
    ap.add_argument("--size", help="WIDTHxHEIGHT (default: the preset's)")
    ap.add_argument("--repeat", type=int, help="timed renders per entry (default: the preset's)")
    ap.add_argument("--heatmap-msaa", type=int, default=1, help="MSAA rate of the heat maps [1]")
    ap.add_argument("--cache", help="reference cache folder (compare's --cache)")
    ap.add_argument("--images", help="keep compare's images here (default: a temporary folder, removed)")
    ap.add_argument("--reuse", action="store_true",
                    help="with --images: where a regime's folder holds compare.json from an earlier run, use it and its "
                         "images instead of running compare (to redraw the charts)")
    ap.add_argument("--no-flip", action="store_true", help="skip FLIP (it is on by default and needs flip-evaluator)")
    ap.add_argument("--compare-arg", action="append", default=[], help="extra argument for every compare (repeatable)")
    args = ap.parse_args(argv)

    preset_name = "quick" if args.quick else "full"
    preset = PRESETS[preset_name]
    if not args.no_flip:
        flip_module()  # fail now, not after an hour, when FLIP is missing
    binary = Binary(args.seamcl)
    regimes = preset["regimes"]
    if args.regimes:
        wanted = args.regimes.split(",")
        known = {r["name"]: r for r in REGIMES + QUICK_REGIMES}
        unknown = [w for w in wanted if w not in known]
        if unknown:
            ap.error(f"unknown regimes {unknown}; known: {sorted(known)}")
        regimes = [known[w] for w in wanted]
    offered = binary.references()
    references = args.references.split(",") if args.references else offered
    methods = [m for m in args.methods.split(",") if m in binary.methods]
    rates = [int(x) for x in args.msaa.split(",")] if args.msaa else preset["rates"]
    size = args.size or preset["size"]
    repeat = args.repeat or preset["repeat"]
    os.makedirs(args.out, exist_ok=True)
    work = args.images or tempfile.mkdtemp(prefix="seamcl-study-")
    study = {"preset": preset_name, "command": shlex.join([os.path.basename(sys.executable)] + [os.path.relpath(sys.argv[0], ROOT)] + (argv if argv is not None else sys.argv[1:])),
             "seamcl": binary.version(), "device": "?", "methods": methods,
             "missing_methods": [m for m in args.methods.split(",") if m not in binary.methods],
             "rates": rates, "size": size, "repeat": repeat, "references_offered": offered,
             "reference_option": binary.reference_option(), "flip": None if args.no_flip else
             {"package": "flip-evaluator", "range": "LDR", "inputs": "8-bit sRGB PNGs", "ppd": 67},
             "even_tolerance": EVEN, "tie_tolerance": TIE, "claims": CLAIMS, "regimes": [], "skipped": []}
    for m in study["missing_methods"]:
        log(f"study: method '{m}' is not in this seamcl; left out")
    todo = []
    for reg in regimes:
        why = regime_missing(binary, reg)
        if why:
            study["skipped"].append({"regime": reg["name"], "why": why})
            log(f"study: regime {reg['name']} skipped: {why}")
            continue
        todo.append(reg)
    for ref in references:
        if ref not in offered:
            study["skipped"].append({"regime": "*", "reference": ref, "why": "compare does not offer it"})
    references = [r for r in references if r in offered]
    t_start = time.monotonic()
    runs_by_regime = {}
    for k, reg in enumerate(todo, start=1):
        elapsed = time.monotonic() - t_start
        eta = "" if k == 1 else f", about {elapsed / (k - 1) * (len(todo) - k + 1) / 60:.1f} min left"
        log(f"study [{k}/{len(todo)}] {reg['name']}: compare {len(methods)} methods x {len(rates)} rates at {size} "
            f"against {', '.join(references)} ({elapsed / 60:.1f} min so far{eta})")
        images_dir = os.path.join(work, reg["name"])
        os.makedirs(images_dir, exist_ok=True)
        cargs = regime_args(reg, images_dir) + ["--methods", ",".join(methods), "--msaa", ",".join(map(str, rates)),
                                     "--size", size, "--repeat", str(repeat)] + args.compare_arg
        if args.cache:
            cargs += ["--cache", args.cache]
        try:
            cmp, cmd, wall, dropped = compare_with_references(binary, cargs, images_dir, references, args.reuse)
        except RuntimeError as e:
            study["skipped"].append({"regime": reg["name"], "why": str(e)})
            log(f"study: {e}; recorded in results.json")
            continue
        for r, why in dropped:
            study["skipped"].append({"regime": reg["name"], "reference": r, "why": why})
        study["device"] = cmp.get("device", study["device"])
        cmd_shown = ["build/seamcl"] + cmd[1:]
        cmd_shown[cmd_shown.index("--images") + 1] = "DIR"
        cmd_shown = [os.path.basename(a) if a.startswith(images_dir) and a.endswith(".json") else a for a in cmd_shown]
        infos = {r.get("name", "paper"): r for r in cmp.get("references", [])} if isinstance(cmp.get("references"), list) else {}
        for name in reference_names(cmp):
            t_flip = time.monotonic()
            entries = measure_run(cmp, images_dir, name, with_flip=not args.no_flip)
            log(f"study   {reg['name']} / {name}: FLIP and curves {time.monotonic() - t_flip:.1f} s")
            run = {"reference": name, "reference_info": infos.get(name, cmp.get("reference")), "size": cmp["size"],
                   "command": cmd_shown, "compare_wall_s": wall, "seam_pixels": cmp.get("seam_pixels"),
                   "mask_coverage": {str(r): mask_coverage(cmp, r) for r in rates},
                   "mask_definition": mask_definition(cmp),
                   "entries": entries, "analysis": analyse_run(entries, reg.get("controls", True)),
                   "images_dir": images_dir, "compare": cmp}
            runs_by_regime.setdefault(reg["name"], (reg, []))[1].append(run)
        log(f"study   compare took {wall:.1f} s")

    figures = []
    for name, (reg, runs) in runs_by_regime.items():
        log(f"study: charts for {name}")
        diffs = image_differences(runs[0])
        figures.append(chart_pareto(reg, runs, args.out))
        figures.append(chart_figure5(reg, runs, args.out, diffs))
        if not args.no_flip:
            hm_rate = args.heatmap_msaa if args.heatmap_msaa in rates else rates[0]
            figures.append(chart_heatmaps(reg, runs[0], args.out, hm_rate))
        keep = {"name": reg["name"], "what": reg["what"], "args": shown_args(reg), "controls": reg.get("controls", True),
                "differences": {str(k): {kk: vv for kk, vv in v.items() if kk in ("mean", "seam_mean")} for k, v in diffs.items()},
                "runs": [{k: v for k, v in run.items() if k not in ("images_dir", "compare")} for run in runs]}
        study["regimes"].append(keep)
    study["wall_s"] = time.monotonic() - t_start
    study["figures"] = [os.path.basename(f) for f in figures if f]
    dump_json(study, os.path.join(args.out, "results.json"))
    with open(os.path.join(args.out, "results.md"), "w") as f:
        f.write(results_md(study))
    if not args.images:
        shutil.rmtree(work, ignore_errors=True)
    for p in ["results.json", "results.md"] + study["figures"]:
        print(os.path.join(args.out, p))
    log(f"study: done in {study['wall_s'] / 60:.1f} min; {len(study['skipped'])} skipped (see results.md)")
    return 0 if study["regimes"] else 1


if __name__ == "__main__":
    sys.exit(main())
