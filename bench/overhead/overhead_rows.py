"""The benchmark's rows: which program measures which call, with how many calls (full run and --quick)."""

from dataclasses import dataclass
from typing import List, Optional


@dataclass(frozen=True)
class Row:
    name: str          # "build 1x16": the row's name in the JSON and the tables
    kind: str          # record | submit | buffer | frame
    program: str       # path relative to the build directory
    args: List[str]    # program arguments; "{n}" is replaced by the number of measured calls
    calls: int         # measured calls in a full run
    quick_calls: int   # with --quick (CI)
    callgrind: bool = True  # False: too slow under valgrind (the scene); ir_per_call is null

    def argv(self, build_dir: str, quick: bool) -> List[str]:
        n = self.quick_calls if quick else self.calls
        return [f"{build_dir}/{self.program}"] + [a.replace("{n}", str(n)) for a in self.args]

    def measured_calls(self, quick: bool) -> int:
        return self.quick_calls if quick else self.calls


def _build(infos: int, geometries: int, calls: int, quick_calls: int) -> Row:
    # Every info with its own scratch, vertex buffer and geometry arrays (own-inputs), as an app building many
    # meshes does: the layer cannot take the shortcuts a shared array allows.
    return Row(f"build {infos}x{geometries}", "record", "bench/overhead/record_builds",
               ["{n}", str(infos), str(geometries), "own-inputs"], calls, quick_calls)


# Calls per row are chosen so that a full run's measured loop takes about 0.1 s or more without a layer on
# lavapipe, and a quick one stays short under callgrind.
ROWS: List[Row] = [
    _build(1, 1, 5000, 500),
    _build(1, 16, 1000, 100),
    _build(1, 256, 100, 20),
    _build(16, 1, 500, 50),
    _build(16, 16, 100, 10),
    _build(16, 256, 10, 3),
    Row("submit 1000 build+update", "submit", "bench/overhead/submit_history", ["build-update", "1000", "{n}"], 20, 3),
    Row("submit 1000 updates", "submit", "bench/overhead/submit_history", ["update", "1000", "{n}"], 20, 3),
    # 100 ray-query dispatches over a TLAS of 10,000 instances (issue 29: judged per dispatch, not per instance).
    Row("submit 100 ray queries", "submit", "bench/overhead/submit_traces", ["{n}", "100", "10000"], 20, 3),
    Row("buffer cycle", "buffer", "bench/overhead/buffer_cycle", ["{n}"], 5000, 500),
    # The sample scene at 128x128 (a lavapipe frame is ~14 ms); frame 0 (the builds) is not counted.
    Row("frame dynamic", "frame", "examples/scene/asval_scene", ["--frames", "{n}", "--size", "128x128"], 31, 6,
        callgrind=False),
    Row("frame static", "frame", "examples/scene/asval_scene", ["--static", "--frames", "{n}", "--size", "128x128"],
        31, 6, callgrind=False),
]


def select(names: Optional[str]) -> List[Row]:
    """The rows named in a comma-separated list (all when None); an unknown name is an error."""
    if not names:
        return list(ROWS)
    by_name = {r.name: r for r in ROWS}
    wanted = [n.strip() for n in names.split(",") if n.strip()]
    unknown = [n for n in wanted if n not in by_name]
    if unknown:
        raise SystemExit("unknown row(s): %s; rows: %s" % (", ".join(unknown), ", ".join(by_name)))
    return [by_name[n] for n in wanted]
