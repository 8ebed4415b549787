#!/usr/bin/env python3
"""Run time against error: plots asval_builder_sweep's CSV (build time vs SAH / Embree-HIGH SAH).

Usage: plot_sweep.py sweep.csv out.png     (needs python3-matplotlib)
One panel per scene; x = single-thread build time (ms, log), y = SAH ratio to Embree rtcBuildBVH HIGH.
asval knob sweeps are connected lines; Embree's anchors are overlaid as labelled markers.
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(path, out):
    rows = list(csv.DictReader(open(path)))
    scenes = []
    for r in rows:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    high = {}
    for r in rows:
        if r["builder"] == "embree_user_HIGH":
            high[r["scene"]] = float(r["sah"])
    cols = 2 if len(scenes) > 1 else 1
    rows_n = (len(scenes) + cols - 1) // cols
    fig, axes = plt.subplots(rows_n, cols, figsize=(7 * cols, 5 * rows_n), squeeze=False)
    for ax, scene in zip([a for row in axes for a in row], scenes):
        series = defaultdict(list)
        for r in rows:
            if r["scene"] != scene or r["threads"] != "1":
                continue
            sah = float(r["sah"])
            if sah <= 0 or scene not in high:
                continue
            ms = float(r["seconds"]) * 1e3
            ratio = sah / high[scene]
            b = r["builder"]
            if b.startswith("embree"):
                ax.scatter([ms], [ratio], marker="s", color="black")
                ax.annotate(b.replace("embree_user_", "Embree "), (ms, ratio), fontsize=7,
                            textcoords="offset points", xytext=(4, 4))
            else:
                key = b
                if b == "asval_sah":
                    k = r["knobs"]
                    key = "asval SAH: " + ("split budget/factor" if ("split" in k or "factor" in k)
                                           else "bins" if k.endswith("leaf8") else "max leaf")
                series[key].append((ms, ratio, r["knobs"]))
        for key, pts in series.items():
            pts.sort()
            style = "*" if key == "asval_default" else "o-"
            ax.plot([p[0] for p in pts], [p[1] for p in pts], style, label=key, markersize=9 if style == "*" else 4)
            for ms, ratio, knobs in pts:
                ax.annotate(knobs.replace("_leaf8", "").replace("bins16_", ""), (ms, ratio), fontsize=6,
                            textcoords="offset points", xytext=(3, -8))
        for r in rows:  # HIGH's single-thread time may be skipped at 1M; mark it at 2 threads
            if r["scene"] == scene and r["builder"] == "embree_user_HIGH" and r["threads"] == "2":
                ax.scatter([float(r["seconds"]) * 1e3], [1.0], marker="D", color="gray")
                ax.annotate("Embree HIGH (2T)", (float(r["seconds"]) * 1e3, 1.0), fontsize=7,
                            textcoords="offset points", xytext=(4, -10))
        ax.set_xscale("log")
        if scene == "clustered":
            ax.set_yscale("log")
        ax.set_title(scene)
        ax.set_xlabel("build time, 1 thread (ms)")
        ax.set_ylabel("SAH / Embree HIGH SAH")
        ax.axhline(1.02, color="green", lw=0.6, ls="--")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
