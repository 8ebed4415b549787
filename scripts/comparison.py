#!/usr/bin/env python3
"""Writes docs/comparison.md (and its plot): what asval catches and what it costs, beside the Khronos layer.

Runs, on this machine, in one go:
  1. the accuracy corpus (tests/corpus/run_corpus.py) under the Khronos layer and under asval at each capture
     setting and with each rule family switched off;
  2. the overhead benchmark (bench/overhead/run_overhead.py) under the same configurations (all rows for the
     main ones, the cheap rows and the scene for the others);
then writes the feature table by family, the overhead table and the run time against error view (a table and
docs/comparison.png). Every figure in the document comes from these two runs; the document says where it ran.

Usage: scripts/comparison.py [--build build] [--out docs/comparison.md] [--rounds 5]
         [--corpus-json F] [--overhead-json F]   reuse earlier runs instead of running them (their JSON is kept
                                                  beside the document as comparison-corpus.json and
                                                  comparison-overhead.json)
Needs python3-matplotlib for the plot (Debian's; the script re-runs itself under /usr/bin/python3 when the python3
on PATH lacks it).
"""
import argparse
import datetime
import glob
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FAMILIES = ["features", "handles", "structure", "alignment", "addresses", "aliasing", "host", "copies", "history"]
ENV_PREFIX = "VK_ASVAL_AS_VALIDATION_"
KHRONOS_SO = "/usr/lib/x86_64-linux-gnu/libVkLayer_khronos_validation.so"
# The configurations of the run time against error view: capture settings, then each family switched off.
CAPTURE_CONFIGS = {
    "asval-capture-off": ENV_PREFIX + "CAPTURE=off",
    "asval-capture-all": ENV_PREFIX + "CAPTURE=all",
}
FAMILY_CONFIGS = {"asval-no-" + f: ENV_PREFIX + "ENABLED_CHECKS=" + ",".join(x for x in FAMILIES if x != f)
                  for f in FAMILIES}
# The rows measured for every configuration of the view (the others run only for none, asval and khronos).
VIEW_ROWS = ["build 1x1", "submit 1000 build+update", "frame dynamic"]


def ensure_matplotlib():
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        if sys.executable != "/usr/bin/python3" and os.path.exists("/usr/bin/python3"):
            os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
        sys.exit("comparison.py: needs python3-matplotlib (apt-get install python3-matplotlib)")


def sh(cmd):
    return subprocess.run(cmd, shell=True, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                          universal_newlines=True).stdout.strip()


def asval_commit():
    return sh("git -C %s rev-parse --short HEAD" % ROOT)


def registry():
    """scripts/checks: every VUID of each family with its status."""
    vuids = {}
    for path in sorted(glob.glob(os.path.join(ROOT, "scripts", "checks", "*.json"))):
        with open(path) as f:
            for entry in json.load(f):
                vuids[entry["vuid"]] = entry
    return vuids


def khronos_named(vuids):
    """The registry's VUIDs (or an older name of theirs) that the Khronos layer's binary contains: an upper bound
    of what it checks, since a message id must be in the binary to be reported."""
    if not os.path.exists(KHRONOS_SO):
        return set()
    text = sh("strings %s | grep -o 'VUID-[A-Za-z0-9_]*-[A-Za-z0-9_]*-[0-9]*' | sort -u" % KHRONOS_SO)
    present = set(text.split())
    with open(os.path.join(ROOT, "scripts", "vuids_newer.json")) as f:
        aliases = json.load(f).get("aliases", {})
    return {v for v in vuids if present & {v, *aliases.get(v, [])}}


def run_corpus(build, out):
    configs = dict(CAPTURE_CONFIGS, **FAMILY_CONFIGS)
    cmd = [sys.executable, os.path.join(ROOT, "tests", "corpus", "run_corpus.py"),
           "--corpus", os.path.join(build, "tests", "corpus", "asval_corpus"),
           "--scene", os.path.join(build, "examples", "scene", "asval_scene"),
           "--layer-path", os.path.join(build, "layer"), "--json", out]
    for name, env in configs.items():
        cmd += ["--config", "%s:%s" % (name, env)]
    print("+ " + " ".join(cmd), flush=True)
    subprocess.run(cmd)  # exit 1 only says a verdict differs from the committed ones: the figures stand
    return " ".join(os.path.relpath(c, ROOT) if c.startswith(ROOT) else c for c in cmd[1:])


def run_overhead(build, out, rounds):
    script = os.path.join(ROOT, "bench", "overhead", "run_overhead.py")
    main = [sys.executable, script, "--build", build, "--callgrind", "--rounds", str(rounds), "--json", out]
    print("+ " + " ".join(main), flush=True)
    subprocess.run(main, check=True)
    # Each family switched off: the rows the view plots, against none measured again in the same run.
    view = [sys.executable, script, "--build", build, "--callgrind", "--rounds", str(rounds), "--json", out + ".view",
            "--rows", ",".join(VIEW_ROWS), "--configs", ",".join(["none"] + list(FAMILY_CONFIGS))]
    for name, env in FAMILY_CONFIGS.items():
        view += ["--config", "%s:%s" % (name, env)]
    print("+ " + " ".join(view), flush=True)
    subprocess.run(view, check=True)
    with open(out) as f:
        merged = json.load(f)
    with open(out + ".view") as f:
        extra = json.load(f)
    merge_family_rows(merged, extra)
    merged["command_view"] = extra.get("command")
    with open(out, "w") as f:
        json.dump(merged, f, indent=1)
    os.remove(out + ".view")
    return "%s; %s" % (" ".join(main[1:]), " ".join(view[1:]))


def merge_family_rows(merged, extra):
    """Adds the family-off rows of a second run to `merged`, each taken relative to its own run's none and stored
    as that ratio (wall) or difference (instructions) applied to the main run's none."""
    look = {(r["row"], r["config"]): r for r in extra["rows"]}
    main_none = {r["row"]: r for r in merged["rows"] if r["config"] == "none"}
    for r in extra["rows"]:
        if r["config"] == "none":
            continue
        base, ref = look.get((r["row"], "none")), main_none.get(r["row"])
        if base and ref and base["wall_ns_median"] and ref["wall_ns_median"]:
            scale = ref["wall_ns_median"] / base["wall_ns_median"]
            for key in ("wall_ns_min", "wall_ns_median"):
                r[key] = r[key] * scale
        if base and ref and r.get("ir_per_call") is not None and base.get("ir_per_call") is not None \
                and ref.get("ir_per_call") is not None:
            r["ir_per_call"] = r["ir_per_call"] - base["ir_per_call"] + ref["ir_per_call"]
        r["rescaled_to_main_none"] = True
        merged["rows"].append(r)


def md_table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(lines)


def corpus_counts(cases, config, family=None):
    sel = [c for c in cases if family in (None, c["family"]) and config in c["results"]]
    faults = [c for c in sel if c["expected"]]
    expected = sum(len(c["expected"]) for c in faults)
    detected = sum(len(c["results"][config]["detected"]) for c in faults)
    fps = sum(1 for c in sel if not c["expected"] and c["results"][config]["errors"])
    valid = len(sel) - len(faults)
    return detected, expected, fps, valid


def feature_table(vuids, named, cases):
    rows = []
    families = FAMILIES + sorted({c["family"] for c in cases} - set(FAMILIES))
    for family in families:
        entries = [e for e in vuids.values() if e["family"] == family]
        checked = [e["vuid"] for e in entries if e["status"] in ("checked", "partial")]
        full = sum(1 for e in entries if e["status"] == "checked")
        k_named = sum(1 for v in checked if v in named)
        corpus_vuids = {v for c in cases if c["family"] == family for v in c["expected"]}
        a = corpus_counts(cases, "asval", family)
        k = corpus_counts(cases, "khronos", family)
        rows.append([family, "%d (%d partial)" % (len(checked), len(checked) - full) if entries else "-",
                     "%d of %d" % (k_named, len(checked)) if entries else "-", len(corpus_vuids),
                     "%d / %d" % (a[0], a[1]), "%d of %d" % (a[2], a[3]),
                     "%d / %d" % (k[0], k[1]), "%d of %d" % (k[2], k[3])])
    return md_table(["family", "asval checks (VUIDs)", "named in the Khronos layer", "corpus VUIDs",
                     "asval detected", "asval false positives (valid cases)", "Khronos detected",
                     "Khronos false positives (valid cases)"], rows)


def overhead_lookup(overhead):
    return {(r["row"], r["config"]): r for r in overhead["rows"]}


def fmt_ns(ns):
    if ns is None:
        return "-"
    if ns >= 1e6:
        return "%.2f ms" % (ns / 1e6)
    if ns >= 1e3:
        return "%.1f µs" % (ns / 1e3)
    return "%.0f ns" % ns


def overhead_table(overhead):
    look = overhead_lookup(overhead)
    rows_order = []
    for r in overhead["rows"]:
        if r["row"] not in rows_order and r["config"] in ("none", "asval"):
            rows_order.append(r["row"])
    configs = [c for c in ["none", "asval", "asval-capture-off", "asval-capture-all", "khronos"]
               if any(k[1] == c for k in look)]
    out = []
    for row in rows_order:
        base = look.get((row, "none"))
        cells = [row]
        for config in configs:
            r = look.get((row, config))
            if not r:
                cells.append("-")
                continue
            cell = "%s / %s" % (fmt_ns(r["wall_ns_min"]), fmt_ns(r["wall_ns_median"]))
            if r.get("ir_per_call") is not None:
                cell += ", %s Ir" % format(int(r["ir_per_call"]), ",")
            if base and config != "none" and base["wall_ns_median"]:
                cell += " (%+.0f%%)" % (100.0 * (r["wall_ns_median"] / base["wall_ns_median"] - 1))
            cells.append(cell)
        a, k = look.get((row, "asval")), look.get((row, "khronos"))
        ratio = "-"
        if base and a and k and a.get("ir_per_call") is not None and k.get("ir_per_call") is not None:
            added_a = a["ir_per_call"] - base["ir_per_call"]
            added_k = k["ir_per_call"] - base["ir_per_call"]
            if added_k > 0:
                ratio = "%.2f" % (added_a / added_k)
        cells.append(ratio)
        out.append(cells)
    return md_table(["row"] + configs + ["asval added Ir / Khronos added Ir"], out)


def added_percent(look, row, config):
    base, r = look.get((row, "none")), look.get((row, config))
    if not base or not r or not base["wall_ns_median"]:
        return None
    return 100.0 * (r["wall_ns_median"] / base["wall_ns_median"] - 1)


def added_ir(look, row, config):
    base, r = look.get((row, "none")), look.get((row, config))
    if not base or not r or base.get("ir_per_call") is None or r.get("ir_per_call") is None:
        return None
    return r["ir_per_call"] - base["ir_per_call"]


def view_points(cases, overhead, frame_overhead):
    """Per configuration: corpus faults missed (this machine's corpus run), instructions added (callgrind, this
    machine) and the dynamic frame's added time (frame_overhead: the GPU's run when there is one, since frame times
    on a loaded CPU driver are noise)."""
    look = overhead_lookup(overhead)
    frames = overhead_lookup(frame_overhead)
    configs = ["asval"] + list(CAPTURE_CONFIGS) + list(FAMILY_CONFIGS) + ["khronos"]
    points = []
    for config in configs:
        if not any(config in c["results"] for c in cases):
            continue
        detected, expected, _, _ = corpus_counts(cases, config)
        missed = sorted({c["name"] for c in cases if c["expected"] and config in c["results"]
                         and c["results"][config]["missed"]})
        points.append({"config": config, "detected": detected, "expected": expected, "missed": missed,
                       "scene": added_percent(frames, "frame dynamic", config),
                       "build_ir": added_ir(look, "build 1x1", config),
                       "submit_ir": added_ir(look, "submit 1000 build+update", config)})
    return points


def view_table(points):
    rows = []
    for p in points:
        missed = ", ".join(p["missed"][:6]) + (" and %d more" % (len(p["missed"]) - 6) if len(p["missed"]) > 6 else "")
        rows.append([p["config"], "-" if p["scene"] is None else "%+.1f%%" % p["scene"],
                     "-" if p["build_ir"] is None else format(int(p["build_ir"]), ","),
                     "-" if p["submit_ir"] is None else format(int(p["submit_ir"]), ","),
                     "%d / %d" % (p["detected"], p["expected"]), p["expected"] - p["detected"], missed or "-"])
    return md_table(["configuration", "dynamic scene frame time", "added Ir per build call (1x1)",
                     "added Ir per submission of 1000 operations", "corpus detected", "faults missed",
                     "cases with a miss"], rows)


def plot(points, path, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(9, 5.5))
    for p in points:
        if p["scene"] is None:
            continue
        missed = p["expected"] - p["detected"]
        khronos = p["config"] == "khronos"
        ax.scatter([p["scene"]], [missed], marker="s" if khronos else "o", s=60,
                   color="tab:red" if khronos else ("tab:blue" if p["config"] == "asval" else "tab:gray"))
        ax.annotate(p["config"].replace("asval-", ""), (p["scene"], missed), textcoords="offset points",
                    xytext=(5, 4), fontsize=8)
    ax.set_xlabel("added frame time, dynamic sample scene (% over no layer, median)")
    ax.set_ylabel("corpus faults missed (labelled VUIDs not reported)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def reuse(path, target):
    """An earlier run's JSON, copied to where the document keeps it; returns what the document says of its command."""
    if os.path.abspath(path) != target:
        with open(path) as f, open(target, "w") as g:
            g.write(f.read())
    return "(reused: %s)" % path


def keep_beside(path, docs, name):
    """Copies a run's JSON next to the document (without the runs' output tails) and returns it loaded."""
    with open(path) as f:
        data = json.load(f)
    for c in data.get("cases", []):
        for r in c["results"].values():
            r.pop("output", None)
    target = os.path.join(docs, name)
    with open(target, "w") as f:
        json.dump(data, f, indent=1)
    return data


def load_gpu_overhead(args, docs):
    """The GPU's overhead run, with its family-off frame rows merged in, kept beside the document."""
    with open(args.gpu_overhead_json) as f:
        overhead = json.load(f)
    if args.gpu_overhead_families_json:
        with open(args.gpu_overhead_families_json) as f:
            merge_family_rows(overhead, json.load(f))
    with open(os.path.join(docs, "comparison-h200-overhead.json"), "w") as f:
        json.dump(overhead, f, indent=1)
    return overhead


def gpu_section(args, docs):
    out = ["## On a real GPU: %s" % args.gpu_name, "",
           "Measured with `scripts/device_comparison.sh overhead` and `scripts/device_comparison.sh corpus` on the "
           "device machine (16 cores, Ubuntu 24.04, Debian's Vulkan loader 1.3.239). That image has no Khronos "
           "layer: Debian's 1.3.239 was carried along. It runs only the corpus's valid programs there, since an "
           "invalid build that it does not catch reaches the GPU, and some hang it. No callgrind on that image: wall "
           "times only.", ""]
    if args.gpu_overhead_json:
        overhead = load_gpu_overhead(args, docs)
        out += ["### Overhead", "", "Raw: [comparison-h200-overhead.json](comparison-h200-overhead.json).", "",
                overhead_table(overhead), ""]
    if args.gpu_corpus_json:
        corpus = keep_beside(args.gpu_corpus_json, docs, "comparison-h200-corpus.json")
        cases = corpus["cases"]
        a = corpus_counts(cases, "asval")
        k = corpus_counts(cases, "khronos")
        out += ["### Corpus", "", "Raw: [comparison-h200-corpus.json](comparison-h200-corpus.json).", "",
                "asval reports %d of %d labelled VUIDs, with %d false positives on %d valid programs; the Khronos layer "
                "reports errors on %d of the %d valid programs." % (a[0], a[1], a[2], a[3], k[2], k[3]), "",
                "The labels are exact on lavapipe. Where this driver's sizes or alignments differ (its scratch "
                "alignment is 128, lavapipe's 8; its structures are larger), a case can break one more rule there, "
                "which asval rightly reports. Every difference from the labels:", ""]
        diffs = []
        for c in cases:
            r = c["results"].get("asval")
            if not r:
                continue
            if r["missed"] or r["extra"] or r["status"] != "done" or (not c["expected"] and r["warnings"]):
                diffs.append("- `%s`: labelled %s; reported %s%s" % (
                    c["name"], ", ".join(v.replace("VUID-", "") for v in c["expected"]) or "nothing",
                    ", ".join(v.replace("VUID-", "") for v in r["errors"]) or "nothing",
                    "" if r["status"] == "done" else "; the run ended: " + r["status"]))
        out += diffs or ["(none)"]
        out.append("")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "comparison.md"))
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--corpus-json")
    ap.add_argument("--overhead-json")
    ap.add_argument("--gpu-corpus-json", help="the corpus run on a GPU (scripts/device_comparison.sh corpus)")
    ap.add_argument("--gpu-overhead-json", help="the overhead run on a GPU (scripts/device_comparison.sh overhead)")
    ap.add_argument("--gpu-overhead-families-json",
                    help="the GPU's dynamic frame with each family off (scripts/device_comparison.sh overhead)")
    ap.add_argument("--gpu-name", default="NVIDIA H200, driver 580.159.04",
                    help="the GPU and driver those runs used (they are stored beside the document)")
    args = ap.parse_args()
    ensure_matplotlib()
    build = os.path.abspath(args.build)
    docs = os.path.dirname(os.path.abspath(args.out))
    os.makedirs(docs, exist_ok=True)
    corpus_json = os.path.join(docs, "comparison-corpus.json")
    overhead_json = os.path.join(docs, "comparison-overhead.json")
    commands = {
        "corpus": reuse(args.corpus_json, corpus_json) if args.corpus_json else run_corpus(build, corpus_json),
        "overhead": (reuse(args.overhead_json, overhead_json) if args.overhead_json
                     else run_overhead(build, overhead_json, args.rounds)),
    }
    with open(corpus_json) as f:
        corpus = json.load(f)
    with open(overhead_json) as f:
        overhead = json.load(f)
    cases = corpus["cases"]
    # Each run's command is kept in its JSON, so that a document regenerated from reused runs still names them.
    if not args.corpus_json:
        corpus["comparison_command"] = commands["corpus"]
    if not args.overhead_json:
        overhead["comparison_command"] = commands["overhead"]
        overhead["comparison_asval"] = asval_commit()  # the commit measured, kept for regenerations
        with open(overhead_json, "w") as f:
            json.dump(overhead, f, indent=1)
    commands = {"corpus": corpus.get("comparison_command", commands["corpus"]),
                "overhead": overhead.get("comparison_command", commands["overhead"])}
    # The corpus JSON is kept small: results only, not the runs' output tails.
    for c in cases:
        for r in c["results"].values():
            r.pop("output", None)
    with open(corpus_json, "w") as f:
        json.dump(corpus, f, indent=1)

    vuids = registry()
    named = khronos_named(vuids)
    m = overhead["machine"]  # bench/overhead/overhead_machine.py says where the runs were made
    frame_overhead, frame_machine = overhead, m.get("driver", "this machine")
    if args.gpu_overhead_json:
        frame_overhead, frame_machine = load_gpu_overhead(args, docs), args.gpu_name
    points = view_points(cases, overhead, frame_overhead)
    png = os.path.splitext(args.out)[0] + ".png"
    title = "asval (each capture setting, each family off) and the Khronos layer %s\nframe time on %s; misses in " \
        "the corpus run on this machine's driver" % (corpus.get("khronos_version") or "", frame_machine)
    plot(points, png, title)
    a = corpus_counts(cases, "asval")
    k = corpus_counts(cases, "khronos")
    doc = ["# asval beside the Khronos validation layer: what each catches, what each costs",
           "",
           "Generated by `scripts/comparison.py` on %s; do not edit by hand. Both layers ran on the same programs, "
           "the Khronos layer stacked alone with default settings (the installed package), asval alone with "
           "default settings unless a configuration says otherwise." % datetime.date.today().isoformat(),
           "",
           "Machine: " + "; ".join(str(part) for part in [
               "%s, %s cores" % (m.get("cpu"), m.get("cores")), m.get("os"), m.get("kernel"),
               m.get("driver"), "Vulkan loader %s" % m.get("loader"), "Khronos validation layer %s" % m.get("khronos_layer"),
               "compiler %s" % m.get("compiler"), "asval %s" % overhead.get("comparison_asval", asval_commit())] if part) + ".",
           "",
           "Commands: corpus `%s`; overhead `%s`." % (commands["corpus"], commands["overhead"]),
           "Raw results: [comparison-corpus.json](comparison-corpus.json), "
           "[comparison-overhead.json](comparison-overhead.json).",
           "",
           "## In one line",
           "",
           "Corpus of %d programs (%d with a fault, %d valid): asval reports %d of %d labelled VUIDs with %d false "
           "positives; the Khronos layer %d of %d with %d false positives." % (
               len(cases), sum(1 for c in cases if c["expected"]), sum(1 for c in cases if not c["expected"]),
               a[0], a[1], a[2], k[0], k[1], k[2]),
           "",
           "## What each layer checks, by rule family",
           "",
           "*asval checks*: VUIDs of the family in the check registry (`scripts/checks`, status checked or partial). "
           "*Named in the Khronos layer*: how many of those VUIDs (under any of their names) occur in the Khronos "
           "layer's binary, an upper bound of what it checks. *Corpus*: the labelled VUIDs of the family's fault "
           "cases that each layer reported (detected / labelled) and the valid cases it reported an error on. "
           "Family `scene`: the sample scene's faults; `patterns`: whole-program valid patterns.",
           "",
           feature_table(vuids, named, cases),
           "",
           "## Overhead",
           "",
           "Per call (per cycle, per submission, per frame): wall time min / median over interleaved rounds, "
           "instructions per call under callgrind, and the median's change against no layer. Ratios are computed "
           "within this run.",
           "",
           overhead_table(overhead),
           "",
           "## Run time against error",
           "",
           "What asval costs at each setting against what it then misses in the corpus; the Khronos layer as a "
           "point of its own. Misses and instructions are this machine's (%s, callgrind); the dynamic frame's added "
           "time is measured on %s (median of interleaved rounds), since frame times on a CPU driver sharing two "
           "cores with other work are noise." % (m.get("driver"), frame_machine),
           "",
           "![run time against error](%s)" % os.path.basename(png),
           "",
           view_table(points),
           "",
           "## Where the Khronos layer differs",
           "",
           ]
    diffs = []
    for c in cases:
        r = c["results"].get("khronos")
        if r is None:
            continue
        if c["expected"] and r["missed"]:
            diffs.append("- `%s` (%s): misses %s%s" % (c["name"], c["family"], ", ".join(r["missed"]),
                                                       "" if r["status"] == "done" else "; the run ended: " + r["status"]))
        if not c["expected"] and r["errors"]:
            diffs.append("- `%s` (valid): reports %s" % (c["name"], ", ".join(r["errors"])))
    doc += diffs or ["(none)"]
    doc.append("")
    if args.gpu_corpus_json or args.gpu_overhead_json:
        doc += gpu_section(args, docs)
    with open(args.out, "w") as f:
        f.write("\n".join(doc))
    print("wrote %s and %s" % (args.out, png))


if __name__ == "__main__":
    main()
