"""Runs refit_frames once under one configuration and reads what it printed: the per-frame times, or (under
callgrind) the instructions of the measured frames over all threads, or (a validity run) asval's JSON report."""

import json
import os
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from typing import Dict, List, Optional

from overhead_measure import RunError, _check_layers, _describe, valgrind  # noqa: F401 (re-exported)

REPORT_ENV = "VK_ASVAL_AS_VALIDATION_REPORT_FILE"
REPORT_FLAGS_ENV = "VK_ASVAL_AS_VALIDATION_REPORT_FLAGS"

_RESULT = re.compile(r"^result: record_ms=([0-9.]+) submit_wait_ms=([0-9.]+) gpu_ms=([0-9.]+|-) frame_ms=([0-9.]+)$",
                     re.M)
_MESSAGES = re.compile(r"^validation messages: (\d+) error\(s\), (\d+) warning\(s\)$", re.M)
_DEVICE = re.compile(r"^device: (.*; driver: .*)$", re.M)


@dataclass(frozen=True)
class Case:
    """One frame shape: N structures of T triangles, refit as N calls or as one call."""
    structures: int
    triangles: int
    shape: str  # "calls" or "one-call"

    @property
    def name(self) -> str:
        return f"{self.structures}x{self.triangles} {self.shape}"

    def argv(self, program: str, frames: int, warmup: int) -> List[str]:
        return [program, "--structures", str(self.structures), "--triangles", str(self.triangles),
                "--shape", self.shape, "--frames", str(frames), "--warmup", str(warmup)]


@dataclass
class FrameResult:
    record_ms: float
    submit_wait_ms: float
    gpu_ms: Optional[float]  # None: the queue has no timestamps
    frame_ms: float
    messages: int  # errors + warnings the layers reported (0 unless tolerated)
    device: Optional[str]


def _messages(argv: List[str], proc: subprocess.CompletedProcess, tolerate: bool) -> int:
    """refit_frames is a valid program: a layer that reports something fails the run unless tolerated (the
    Khronos layer's row, whose release may report false positives: its count is noted, not hidden)."""
    m = _MESSAGES.search(proc.stdout)
    if not m:
        raise RunError(_describe(argv, proc))
    count = int(m.group(1)) + int(m.group(2))
    if count and not tolerate:
        tail = (proc.stdout + proc.stderr).strip().splitlines()[-8:]
        raise RunError(f"{' '.join(argv)}: the layers reported {m.group(1)} error(s), {m.group(2)} warning(s) on a "
                       "valid program:\n  " + "\n  ".join(tail))
    return count


def _run(argv: List[str], env: Dict[str, str], timeout: float) -> subprocess.CompletedProcess:
    # The private HOME as working directory: asval reads a vk_layer_settings.txt there when no other settings
    # file is found, and the caller's (the repository root has one) must not count.
    proc = subprocess.run(argv, env=env, cwd=env["HOME"], capture_output=True, text=True, timeout=timeout)
    if proc.returncode not in (0, 3):  # 3: a layer reported something; _messages decides
        raise RunError(_describe(argv, proc))
    return proc


def run_frames(argv: List[str], env: Dict[str, str], tolerate: bool, timeout: float = 1800) -> FrameResult:
    proc = _run(argv, env, timeout)
    messages = _messages(argv, proc, tolerate)
    _check_layers(argv, proc, env)
    m = _RESULT.search(proc.stdout)
    if not m:
        raise RunError(f"{' '.join(argv)}: no result line in its output")
    device = _DEVICE.search(proc.stdout)
    return FrameResult(float(m.group(1)), float(m.group(2)), None if m.group(3) == "-" else float(m.group(3)),
                       float(m.group(4)), messages, device.group(1) if device else None)


def _totals(path: str) -> int:
    with open(path) as f:
        for line in f:
            if line.startswith("totals:"):
                return int(line.split()[1])
    return 0


def run_callgrind(argv: List[str], env: Dict[str, str], frames: int, timeout: float = 3600) -> float:
    """Instructions per measured frame over all threads (--separate-threads=no): lavapipe builds on a queue
    thread of its own and asval judges the captured bytes when the work completes, so the calling thread alone
    would miss part of what the capture costs. refit_frames instruments only its measured frames."""
    out_dir = tempfile.mkdtemp(prefix="refit-cg-")
    try:
        out = os.path.join(out_dir, "cg")
        full = [valgrind() or "valgrind", "--tool=callgrind", "--instr-atstart=no", "--separate-threads=no",
                f"--callgrind-out-file={out}"] + argv
        proc = _run(full, env, timeout)
        _messages(full, proc, False)
        _check_layers(full, proc, env)
        total = _totals(out) if os.path.exists(out) else 0
        if total == 0:
            raise RunError(f"{' '.join(full)}: callgrind collected no instructions in the measured frames "
                           "(was refit_frames built without valgrind/callgrind.h?)")
        return total / frames
    finally:
        shutil.rmtree(out_dir, ignore_errors=True)


@dataclass
class Report:
    findings: List[dict]  # its errors and warnings
    summary: Optional[dict]  # the ASVAL-History-Summary notice: what the capture captured, judged and skipped


def report(argv: List[str], env: Dict[str, str], timeout: float = 600) -> Report:
    """Runs once with asval's JSON-lines report on, notices included (the summary shows that the capture ran),
    and returns its errors and warnings (a valid program has none) and its capture summary. The messenger's
    count must be zero too: refit_frames exits 3 otherwise."""
    with tempfile.TemporaryDirectory(prefix="refit-report-") as tmp:
        path = os.path.join(tmp, "report.jsonl")
        env = dict(env, **{REPORT_ENV: path, REPORT_FLAGS_ENV: "error,warn,info"})
        proc = _run(argv, env, timeout)
        _check_layers(argv, proc, env)
        lines = []
        if os.path.exists(path):
            with open(path) as f:
                lines = [json.loads(line) for line in f if line.strip()]
        findings = [line for line in lines if line.get("severity") in ("error", "warning")]
        if not findings and _messages(argv, proc, True):
            raise RunError(f"{' '.join(argv)}: the messenger received messages the report does not hold")
        summary = next((line for line in lines if line.get("vuid") == "ASVAL-History-Summary"), None)
        return Report(findings, summary)
