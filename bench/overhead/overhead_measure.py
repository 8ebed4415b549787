"""Runs one row's program under one configuration and reads what it printed: wall time per call, or (under
callgrind) the instructions of the measured calls."""

import glob
import os
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from typing import Dict, List, Optional

from overhead_rows import Row


class RunError(Exception):
    pass


@dataclass
class WallResult:
    ns_per_call: float
    driver: Optional[str]  # "deviceName; driver: driverName driverInfo", from the overhead programs
    messages: int  # errors and warnings the layers reported (0 unless tolerated, see _check_messages)


_NS = re.compile(r"^ns_per_call: ([0-9.]+) calls: (\d+)$", re.M)
_FPS = re.compile(r"frames 1\.\.\d+ \((?:refits|trace only)\) ([0-9.]+) fps")
_MESSAGES = re.compile(r"^validation messages: (\d+) error\(s\), (\d+) warning\(s\)$", re.M)
_DEVICE = re.compile(r"^device: (.*; driver: .*)$", re.M)
_LAYERS = re.compile(r"^layers:(.*)$", re.M)


def _check_layers(argv: List[str], proc: subprocess.CompletedProcess, env: Dict[str, str]) -> None:
    """The overhead programs print the layers the loader activated: a run with other layers than its
    configuration names measured something else. (The scene prints none; its rows are wall time only.)"""
    m = _LAYERS.search(proc.stdout)
    if not m:
        return
    active = [x for x in m.group(1).strip().split(",") if x]
    wanted = [x for x in env.get("VK_INSTANCE_LAYERS", "").split(":") if x]
    if active != wanted:
        raise RunError(f"{' '.join(argv)}: ran with layers {active or 'none'}, its configuration names "
                       f"{wanted or 'none'}")


def _describe(argv: List[str], proc: subprocess.CompletedProcess) -> str:
    tail = (proc.stdout + proc.stderr).strip().splitlines()[-8:]
    return f"{' '.join(argv)} exited with {proc.returncode}:\n  " + "\n  ".join(tail)


def _check_messages(argv: List[str], proc: subprocess.CompletedProcess, tolerate: bool) -> int:
    """The measured calls are valid: a layer that reports something is measuring its reporting path, so a
    report fails the run, unless tolerated (the Khronos layer 1.3.239 reports false errors on the scene: it
    checks updates against the build recorded last, not executed last). Returns errors + warnings."""
    m = _MESSAGES.search(proc.stdout)
    if not m:
        raise RunError(_describe(argv, proc))
    count = int(m.group(1)) + int(m.group(2))
    if count and not tolerate:
        tail = (proc.stdout + proc.stderr).strip().splitlines()[-8:]
        raise RunError(f"{' '.join(argv)}: the layers reported {m.group(1)} error(s), {m.group(2)} warning(s) "
                       f"on calls that are valid:\n  " + "\n  ".join(tail))
    return count


def _cwd(env: Dict[str, str]) -> str:
    """The private HOME: asval reads a vk_layer_settings.txt in the working directory when no other settings file
    is found, and the caller's (the repository root has one) must not count."""
    return env["HOME"]


def run_wall(row: Row, argv: List[str], env: Dict[str, str], tolerate: bool = False,
             timeout: float = 600) -> WallResult:
    proc = subprocess.run(argv, env=env, cwd=_cwd(env), capture_output=True, text=True, timeout=timeout)
    # The overhead programs exit with 3 when a layer reported something; _check_messages decides.
    if proc.returncode not in (0, 3):
        raise RunError(_describe(argv, proc))
    messages = _check_messages(argv, proc, tolerate)
    _check_layers(argv, proc, env)
    device = _DEVICE.search(proc.stdout)
    if row.kind == "frame":
        m = _FPS.search(proc.stdout)
        if not m:
            raise RunError(f"{' '.join(argv)}: no frame rate in its output")
        return WallResult(1e9 / float(m.group(1)), None, messages)
    m = _NS.search(proc.stdout)
    if not m:
        raise RunError(f"{' '.join(argv)}: no ns_per_call line in its output")
    return WallResult(float(m.group(1)), device.group(1) if device else None, messages)


def valgrind() -> Optional[str]:
    return shutil.which("valgrind")


def _totals(path: str) -> int:
    """The file's "totals:" line (its "summary:" line is written when the program starts, 0 with
    --instr-atstart=no)."""
    with open(path) as f:
        for line in f:
            if line.startswith("totals:"):
                return int(line.split()[1])
    return 0


def run_callgrind(row: Row, argv: List[str], env: Dict[str, str], calls: int, tolerate: bool = False,
                  timeout: float = 1800) -> float:
    """Instructions per measured call, of the calling thread only. The programs switch instrumentation on
    around the measured calls; the driver's own threads (lavapipe executes submissions on a thread of its own,
    which may or may not run inside the measured window) are counted apart by --separate-threads and left out,
    so that the figure repeats run to run."""
    out_dir = tempfile.mkdtemp(prefix="overhead-cg-")
    try:
        out = os.path.join(out_dir, "cg")
        full = [valgrind() or "valgrind", "--tool=callgrind", "--instr-atstart=no", "--separate-threads=yes",
                f"--callgrind-out-file={out}"] + argv
        proc = subprocess.run(full, env=env, cwd=_cwd(env), capture_output=True, text=True, timeout=timeout)
        if proc.returncode not in (0, 3):
            raise RunError(_describe(full, proc))
        _check_messages(full, proc, tolerate)
        _check_layers(full, proc, env)
        main_thread = [p for p in glob.glob(out + "-*") if p.endswith("-01")]
        total = _totals(main_thread[0]) if main_thread else 0
        if total == 0:
            raise RunError(f"{' '.join(full)}: callgrind collected no instructions in the measured calls "
                           "(was the program built without valgrind/callgrind.h?)")
        return total / calls
    finally:
        shutil.rmtree(out_dir, ignore_errors=True)
