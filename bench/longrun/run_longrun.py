#!/usr/bin/env python3
"""Long run of the sample scene under asval (issue 14): memory and per-frame cost over 10,000 frames.

Runs examples/scene's asval_scene on lavapipe (the integration tests' environment: the real loader, the layer
from the build tree, no implicit layers, a private HOME) with capture on (the layer's default settings), once
per frame count (100, 1,000, 10,000 by default), each process printing checkpoints (--checkpoints: resident memory
now and at its peak, wall time per frame of the 100 frames before) and ending with the layer's
ASVAL-Layer-Footprint information message at vkDestroyDevice (read from the JSON report: what the layer holds
then, and the peaks its growing containers kept). The same scene without any layer runs once for the largest
count, with the same checkpoints (the pass-through baseline). Peak resident memory and CPU time of each process
come from wait4's rusage.

Prints a table and writes a JSON result (--json). Memory is "flat" when the resident memory and every footprint
count at the largest count equal those at the one before, within --rss-tolerance-kb for memory.

usage: run_longrun.py --build DIR [--frames 100,1000,10000] [--size 64x64] [--instances 500] [--json FILE]
"""

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from typing import Dict, List, Optional

ASVAL = "VK_LAYER_ASVAL_as_validation"
LAVAPIPE_ICD = "/usr/share/vulkan/icd.d/lvp_icd.json"
FOOTPRINT_ID = "ASVAL-Layer-Footprint"
CHECKPOINT = re.compile(r"^checkpoint: frames (\d+); rss_kb (-?\d+); rss_peak_kb (-?\d+); heap_bytes (\d+); "
                        r"frames (\d+)\.\.(\d+): mean ([\d.]+) ms, median ([\d.]+) ms, max ([\d.]+) ms, "
                        r"cpu ([\d.]+) ms$")
MESSAGES = re.compile(r"^validation messages: (\d+) error\(s\), (\d+) warning\(s\)$")
PAIR = re.compile(r"\b([a-z_]+)=(\d+)\b")
# Footprint counts shown in the table (all are in the JSON).
SHOWN = ["structures", "buffers", "command_buffers", "recorded_operations", "capture_logs", "history_records",
         "serialized_blobs", "query_slots", "capture_slabs", "capture_slab_bytes", "capture_pending_submissions",
         "peak_capture_slabs_in_use", "peak_capture_pending_submissions", "peak_history_records"]


def parse_args(argv: List[str]) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--build", required=True, help="build tree with layer/ and examples/scene/asval_scene")
    p.add_argument("--frames", default="100,1000,10000", help="frame counts, ascending (one process each)")
    p.add_argument("--size", default="64x64", help="render size (lavapipe renders on the CPU)")
    p.add_argument("--instances", type=int, default=500, help="instances in the top-level structure")
    p.add_argument("--json", default=None, help="write the result here")
    p.add_argument("--rss-tolerance-kb", type=int, default=1024,
                   help="resident memory at the last two counts may differ by this much and still be flat")
    p.add_argument("--skip-baseline", action="store_true", help="do not run the scene without the layer")
    p.add_argument("--layer-env", action="append", default=[], metavar="VAR=VALUE",
                   help="an environment variable for the runs under the layer, e.g. "
                        "VK_ASVAL_AS_VALIDATION_CAPTURE=all (repeatable)")
    args = p.parse_args(argv)
    args.counts = [int(x) for x in args.frames.split(",")]
    if any("=" not in item for item in args.layer_env):
        p.error("--layer-env: VAR=VALUE")
    if args.counts != sorted(set(args.counts)) or args.counts[0] < 1:
        p.error("--frames: ascending positive counts")
    return args


def base_environment(build: str) -> Dict[str, str]:
    """lavapipe, the real loader, the layer from the build tree, no implicit layers, a private HOME and XDG folder
    without a settings file; every VK_* variable of the caller's dropped (each run names its own)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("VK_")}
    xdg = os.path.join(build, "bench", "longrun", "xdg")
    os.makedirs(xdg, exist_ok=True)
    env.update({
        "VK_LAYER_PATH": os.path.join(build, "layer"),
        "VK_DRIVER_FILES": os.environ.get("VK_DRIVER_FILES", LAVAPIPE_ICD),
        "VK_LOADER_LAYERS_DISABLE": "~implicit~",
        "HOME": xdg,
        "XDG_DATA_HOME": xdg,
        "VK_LAYER_SETTINGS_PATH": os.path.join(xdg, "none"),
    })
    return env


def run_scene(args, frames: int, with_layer: bool, env: Dict[str, str]) -> Dict:
    scene = os.path.join(args.build, "examples", "scene", "asval_scene")
    checkpoints = [c for c in args.counts if c <= frames]
    argv = [scene, "--frames", str(frames), "--size", args.size, "--instances", str(args.instances)]
    if checkpoints:
        argv += ["--checkpoints", ",".join(str(c) for c in checkpoints)]
    env = dict(env)
    report = None
    if with_layer:
        fd, report = tempfile.mkstemp(prefix="asval-longrun-", suffix=".jsonl")
        os.close(fd)
        env["VK_INSTANCE_LAYERS"] = ASVAL
        # Information messages on, for the footprint; everything else the layer's defaults (capture=updates).
        env["VK_ASVAL_AS_VALIDATION_REPORT_FILE"] = report
        env["VK_ASVAL_AS_VALIDATION_REPORT_FLAGS"] = "error,warn,info"
        env.update(dict(item.split("=", 1) for item in args.layer_env))
    started = time.monotonic()
    with tempfile.TemporaryFile("w+") as out_file, tempfile.TemporaryFile("w+") as err_file:
        proc = subprocess.Popen(argv, env=env, stdout=out_file, stderr=err_file, text=True)
        # Reaped here rather than by Popen, for the child's own rusage: its peak resident memory.
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
        wall = time.monotonic() - started
        out_file.seek(0)
        err_file.seek(0)
        out, err = out_file.read(), err_file.read()
    result = {"frames": frames, "layer": with_layer, "argv": argv, "exit": proc.returncode, "wall_s": round(wall, 2),
              "cpu_s": round(usage.ru_utime + usage.ru_stime, 2), "max_rss_kb": usage.ru_maxrss,
              "checkpoints": [], "errors": None, "warnings": None, "footprint": None, "stderr_tail": err[-2000:]}
    for line in out.splitlines():
        m = CHECKPOINT.match(line)
        if m:
            result["checkpoints"].append({
                "frames": int(m[1]), "rss_kb": int(m[2]), "rss_peak_kb": int(m[3]), "heap_bytes": int(m[4]),
                "window": [int(m[5]), int(m[6])], "mean_ms": float(m[7]), "median_ms": float(m[8]),
                "max_ms": float(m[9]), "cpu_ms": float(m[10])})
        m = MESSAGES.match(line)
        if m:
            result["errors"], result["warnings"] = int(m[1]), int(m[2])
    if report:
        with open(report, encoding="utf-8") as f:
            for line in f:
                entry = json.loads(line)
                if entry.get("vuid") == FOOTPRINT_ID:
                    result["footprint"] = {k: int(v) for k, v in PAIR.findall(entry.get("message", ""))}
        os.remove(report)
    if proc.returncode != 0:
        sys.stderr.write(f"run_longrun: {' '.join(argv)} exited {proc.returncode}\n{err[-2000:]}\n")
    return result


def checkpoint(run: Dict, frames: int) -> Optional[Dict]:
    return next((c for c in run["checkpoints"] if c["frames"] == frames), None)


def fmt_ms(c: Optional[Dict]) -> str:
    return f"{c['mean_ms']:.2f}/{c['median_ms']:.2f}/{c['cpu_ms']:.2f}" if c else "-"


def fmt_int(c: Optional[Dict], key: str) -> str:
    return f"{c[key]:,}" if c else "-"


def print_table(args, layer_runs: List[Dict], baseline: Optional[Dict]) -> None:
    longest = layer_runs[-1]
    print(f"\nscene --size {args.size} --instances {args.instances}, lavapipe, checkpoints of the {longest['frames']}-frame "
          f"processes; ms/frame: wall mean/median/CPU mean of the 100 frames before (frame 1, the builds, never in a "
          f"window); peak RSS: the asval process of that many frames (wait4)")
    print(f"{'frames':>7} | {'RSS kB none':>11} | {'RSS kB asval':>12} | {'heap B none':>12} | {'heap B asval':>12} | "
          f"{'ms/frame none':>18} | {'ms/frame asval':>18} | {'peak RSS kB':>11}")
    for n in args.counts:
        b = checkpoint(baseline, n) if baseline else None
        a = checkpoint(longest, n)
        own = next(r for r in layer_runs if r["frames"] == n)
        print(f"{n:>7} | {fmt_int(b, 'rss_kb'):>11} | {fmt_int(a, 'rss_kb'):>12} | {fmt_int(b, 'heap_bytes'):>12} | "
              f"{fmt_int(a, 'heap_bytes'):>12} | {fmt_ms(b):>18} | {fmt_ms(a):>18} | {own['max_rss_kb']:>11,}")
    print("\nASVAL-Layer-Footprint at vkDestroyDevice (after the scene destroyed its objects: what is left, and the "
          "peaks), one process per count:")
    print(f"{'count':<36}" + "".join(f"{n:>12}" for n in args.counts))
    keys = SHOWN + [k for k in (layer_runs[-1]["footprint"] or {}) if k not in SHOWN]
    for k in keys:
        print(f"{k:<36}" + "".join(f"{(r['footprint'] or {}).get(k, '-'):>12}" for r in layer_runs))


def flatness(args, layer_runs: List[Dict], baseline: Optional[Dict]) -> Dict:
    """Compares the last two counts: footprint counts must be equal, resident memory and heap bytes in use grow
    no more with the layer than without it (resident memory within --rss-tolerance-kb; the checkpoints of the
    longest runs)."""
    if len(args.counts) < 2:
        return {}
    n0, n1 = args.counts[-2], args.counts[-1]
    f0, f1 = layer_runs[-2]["footprint"] or {}, layer_runs[-1]["footprint"] or {}
    changed = {k: [f0.get(k), f1.get(k)] for k in sorted(set(f0) | set(f1)) if f0.get(k) != f1.get(k)}
    out = {"compared": [n0, n1], "footprint_changed": changed}
    for name, run in (("asval", layer_runs[-1]), ("none", baseline)):
        if not run:
            continue
        c0, c1 = checkpoint(run, n0), checkpoint(run, n1)
        if c0 and c1:
            out[f"rss_growth_kb_{name}"] = c1["rss_kb"] - c0["rss_kb"]
            out[f"heap_growth_bytes_{name}"] = c1["heap_bytes"] - c0["heap_bytes"]
            out[f"wall_ms_per_frame_change_{name}"] = round(c1["mean_ms"] - c0["mean_ms"], 3)
            out[f"cpu_ms_per_frame_change_{name}"] = round(c1["cpu_ms"] - c0["cpu_ms"], 3)
    growth = out.get("rss_growth_kb_asval")
    heap = out.get("heap_growth_bytes_asval")
    out["flat"] = (not changed and growth is not None and
                   growth - out.get("rss_growth_kb_none", 0) <= args.rss_tolerance_kb and
                   heap - out.get("heap_growth_bytes_none", 0) <= 1024 * args.rss_tolerance_kb)
    return out


def main(argv: List[str]) -> int:
    args = parse_args(argv)
    env = base_environment(os.path.abspath(args.build))
    # Mesa compiles the scene's shaders into its disk cache (in the private HOME) on the first run: that run's
    # frame 0 and its resident memory are not those of the others, so a short run of each configuration goes first.
    for with_layer in (False, True):
        warm = run_scene(args, 2, with_layer, env)
        if warm["exit"] != 0:
            sys.stderr.write("run_longrun: the warm-up run failed\n")
            return 1
    layer_runs = []
    for n in args.counts:
        print(f"asval, {n} frames ...", flush=True)
        layer_runs.append(run_scene(args, n, True, env))
        print(f"  {layer_runs[-1]['wall_s']} s", flush=True)
    baseline = None
    if not args.skip_baseline:
        print(f"no layer, {args.counts[-1]} frames ...", flush=True)
        baseline = run_scene(args, args.counts[-1], False, env)
        print(f"  {baseline['wall_s']} s", flush=True)
    print_table(args, layer_runs, baseline)
    flat = flatness(args, layer_runs, baseline)
    print(f"\nflat: {json.dumps(flat)}")
    failed = [r for r in layer_runs + ([baseline] if baseline else []) if r["exit"] != 0]
    errors = [r for r in layer_runs if r["errors"] or r["footprint"] is None]
    result = {"command": " ".join([os.path.basename(sys.argv[0])] + argv), "runs": layer_runs, "baseline": baseline,
              "flatness": flat, "uname": " ".join(os.uname())}
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(result, f, indent=1)
            f.write("\n")
    if failed or errors:
        sys.stderr.write("run_longrun: a run failed, reported an error, or had no footprint message\n")
        return 1
    return 0 if flat.get("flat", True) else 3


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
