#!/usr/bin/env python3
"""The paper's Figure 5 for Discard and Traverse, from Python (docs/python.md): left, the fraction
of pixels where the two images differ by at least x, per MSAA rate; right, the fraction that
deviate from the reference by at least x (compare's `curve`).
    PYTHONPATH=build/python python3 examples/figure5.py [OUT.png [WxH]]"""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import seamcl  # noqa: E402

out = sys.argv[1] if len(sys.argv) > 1 else "figure5.png"
size = sys.argv[2] if len(sys.argv) > 2 else "160x180"
c = seamcl.compare(scene="paper", size=size, methods=["discard", "traverse"], msaa=[1, 8], images=True)
fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5), sharey=True)
x = np.array([point[0] for point in c.results[0]["curve"]])
for msaa in (1, 8):
    d = np.linalg.norm(c.images["discard", msaa][..., :3] - c.images["traverse", msaa][..., :3], axis=-1)
    left.plot(x, [(d >= t).mean() for t in x], label=f"{msaa}x")
for r in c.results:
    right.plot(x, [y for _, y in r["curve"]], "-" if r["method"] == "discard" else "--", label=f"{r['method']} {r['msaa']}x")
for ax, title in ((left, "||discard - traverse|| >= x"), (right, "||image - reference|| >= x")):
    ax.set(xscale="log", xlabel="x", title=title)
    ax.legend()
left.set_ylabel("fraction of pixels")
fig.savefig(out, dpi=110)
print(f"figure5: wrote {out}")
