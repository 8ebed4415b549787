#!/usr/bin/env python3
"""Markdown table of asval_builder_sweep's CSV: per scene, every point's time, Mprims/s, SAH and ratio.

Usage: sweep_table.py sweep.csv > table.md
"""
import csv
import sys


def main(path):
    rows = list(csv.DictReader(open(path)))
    high = {r["scene"]: float(r["sah"]) for r in rows if r["builder"] == "embree_user_HIGH"}
    print("| scene | builder | knobs | threads | wall ms | Mprims/s (wall) | Mprims/s (CPU time) | SAH | x Embree HIGH | peak B/prim |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        sah = float(r["sah"])
        ratio = f"{sah / high[r['scene']]:.3f}" if sah > 0 and r["scene"] in high else "-"
        cpu = float(r.get("cpu_seconds") or 0)
        tris = float(r["mprims"]) * float(r["seconds"])  # Mtriangles
        cpu_rate = f"{tris / cpu:.2f}" if cpu > 0 and r["threads"] == "1" else "-"
        print(f"| {r['scene']} | {r['builder']} | {r['knobs']} | {r['threads']} | {float(r['seconds']) * 1e3:.0f} | "
              f"{float(r['mprims']):.2f} | {cpu_rate} | {sah:.2f} | {ratio} | {r['peak_bpp'] if r['peak_bpp'] != '0' else '-'} |")


if __name__ == "__main__":
    main(sys.argv[1])
