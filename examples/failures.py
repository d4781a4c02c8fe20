#!/usr/bin/python3
"""Charts for docs/results/failures/ from the JSON the Failure.* tests write.

    SEAMCL_FAILURES_OUT=docs/results/failures build/seamcl_tests --gtest_filter='Failure*'
    /usr/bin/python3 examples/failures.py docs/results/failures

Writes failures.png: grazing error by eye height, guard band difference by g, temporal flicker.
Only for the figures; the tests do not need it.
"""
import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

d = Path(sys.argv[1] if len(sys.argv) > 1 else "docs/results/failures")
grazing = json.loads((d / "grazing.json").read_text())["results"]
guard = json.loads((d / "guardband.json").read_text())["results"]
temporal = json.loads((d / "temporal.json").read_text())

fig, ax = plt.subplots(1, 3, figsize=(14, 4))
heights = [r["height"] for r in grazing]
for m in ["clamp", "discard", "traverse", "guardband"]:
    ax[0].plot(heights, [r[m]["seam_mean"] for r in grazing], "o-", label=f"{m} seams")
    ax[0].plot(heights, [r[m]["beyond_16x_mean"] for r in grazing], "x--", label=f"{m} beyond 16:1")
ax[0].set_xscale("log")
ax[0].invert_xaxis()
ax[0].set_xlabel("eye height over the plane")
ax[0].set_ylabel("mean error vs reference")
ax[0].set_title("plane, grazing: seam pixels / pixels beyond 16:1")
ax[0].legend(fontsize=7)

gs = [r["g"] for r in guard]
ax[1].plot(gs, [r["seam_mean_vs_traverse"] for r in guard], "o-", label="all seam pixels")
for b in range(len(guard[0]["by_probes"])):
    top = guard[0]["by_probes"][b]["probes_up_to"]
    if guard[0]["by_probes"][b]["pixels"] == 0:
        continue
    ax[1].plot(gs, [r["by_probes"][b]["mean"] for r in guard], "x--", label=f"probes N <= {top}")
ax[1].set_xscale("log", base=2)
ax[1].set_xlabel("guard band g (texels)")
ax[1].set_ylabel("mean |guardband - traverse|")
ax[1].set_title("plane: guard band vs traverse, seam pixels")
ax[1].legend(fontsize=7)

rows = temporal["results"]
labels = [f'{r["method"]}\n{r["msaa"]}x' for r in rows]
ax[2].bar(range(len(rows)), [r["error_change"] for r in rows])
ax[2].set_xticks(range(len(rows)), labels, fontsize=8)
ax[2].set_ylabel("mean frame-to-frame change of the error")
ax[2].set_title("paper orbit, 0.5 deg/frame: flicker near seams")
fig.tight_layout()
fig.savefig(d / "failures.png", dpi=100)
