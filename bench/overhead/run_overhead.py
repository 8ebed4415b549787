#!/usr/bin/env python3
"""run_overhead.py: what validation layers cost per call, asval's and the Khronos layer's, on the calls an app
makes: recording builds, submitting builds and updates, creating buffers, and the sample scene's frames.

Every row (overhead_rows.py) runs under every configuration: none, asval (default settings), asval with
capture off and with capture=all, the installed Khronos layer with default settings, and any --config. Wall
time: configurations interleaved round-robin, --rounds rounds, min and median. --callgrind: instructions per
call of the measured calls (the calling thread's), one run per row and configuration. Writes --json and prints
a table with each configuration's added cost against none and, for asval's, the ratio to the Khronos layer's.

--guard FILE / --update-baseline FILE: the CI regression guard (overhead_guard.py); exit 0 passed, 1 a row grew
more than the threshold, 77 no baseline for this system (skipped). docs/performance.md has the commands.
"""

import argparse
import datetime
import json
import os
import statistics
import sys
from concurrent.futures import ThreadPoolExecutor
from typing import Dict, List, Optional, Tuple

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import overhead_env  # noqa: E402
import overhead_guard  # noqa: E402
import overhead_machine  # noqa: E402
import overhead_rows  # noqa: E402
from overhead_measure import RunError, run_callgrind, run_wall, valgrind  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def parse_args(argv: List[str]) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build", default=os.path.join(REPO, "build"), help="build directory (default: build/)")
    p.add_argument("--layer-dir", help="folder of asval's manifest and library (default: BUILD/layer), e.g. a "
                   "layer built from another commit, measured with this build's programs")
    p.add_argument("--rounds", type=int, default=5, help="wall-time rounds (default 5; 0: none)")
    p.add_argument("--callgrind", action="store_true", help="also count instructions per call under callgrind")
    p.add_argument("--rows", help="comma-separated rows (default: all): " +
                   ", ".join(r.name for r in overhead_rows.ROWS))
    p.add_argument("--configs", help="comma-separated subset of the configurations (default: all)")
    p.add_argument("--config", action="append", default=[], metavar="NAME:ENV=VALUE,...",
                   help="an extra configuration (asval enabled unless VK_INSTANCE_LAYERS is given)")
    p.add_argument("--quick", action="store_true", help="few calls per row (CI)")
    p.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1),
                   help="callgrind runs at once (default: 2 or the core count); wall runs are never parallel")
    p.add_argument("--json", help="write the results here")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--guard", metavar="BASELINE", help="check asval's added instructions against BASELINE")
    g.add_argument("--update-baseline", metavar="BASELINE", help="rewrite this system's entry of BASELINE")
    return p.parse_args(argv)


def configurations(args: argparse.Namespace) -> List[overhead_env.Config]:
    configs = overhead_env.default_configs() + [overhead_env.parse_config(c) for c in args.config]
    if args.configs:
        wanted = [c.strip() for c in args.configs.split(",") if c.strip()]
        names = [c.name for c in configs]
        unknown = [w for w in wanted if w not in names]
        if unknown:
            raise SystemExit(f"unknown configuration(s): {', '.join(unknown)}; known: {', '.join(names)}")
        configs = [c for c in configs if c.name in wanted]
    return configs


def measure_wall(rows, configs, args, base_env, notes) -> Tuple[Dict[Tuple[str, str], List[float]], Optional[str]]:
    samples: Dict[Tuple[str, str], List[float]] = {}
    driver = None
    for r in range(args.rounds):
        for row in rows:
            for config in configs:  # interleaved: a slow moment of the machine hits every configuration
                result = run_wall(row, row.argv(args.build, args.quick), overhead_env.environment(base_env, config),
                                  overhead_env.tolerates_messages(config))
                samples.setdefault((row.name, config.name), []).append(result.ns_per_call)
                driver = driver or result.driver
                if result.messages:
                    notes[(row.name, config.name)] = result.messages
        print(f"wall round {r + 1}/{args.rounds} done", file=sys.stderr, flush=True)
    return samples, driver


def measure_callgrind(rows, configs, args, base_env) -> Dict[Tuple[str, str], float]:
    jobs = [(row, config) for row in rows if row.callgrind for config in configs]

    def one(job):
        row, config = job

        def run():
            return run_callgrind(row, row.argv(args.build, args.quick), overhead_env.environment(base_env, config),
                                 row.measured_calls(args.quick), overhead_env.tolerates_messages(config))

        try:
            return run()
        except RunError as e:
            # Once, in eleven guard runs, an asval run counted as if no layer were loaded (the active-layer check
            # did not exist yet): a failed run is tried once more, and fails for good the second time.
            print(f"run_overhead: {row.name}, {config.name}: {e}\nrun_overhead: trying once more", file=sys.stderr)
            return run()

    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        results = list(pool.map(one, jobs))
    return {(row.name, config.name): ir for (row, config), ir in zip(jobs, results)}


def fmt(value: Optional[float]) -> str:
    if value is None:
        return "-"
    return f"{value:,.0f}" if abs(value) >= 100 else f"{value:,.1f}"


def print_table(rows, configs, wall, ir) -> None:
    """One line per row and configuration; added costs against none and, for configurations other than none
    and khronos, their added cost as a share of the Khronos layer's (both from this run)."""
    header = ["row", "config", "wall ns median", "wall ns min", "+wall vs none", "Ir/call", "+Ir vs none",
              "+Ir / khronos +Ir", "+wall / khronos +wall"]
    lines = [header]
    for row in rows:
        def med(c):
            s = wall.get((row.name, c))
            return statistics.median(s) if s else None

        def added(values, c):
            if values(c) is None or values("none") is None:
                return None
            return values(c) - values("none")

        def ir_of(c):
            return ir.get((row.name, c))

        def ratio(values, c):
            mine, theirs = added(values, c), added(values, "khronos")
            if c in ("none", "khronos") or mine is None or theirs is None or theirs <= 0:
                return "-"
            return f"{mine / theirs:.2f}"

        for config in configs:
            c = config.name
            s = wall.get((row.name, c))
            lines.append([row.name, c, fmt(med(c)), fmt(min(s) if s else None),
                          "-" if c == "none" else fmt(added(med, c)), fmt(ir_of(c)),
                          "-" if c == "none" else fmt(added(ir_of, c)), ratio(ir_of, c), ratio(med, c)])
    widths = [max(len(line[i]) for line in lines) for i in range(len(header))]
    for i, line in enumerate(lines):
        print("| " + " | ".join(cell.ljust(widths[k]) if k < 2 else cell.rjust(widths[k])
                                for k, cell in enumerate(line)) + " |")
        if i == 0:
            print("|" + "|".join("-" * (w + 2) for w in widths) + "|")


def run_guard(args: argparse.Namespace, base_env: Dict[str, str]) -> int:
    path = args.guard or args.update_baseline
    if not valgrind():
        print("overhead guard: valgrind is not installed (scripts/setup.sh installs it): skipped")
        return overhead_guard.SKIP
    key = overhead_machine.system_key(args.build)
    build_type = overhead_machine.build_type(args.build)
    baseline = overhead_guard.load(path)
    if args.guard:
        entry, why = overhead_guard.entry_for(baseline, key, build_type)
        if entry is None:
            print(f"overhead guard: {why}: skipped. Record one with run_overhead.py --update-baseline {path}")
            return overhead_guard.SKIP
    args.quick = True
    rows = overhead_rows.select(",".join(overhead_guard.GUARD_ROWS))
    configs = [c for c in overhead_env.default_configs() if c.name in ("none", "asval")]
    ir = measure_callgrind(rows, configs, args, base_env)
    added = {row.name: ir[(row.name, "asval")] - ir[(row.name, "none")] for row in rows}
    calls = {row.name: row.measured_calls(True) for row in rows}
    if args.guard:
        # A row out of bounds is measured again before it fails: the counts repeat run to run (docs/performance.md),
        # so a real growth shows twice, and a one-off disturbance does not fail CI.
        threshold = baseline.get("threshold", overhead_guard.THRESHOLD)
        suspect = [row for row in rows if overhead_guard.out_of_bounds(entry, row.name, added[row.name], threshold)]
        if suspect:
            print("overhead guard: measuring again: " + ", ".join(row.name for row in suspect))
            again = measure_callgrind(suspect, configs, args, base_env)
            for row in suspect:
                added[row.name] = again[(row.name, "asval")] - again[(row.name, "none")]
    print(f"overhead guard, system {key} ({build_type}): asval's added instructions per call (callgrind, "
          "calling thread, asval minus no layer)")
    if args.update_baseline:
        driver = run_wall(rows[0], rows[0].argv(args.build, True), base_env).driver or "unknown"
        overhead_guard.update(path, baseline, key, build_type, driver, added, calls)
        for row, value in added.items():
            print(f"{row:<26} {value:>12.0f}")
        print(f"wrote the {key} entry of {path}")
        return 0
    return overhead_guard.check(entry, added, calls, baseline.get("threshold", overhead_guard.THRESHOLD))


def main(argv: List[str]) -> int:
    args = parse_args(argv)
    args.build = os.path.abspath(args.build)
    args.layer_dir = os.path.abspath(args.layer_dir or os.path.join(args.build, "layer"))
    base_env = overhead_env.base_environment(args.build, args.layer_dir)
    try:
        if args.guard or args.update_baseline:
            return run_guard(args, base_env)
        rows = overhead_rows.select(args.rows)
        configs = configurations(args)
        if args.callgrind and not valgrind():
            raise SystemExit("--callgrind: valgrind is not installed")
        notes: Dict[Tuple[str, str], int] = {}
        wall, driver = measure_wall(rows, configs, args, base_env, notes)
        ir = measure_callgrind(rows, configs, args, base_env) if args.callgrind else {}
    except RunError as e:
        print(f"run_overhead: {e}", file=sys.stderr)
        return 1
    print_table(rows, configs, wall, ir)
    for (row, config), count in notes.items():
        print(f"note: {row}, {config}: the layers reported {count} message(s) in a run (the Khronos layer's "
              "false positives; its cost includes reporting them)")
    if args.json:
        result = {
            "machine": overhead_machine.machine(args.build, overhead_env.SYSTEM_LAYER_DIR, driver),
            "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
            "command": " ".join(["bench/overhead/run_overhead.py"] + argv),
            "rounds": args.rounds,
            "rows": [{"row": row.name, "kind": row.kind, "config": c.name,
                      "wall_ns_min": min(wall[(row.name, c.name)]) if (row.name, c.name) in wall else None,
                      "wall_ns_median": (statistics.median(wall[(row.name, c.name)])
                                         if (row.name, c.name) in wall else None),
                      "ir_per_call": ir.get((row.name, c.name))}
                     for row in rows for c in configs],
        }
        with open(args.json, "w") as f:
            json.dump(result, f, indent=2)
            f.write("\n")
        print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
