"""The refit benchmark's tables: per case and configuration the medians over rounds of each per-frame figure,
with frame and GPU time as ratios against no layer; the issue's summary (asval's ratios by N and shape); and
the callgrind mode's added instructions."""

import statistics
from typing import Dict, List, Optional, Sequence, Tuple

METRICS = ("record_ms", "submit_wait_ms", "gpu_ms", "frame_ms")

# samples[(case name, config name, metric)] = one value per round (None: no timestamps).
Samples = Dict[Tuple[str, str, str], List[Optional[float]]]


def median(samples: Samples, case: str, config: str, metric: str) -> Optional[float]:
    values = [v for v in samples.get((case, config, metric), []) if v is not None]
    return statistics.median(values) if values else None


def ratio(samples: Samples, case: str, config: str, metric: str) -> Optional[float]:
    mine, base = median(samples, case, config, metric), median(samples, case, "none", metric)
    if mine is None or not base:
        return None
    return mine / base


def _ms(value: Optional[float]) -> str:
    if value is None:
        return "-"
    return f"{value:.3f}" if value < 10 else f"{value:.1f}"


def _x(value: Optional[float]) -> str:
    return "-" if value is None else f"{value:.2f}x"


def _print(lines: List[List[str]], left: int) -> None:
    widths = [max(len(line[i]) for line in lines) for i in range(len(lines[0]))]
    for i, line in enumerate(lines):
        print("| " + " | ".join(cell.ljust(widths[k]) if k < left else cell.rjust(widths[k])
                                for k, cell in enumerate(line)) + " |")
        if i == 0:
            print("|" + "|".join("-" * (w + 2) for w in widths) + "|")


def print_frames(samples: Samples, cases: Sequence[str], configs: Sequence[str]) -> None:
    lines = [["case", "config", "record ms", "submit+wait ms", "GPU ms", "frame ms", "frame / none", "GPU / none"]]
    for case in cases:
        for config in configs:
            lines.append([case, config] + [_ms(median(samples, case, config, m)) for m in METRICS] +
                         ["" if config == "none" else _x(ratio(samples, case, config, m))
                          for m in ("frame_ms", "gpu_ms")])
    _print(lines, 2)


def print_summary(samples: Samples, structures: Sequence[int], triangles: int, configs: Sequence[str]) -> None:
    """The issue's table: per configuration and N, frame and GPU time against no layer, N calls and one call."""
    for config in configs:
        if config == "none":
            continue
        print(f"\n{config} against no layer ({triangles} triangles per structure):")
        lines = [["refits per frame", "N calls: frame", "GPU", "one call: frame", "GPU"]]
        for n in structures:
            row = [f"{n:,}"]
            for shape in ("calls", "one-call"):
                case = f"{n}x{triangles} {shape}"
                row += [_x(ratio(samples, case, config, "frame_ms")), _x(ratio(samples, case, config, "gpu_ms"))]
            lines.append(row)
        _print(lines, 1)


def print_callgrind(ir: Dict[Tuple[str, str], float], cases: Sequence[str]) -> None:
    lines = [["case", "no layer Ir/frame", "asval (default) +Ir", "capture off +Ir", "default / capture off"]]
    for case in cases:
        base = ir[(case, "none")]
        default, off = ir[(case, "asval")] - base, ir[(case, "asval-capture-off")] - base
        lines.append([case, f"{base:,.0f}", f"{default:+,.0f}", f"{off:+,.0f}",
                      f"{default / off:.2f}" if off > 0 else "-"])
    _print(lines, 1)
