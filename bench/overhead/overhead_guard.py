"""The CI guard: asval's added instructions per call (asval minus no layer, callgrind, --quick call counts) on
a few cheap rows, against a committed baseline per system. Growth above the threshold fails; refreshing the
baseline is an explicit step (--update-baseline, reviewed like any other change)."""

import datetime
import json
import os
from typing import Dict, Optional

GUARD_ROWS = ["build 1x1", "build 1x256", "submit 1000 build+update", "buffer cycle"]
THRESHOLD = 0.10
SKIP = 77  # ctest's SKIP_RETURN_CODE for this test


def load(path: str) -> Dict:
    if not os.path.exists(path):
        return {"threshold": THRESHOLD, "systems": {}}
    with open(path) as f:
        return json.load(f)


def entry_for(baseline: Dict, key: str, build_type: str) -> (Optional[Dict], str):
    """The system's entry, or None and why not."""
    entry = baseline.get("systems", {}).get(key)
    if entry is None:
        known = ", ".join(sorted(baseline.get("systems", {}))) or "none"
        return None, f"no baseline for system {key!r} (baselines exist for: {known})"
    if entry.get("build_type") != build_type:
        return None, (f"the baseline for {key!r} was measured on a {entry.get('build_type')} build, this build is "
                      f"{build_type or 'of no type'}")
    return entry, ""


def out_of_bounds(entry: Dict, row: str, measured: float, threshold: float) -> bool:
    """Whether a row moved more than the threshold either way (a drop that large is as unexpected)."""
    base = entry["rows"].get(row)
    if base is None or base["added_ir_per_call"] <= 0:
        return False
    return abs(measured / base["added_ir_per_call"] - 1) > threshold


def check(entry: Dict, added: Dict[str, float], calls: Dict[str, int], threshold: float) -> int:
    """Prints one line per row; returns 0, or 1 when a row grew more than the threshold."""
    failed = 0
    print(f"{'row':<26} {'baseline':>12} {'measured':>12} {'growth':>8}")
    for row, measured in added.items():
        base = entry["rows"].get(row)
        if base is None:
            print(f"{row:<26} {'-':>12} {measured:>12.0f}        (no baseline for this row)")
            continue
        if base.get("calls") != calls[row]:
            print(f"{row:<26} baseline measured with {base.get('calls')} calls, now {calls[row]}: not comparable")
            failed = 1
            continue
        reference = base["added_ir_per_call"]
        growth = measured / reference - 1 if reference > 0 else float("inf")
        verdict = "FAIL" if growth > threshold else "ok"
        print(f"{row:<26} {reference:>12.0f} {measured:>12.0f} {growth * 100:>+7.1f}%  {verdict}")
        if growth > threshold:
            failed = 1
        elif growth < -threshold:
            print(f"{'':<26} (faster by more than {threshold * 100:.0f}%: refresh the baseline with "
                  "--update-baseline to keep the gain)")
    if failed:
        print(f"asval's added instructions grew more than {threshold * 100:.0f}% on a row above. If the growth is "
              "intended, refresh the baseline with run_overhead.py --update-baseline (docs/performance.md).")
    return failed


def update(path: str, baseline: Dict, key: str, build_type: str, driver: str, added: Dict[str, float],
           calls: Dict[str, int]) -> None:
    baseline["about"] = ("asval's added instructions per call (callgrind, the calling thread, asval at default "
                         "settings minus no layer, run_overhead.py --quick call counts), per system and build type. "
                         "Checked by run_overhead.py --guard (ctest overhead_guard); rewritten only by "
                         "run_overhead.py --update-baseline (docs/performance.md).")
    baseline.setdefault("threshold", THRESHOLD)
    baseline.setdefault("systems", {})[key] = {
        "build_type": build_type,
        "driver": driver,
        "updated": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d"),
        "rows": {row: {"calls": calls[row], "added_ir_per_call": round(value, 1)} for row, value in added.items()},
    }
    with open(path, "w") as f:
        json.dump(baseline, f, indent=2, sort_keys=True)
        f.write("\n")
