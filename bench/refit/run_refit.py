#!/usr/bin/env python3
"""run_refit.py: what validation layers cost in heavy-refit frames (issue 27). Each case runs refit_frames (N
bottom-level structures of T triangles moved by a compute shader, refit in place as N calls or as one call of N
infos, one top-level update) under each configuration as its own process: no layer, asval at default settings,
asval with capture=off, and the installed Khronos layer (skipped when not installed). Configurations are
interleaved round by round; the table holds the median over rounds of each run's per-frame means (CPU record,
submit+wait, GPU time from timestamps, frame time) with frame and GPU time against no layer.

--callgrind: instructions per measured frame over all threads for no layer, asval and asval capture=off (100
structures of 256 triangles as 100 calls unless told otherwise), and the ratio of what asval adds at default
settings to what it adds with capture off (the issue's lavapipe target: at most 2).
--smoke: CI's quick mode (N 1 and 10, 64 triangles, 3 frames, one round, no timing asserted), then one run of
each shape under asval with capture=all whose JSON report must hold no error or warning.
docs/performance.md ("Heavy-refit frames") has the commands and figures.
"""

import argparse
import datetime
import json
import os
import re
import sys
from concurrent.futures import ThreadPoolExecutor
from typing import Dict, List, Tuple

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "overhead"))
sys.path.insert(0, HERE)

import overhead_env  # noqa: E402
import overhead_machine  # noqa: E402
import refit_table  # noqa: E402
from refit_runs import Case, RunError, report, run_callgrind, run_frames, valgrind  # noqa: E402

REPO = os.path.dirname(os.path.dirname(HERE))
Config = overhead_env.Config


def parse_args(argv: List[str]) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build", default=os.path.join(REPO, "build"), help="build directory (default: build/)")
    p.add_argument("--layer-dir", help="folder of asval's manifest and library (default: BUILD/layer)")
    p.add_argument("--structures", help="comma-separated N (default 1,10,100,1000; --callgrind: 100)")
    p.add_argument("--triangles", type=int, help="triangles per structure (default 1024; --callgrind: 256)")
    p.add_argument("--shapes", help="calls, one-call or both, comma-separated (default both; --callgrind: calls)")
    p.add_argument("--frames", type=int, help="measured frames per run (default 100; --callgrind: 3)")
    p.add_argument("--warmup", type=int, default=2, help="refit frames before the measured ones (default 2)")
    p.add_argument("--rounds", type=int, default=3, help="interleaved rounds (default 3)")
    p.add_argument("--configs", help="comma-separated subset of: none, asval, asval-capture-off, khronos")
    p.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1),
                   help="callgrind runs at once (default: 2 or the core count); timed runs are never parallel")
    p.add_argument("--json", help="write the results here")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--callgrind", action="store_true", help="instructions per frame instead of wall time")
    mode.add_argument("--smoke", action="store_true", help="CI's quick mode, then asval's report must be clean")
    args = p.parse_args(argv)
    if args.smoke:
        defaults = {"structures": "1,10", "triangles": 64, "shapes": "calls,one-call", "frames": 3}
        args.rounds, args.warmup = 1, 1
    elif args.callgrind:
        defaults = {"structures": "100", "triangles": 256, "shapes": "calls", "frames": 3}
    else:
        defaults = {"structures": "1,10,100,1000", "triangles": 1024, "shapes": "calls,one-call", "frames": 100}
    for key, value in defaults.items():
        if getattr(args, key) is None:
            setattr(args, key, value)
    return args


def configurations(args: argparse.Namespace) -> List[Config]:
    asval = overhead_env.ASVAL
    configs = [Config("none", {}),
               Config("asval", {"VK_INSTANCE_LAYERS": asval}),  # defaults: capture=updates, capture_method=auto
               Config("asval-capture-off", {"VK_INSTANCE_LAYERS": asval, "VK_ASVAL_AS_VALIDATION_CAPTURE": "off"})]
    khronos_manifest = os.path.join(overhead_env.SYSTEM_LAYER_DIR, "VkLayer_khronos_validation.json")
    if args.callgrind:
        pass  # the issue's target compares asval with itself
    elif os.path.exists(khronos_manifest):
        configs.append(Config("khronos", {"VK_INSTANCE_LAYERS": overhead_env.KHRONOS}))
    else:
        print(f"run_refit: {khronos_manifest} not found: no Khronos row", file=sys.stderr)
    if args.configs:
        wanted = [c.strip() for c in args.configs.split(",") if c.strip()]
        unknown = [w for w in wanted if w not in [c.name for c in configs]]
        if unknown:
            raise SystemExit(f"unknown or unavailable configuration(s): {', '.join(unknown)}")
        configs = [c for c in configs if c.name in wanted]
    return configs


def cases(args: argparse.Namespace) -> List[Case]:
    shapes = [s.strip() for s in args.shapes.split(",") if s.strip()]
    if any(s not in ("calls", "one-call") for s in shapes):
        raise SystemExit("--shapes: calls, one-call")
    return [Case(int(n), args.triangles, s) for n in args.structures.split(",") for s in shapes]


def program(args: argparse.Namespace) -> str:
    path = os.path.join(args.build, "bench", "refit", "refit_frames")
    if not os.path.exists(path):
        raise SystemExit(f"{path} not found: build the refit_frames target")
    return path


def measure_frames(args, all_cases, configs, base_env) -> Tuple[refit_table.Samples, Dict[Tuple[str, str], int], str]:
    samples: refit_table.Samples = {}
    notes: Dict[Tuple[str, str], int] = {}
    driver = ""
    for r in range(args.rounds):
        for case in all_cases:
            for config in configs:  # interleaved: a slow moment of the machine hits every configuration
                result = run_frames(case.argv(program(args), args.frames, args.warmup),
                                    overhead_env.environment(base_env, config), config.name == "khronos")
                for metric in refit_table.METRICS:
                    samples.setdefault((case.name, config.name, metric), []).append(getattr(result, metric))
                if result.messages:
                    notes[(case.name, config.name)] = result.messages
                driver = driver or result.device or ""
        print(f"round {r + 1}/{args.rounds} done", file=sys.stderr, flush=True)
    return samples, notes, driver


def measure_callgrind(args, all_cases, configs, base_env) -> Dict[Tuple[str, str], float]:
    if not valgrind():
        raise SystemExit("--callgrind: valgrind is not installed")
    jobs = [(case, config) for case in all_cases for config in configs]

    def one(job):
        case, config = job
        return run_callgrind(case.argv(program(args), args.frames, args.warmup),
                             overhead_env.environment(base_env, config), args.frames)

    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        results = list(pool.map(one, jobs))
    return {(case.name, config.name): ir for (case, config), ir in zip(jobs, results)}


def check_valid(args, all_cases, base_env) -> int:
    """asval with capture=all (every build's inputs captured and judged) on the largest case of each shape: the
    benchmark is a valid program, so the report holds no error and no warning; and its capture summary shows that
    updates were judged on captured bytes and that no input a rule needed went uncaptured (else the check would
    be vacuous)."""
    config = Config("asval-capture-all", {"VK_INSTANCE_LAYERS": overhead_env.ASVAL,
                                          "VK_ASVAL_AS_VALIDATION_CAPTURE": "all"})
    largest = {}
    for case in all_cases:
        if case.shape not in largest or case.structures > largest[case.shape].structures:
            largest[case.shape] = case
    failed = 0
    for case in largest.values():
        result = report(case.argv(program(args), args.frames, args.warmup), overhead_env.environment(base_env, config))
        for f in result.findings[:5]:
            print(f"  {f.get('severity')} {f.get('vuid')}: {f.get('message', '')[:200]}")
        print(f"validity, {case.name}, asval capture=all: {len(result.findings)} error(s) or warning(s) in its report")
        failed += bool(result.findings)
        message = (result.summary or {}).get("message", "")
        skipped = sum((result.summary or {}).get("capture_skipped", {}).values())
        print(f"  capture summary: {message or 'none'}")
        if not re.search(r"[1-9][0-9]* updates judged", message) or skipped:
            print("  the capture judged no update, or skipped an input a rule needed: the check proves nothing")
            failed += 1
    return failed


def write_json(path, args, argv, configs, driver, samples=None, notes=None, ir=None) -> None:
    result = {
        "machine": overhead_machine.machine(args.build, overhead_env.SYSTEM_LAYER_DIR, driver),
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "command": " ".join(["bench/refit/run_refit.py"] + argv),
        "rounds": args.rounds, "frames": args.frames, "warmup": args.warmup,
        "configs": [c.name for c in configs],
    }
    if samples is not None:
        result["frames_ms"] = [{"case": case, "config": config, "metric": metric, "rounds": values,
                                "median": refit_table.median(samples, case, config, metric)}
                               for (case, config, metric), values in samples.items()]
        result["messages"] = [{"case": c, "config": k, "count": n} for (c, k), n in (notes or {}).items()]
    if ir is not None:
        result["callgrind_ir_per_frame"] = [{"case": c, "config": k, "ir": v} for (c, k), v in ir.items()]
    with open(path, "w") as f:
        json.dump(result, f, indent=2)
        f.write("\n")
    print(f"wrote {path}")


def main(argv: List[str]) -> int:
    args = parse_args(argv)
    args.build = os.path.abspath(args.build)
    args.layer_dir = os.path.abspath(args.layer_dir or os.path.join(args.build, "layer"))
    base_env = overhead_env.base_environment(args.build, args.layer_dir)
    configs = configurations(args)
    all_cases = cases(args)
    try:
        if args.callgrind:
            ir = measure_callgrind(args, all_cases, configs, base_env)
            print(f"instructions per measured frame (callgrind, all threads, {args.frames} frames):")
            refit_table.print_callgrind(ir, [c.name for c in all_cases])
            if args.json:
                write_json(args.json, args, argv, configs, "", ir=ir)
            return 0
        samples, notes, driver = measure_frames(args, all_cases, configs, base_env)
        print(f"device: {driver}; medians of {args.rounds} interleaved round(s) of {args.frames} frame(s), "
              "per-frame means")
        refit_table.print_frames(samples, [c.name for c in all_cases], [c.name for c in configs])
        if not args.smoke:
            structures = sorted({c.structures for c in all_cases})
            refit_table.print_summary(samples, structures, args.triangles, [c.name for c in configs])
        for (case, config), count in notes.items():
            print(f"note: {case}, {config}: the layer reported {count} message(s) in a run (a valid program: "
                  "false positives; its times include reporting them)")
        if args.json:
            write_json(args.json, args, argv, configs, driver, samples, notes)
        if args.smoke and check_valid(args, all_cases, base_env):
            print("FAIL: asval reported findings on the refit benchmark, a valid program")
            return 1
    except RunError as e:
        print(f"run_refit: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
