#!/usr/bin/env python3
"""Runs the accuracy corpus under asval and under the Khronos validation layer, and compares.

Each case runs in its own process: the corpus program's cases (asval_corpus --list) and the sample scene's
faults (asval_scene --list-faults). A case is labelled with the VUIDs it must trigger; a valid case must
trigger nothing. Per configuration (a layer and its settings) the runner counts, per rule family:
  detected / expected   labelled VUIDs reported (a layer may use an older name of the same rule: the aliases
                        of scripts/vuids_newer.json count), over all fault cases
  false positives       valid cases with any error
and prints one table. asval's own configuration is held to the labels exactly: every labelled VUID reported,
no other error in a fault case, no error or warning in a valid case. With --verdicts, every configuration's
verdicts are compared with the committed ones (the Khronos layer's only when its version is the one recorded);
any change fails the run. --update-verdicts rewrites that file instead: a reviewed step, like a new baseline.

Extra configurations: --config NAME:ENV=VALUE,ENV=VALUE (asval with those settings), reported beside.
Exit status: 0 all well, 1 a verdict differs from the labels or the committed verdicts.
"""
import argparse
import atexit
import concurrent.futures
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "bench", "overhead"))
import overhead_env  # noqa: E402  (--config's syntax: one parser for the corpus and the overhead benchmark)
ALIASES_FILE = os.path.join(ROOT, "scripts", "vuids_newer.json")
KHRONOS_MANIFEST_DIR = "/usr/share/vulkan/explicit_layer.d"
ASVAL = "VK_LAYER_ASVAL_as_validation"
KHRONOS = "VK_LAYER_KHRONOS_validation"
LVP_ICD = "/usr/share/vulkan/icd.d/lvp_icd.json"
TEST_DRIVER = "VK_LAYER_ASVAL_test_driver"
# The rules a host or indirect build breaks on a device without the feature (lavapipe): a case labelled with one of
# these runs again on asval's test driver (tests/driver), whose device enables the feature, labelled without it.
FEATURE_RULES = {
    "VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581": "host-commands",
    "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-accelerationStructureIndirectBuild-03650": "indirect-build",
}
DRIVER_SUFFIX = "@test-driver"
TIMEOUT_S = 120


def khronos_version():
    try:
        for name in os.listdir(KHRONOS_MANIFEST_DIR):
            with open(os.path.join(KHRONOS_MANIFEST_DIR, name)) as f:
                layer = json.load(f).get("layer", {})
            if layer.get("name") == KHRONOS:
                return layer.get("api_version", "unknown")
    except OSError:
        pass
    return None


def load_aliases():
    with open(ALIASES_FILE) as f:
        return json.load(f).get("aliases", {})


def registry_families():
    """VUID -> its rule family in asval's check registry (scripts/checks/<family>.json)."""
    families = {}
    checks = os.path.join(ROOT, "scripts", "checks")
    for name in sorted(os.listdir(checks)):
        if name.endswith(".json"):
            with open(os.path.join(checks, name)) as f:
                for entry in json.load(f):
                    families[entry["vuid"]] = entry["family"]
    return families


def list_cases(corpus, scene):
    """Every case with its label. A case counts in the family it names when asval's registry gives one of its VUIDs
    that family (what switching the family off loses), else in its first VUID's family."""
    families = registry_families()
    cases = []
    out = subprocess.run([corpus, "--list"], stdout=subprocess.PIPE, universal_newlines=True, check=True).stdout
    for c in json.loads(out):
        c["command"] = [corpus, c["name"]]
        label_families = [families[v] for v in c["expected"] if v in families]
        if label_families and c["family"] not in label_families:
            c["family"] = label_families[0]
        if c.get("test_driver"):
            c["family"] += DRIVER_SUFFIX
        cases.append(c)
    cases += test_driver_twins(cases)
    if scene:
        out = subprocess.run([scene, "--list-faults"], stdout=subprocess.PIPE, universal_newlines=True,
                             check=True).stdout
        for line in out.splitlines():
            if not line.strip() or line.startswith("#"):
                continue
            name, vuid = line.split()[:2]
            cases.append({"name": "scene-" + name, "family": "scene", "expected": [vuid],
                          "pattern": "the sample scene, 2 frames, then the fault " + name,
                          "command": [scene, "--frames", "2", "--instances", "500", "--inject", name]})
        cases.append({"name": "scene-clean", "family": "scene", "expected": [],
                      "pattern": "the sample scene, 4 frames: refits, TLAS updates and rebuilds, tracing",
                      "command": [scene, "--frames", "4", "--instances", "500"]})
    return cases


def test_driver_twins(cases):
    """The host and indirect cases again on asval's test driver, a layer placed last over lavapipe that executes host
    and indirect builds (docs/testing.md): the device enables the feature, and the label drops the feature's rule. A
    case about the missing feature alone is left out (it has nothing else to report), except the valid twins of the
    host family ("feature-only"), which become valid programs there. Every layer of a configuration sits above the
    test driver."""
    twins = []
    for c in cases:
        features = [FEATURE_RULES[v] for v in c["expected"] if v in FEATURE_RULES]
        if not features:
            continue
        expected = [v for v in c["expected"] if v not in FEATURE_RULES]
        if not expected and "feature-only" not in c["name"]:
            continue
        twins.append(dict(c, name=c["name"] + DRIVER_SUFFIX, family=c["family"] + DRIVER_SUFFIX, expected=expected,
                          test_driver=",".join(features),
                          pattern=c["pattern"] + " (on the test driver, the feature enabled)"))
    return twins


def case_env(case, env):
    """A configuration's environment for one case: on the test driver, that layer last and the device's features.
    The test driver sits over lavapipe, a CPU device, where asval's capture_method auto copies and so cannot read what
    an indirect build's range infos select (docs/capture.md); indirect builds exist on GPUs, where auto reduces: the
    cases there run asval as it runs on a GPU (capture_method reduce), unless the configuration sets the method."""
    if not case.get("test_driver"):
        return env
    layers = env["ASVAL_TEST_LAYERS"] + ":" + TEST_DRIVER
    extra = {"ASVAL_TEST_LAYERS": layers, "VK_INSTANCE_LAYERS": layers,
             "ASVAL_CORPUS_DEVICE_FEATURES": case["test_driver"]}
    if "VK_ASVAL_AS_VALIDATION_CAPTURE_METHOD" not in env:
        extra["VK_ASVAL_AS_VALIDATION_CAPTURE_METHOD"] = "reduce"
    return dict(env, **extra)


# The Khronos layer 1.3.239 predates VK_EXT_layer_settings: it reports a VkLayerSettingsCreateInfoEXT in
# VkInstanceCreateInfo's chain (the scene's fault runs chain one to turn on asval's protect mode) as
# VUID-VkInstanceCreateInfo-pNext-pNext. A known-old rule, muted by VUID; every other setting is the default.
KHRONOS_SETTINGS = "khronos_validation.message_id_filter = VUID-VkInstanceCreateInfo-pNext-pNext\n"


def khronos_settings_file():
    folder = tempfile.mkdtemp(prefix="asval-corpus-khronos-")
    atexit.register(shutil.rmtree, folder, True)
    path = os.path.join(folder, "vk_layer_settings.txt")
    with open(path, "w") as f:
        f.write(KHRONOS_SETTINGS)
    return path


def configurations(layer_path, extra, driver_files, test_driver_path):
    base = {
        "VK_LAYER_PATH": ":".join([layer_path, KHRONOS_MANIFEST_DIR] + ([test_driver_path] if test_driver_path else [])),
        "VK_DRIVER_FILES": driver_files,
        "VK_LOADER_LAYERS_DISABLE": "~implicit~",
        "VK_LAYER_SETTINGS_PATH": "/nonexistent/vk_layer_settings.txt",  # default settings for every layer
    }
    configs = {
        "asval": dict(base, ASVAL_TEST_LAYERS=ASVAL, VK_INSTANCE_LAYERS=ASVAL),
        "khronos": dict(base, ASVAL_TEST_LAYERS=KHRONOS, VK_INSTANCE_LAYERS=KHRONOS,
                        VK_LAYER_SETTINGS_PATH=khronos_settings_file()),
    }
    for spec in extra:  # NAME:ENV=VALUE,... read as the overhead benchmark reads its own --config
        config = overhead_env.parse_config(spec)
        configs[config.name] = dict(configs["asval"], **config.env)
    return configs


# Scene lines "finding: error VUID"; corpus lines are JSON.
SCENE_FINDING = re.compile(r"^finding: (error|warning) (\S+)")


def run_case(case, env):
    full_env = dict(os.environ)
    for key in ("VK_INSTANCE_LAYERS", "ASVAL_TEST_LAYERS", "VK_ADD_LAYER_PATH"):
        full_env.pop(key, None)
    full_env.update(env)
    errors, warnings, status = [], [], "done"
    with tempfile.TemporaryDirectory() as cwd:  # no vk_layer_settings.txt of a working directory applies
        try:
            proc = subprocess.run(case["command"], env=full_env, cwd=cwd, stdout=subprocess.PIPE,
                                  stderr=subprocess.STDOUT, universal_newlines=True, errors="replace",
                                  timeout=TIMEOUT_S)
            output, code = proc.stdout, proc.returncode
        except subprocess.TimeoutExpired as e:
            output, code = (e.stdout or b"").decode(errors="replace") if isinstance(e.stdout, bytes) else (
                e.stdout or ""), None
            status = "timeout"
    finished = False
    for line in output.splitlines():
        m = SCENE_FINDING.match(line)
        if m:
            (errors if m.group(1) == "error" else warnings).append(m.group(2))
            continue
        if not line.startswith("{"):
            continue
        try:
            msg = json.loads(line)
        except ValueError:
            continue
        if "severity" in msg:
            (errors if msg["severity"] == "error" else warnings).append(msg["id"] or "(no id)")
        elif msg.get("done"):
            finished = True
        elif "exception" in msg:
            status = "exception: " + msg["exception"]
    if status == "done":
        is_scene = case["family"] == "scene"
        if code != 0 or (not is_scene and not finished):
            status = "crashed (exit %s)" % code
    return {"status": status, "errors": sorted(set(errors)), "warnings": sorted(set(warnings)),
            "output": output[-3000:] if status != "done" else ""}


def judge(case, result, aliases):
    names = {v: {v, *aliases.get(v, [])} for v in case["expected"]}
    reported = set(result["errors"])
    detected = [v for v in case["expected"] if names[v] & reported]
    known = set().union(*names.values()) if names else set()
    result["detected"] = detected
    result["missed"] = [v for v in case["expected"] if v not in detected]
    result["extra"] = sorted(reported - known)
    return result


def exact(case, result):
    """asval's own standard: the labels exactly."""
    if result["status"] != "done" or result["missed"] or result["extra"]:
        return False
    return bool(case["expected"]) or not result["warnings"]


def verdict(result):
    """What --verdicts compares: what was reported of the labels, and what else."""
    return {"status": result["status"].split(" ")[0], "detected": result["detected"], "extra": result["extra"]}


def table(cases, configs):
    families = sorted({c["family"] for c in cases})
    header = ["family", "faults", "valid"]
    for name in configs:
        header += [name + " detected", name + " FP"]
    rows = [header]
    totals = [0, 0] + [[0, 0, 0] for _ in configs]
    for family in families + ["total"]:
        sel = [c for c in cases if family in ("total", c["family"])]
        faults = [c for c in sel if c["expected"]]
        row = [family, str(len(faults)), str(len(sel) - len(faults))]
        for name in configs:
            ran = [c for c in faults if name in c["results"]]
            expected = sum(len(c["expected"]) for c in ran)
            detected = sum(len(c["results"][name]["detected"]) for c in ran)
            fps = sum(1 for c in sel if not c["expected"] and c["results"][name]["errors"])
            row += ["%d/%d" % (detected, expected), str(fps)]
        rows.append(row)
    widths = [max(len(r[i]) for r in rows) for i in range(len(header))]
    return "\n".join("  ".join(cell.ljust(w) for cell, w in zip(r, widths)) for r in rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--corpus", required=True, help="the asval_corpus program")
    ap.add_argument("--scene", help="the asval_scene program (its faults join the corpus)")
    ap.add_argument("--layer-path", required=True, help="the folder holding asval's layer manifest")
    ap.add_argument("--config", action="append", default=[], help="NAME:ENV=VALUE,... an extra asval configuration")
    ap.add_argument("--no-khronos", action="store_true", help="leave the Khronos layer out")
    ap.add_argument("--driver-files", default=LVP_ICD, help="the ICD manifest (VK_DRIVER_FILES); default lavapipe")
    ap.add_argument("--test-driver-path", help="the folder holding the test driver's layer manifest (tests/driver of "
                    "the build): the host and indirect cases run there too (name" + DRIVER_SUFFIX + ")")
    ap.add_argument("--valid-only", action="append", default=[], metavar="CONFIG",
                    help="run only the valid cases under CONFIG (on a GPU that an uncaught invalid build may hang)")
    ap.add_argument("--cases", help="only the cases whose name starts with this")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    ap.add_argument("--json", help="write every result here")
    ap.add_argument("--verdicts", help="the committed verdicts to compare with")
    ap.add_argument("--update-verdicts", action="store_true", help="rewrite --verdicts from this run")
    args = ap.parse_args()

    aliases = load_aliases()
    cases = list_cases(os.path.abspath(args.corpus), args.scene and os.path.abspath(args.scene))
    if not args.test_driver_path:
        cases = [c for c in cases if not c.get("test_driver")]
    if args.cases:
        cases = [c for c in cases if c["name"].startswith(args.cases)]
    configs = configurations(os.path.abspath(args.layer_path), args.config, args.driver_files,
                             args.test_driver_path and os.path.abspath(args.test_driver_path))
    kversion = khronos_version()
    if args.no_khronos or not kversion:
        del configs["khronos"]
        if not args.no_khronos:
            print("note: the Khronos validation layer is not installed; its column is left out")

    jobs = [(c, name) for c in cases for name in configs if not (c["expected"] and name in args.valid_only)]
    for c in cases:
        c["results"] = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = {pool.submit(run_case, c, case_env(c, configs[name])): (c, name) for c, name in jobs}
        for future in concurrent.futures.as_completed(futures):
            c, name = futures[future]
            c["results"][name] = judge(c, future.result(), aliases)

    problems = []
    for c in cases:
        r = c["results"].get("asval")
        if r and not exact(c, r):
            problems.append("asval on %s: expected %s; reported errors %s, warnings %s, status %s%s" % (
                c["name"], c["expected"] or "silence", r["errors"], r["warnings"], r["status"],
                ("\n" + r["output"]) if r["output"] else ""))
    print("corpus: %d cases (%d faults, %d valid), Khronos layer %s" % (
        len(cases), sum(1 for c in cases if c["expected"]), sum(1 for c in cases if not c["expected"]),
        kversion or "absent"))
    print(table(cases, configs))
    for c in cases:  # what the other layers missed or got wrong, for the reader
        for name in c["results"]:
            r = c["results"][name]
            if name != "asval" and (r["missed"] or (not c["expected"] and r["errors"])):
                print("  %s on %s: missed %s, errors %s, status %s" % (name, c["name"], r["missed"], r["errors"],
                                                                        r["status"]))

    if args.verdicts:
        current = {"khronos_version": kversion,
                   "verdicts": {name: {c["name"]: verdict(c["results"][name]) for c in cases if name in c["results"]}
                                for name in configs}}
        if args.update_verdicts:
            with open(args.verdicts, "w") as f:
                json.dump(current, f, indent=1, sort_keys=True)
                f.write("\n")
            print("wrote " + args.verdicts)
        elif os.path.exists(args.verdicts):
            with open(args.verdicts) as f:
                committed = json.load(f)
            for name, verdicts in current["verdicts"].items():
                if name == "khronos" and committed.get("khronos_version") != kversion:
                    print("note: Khronos layer %s, verdicts committed for %s: not compared" % (
                        kversion, committed.get("khronos_version")))
                    continue
                before = committed["verdicts"].get(name)
                if before is None:
                    continue
                if args.cases:
                    before = {k: v for k, v in before.items() if k in verdicts}
                for case in sorted(set(before) | set(verdicts)):
                    if before.get(case) != verdicts.get(case):
                        problems.append("verdict changed, %s on %s: committed %s, now %s" % (
                            name, case, before.get(case), verdicts.get(case)))
        else:
            problems.append("no committed verdicts at %s (run with --update-verdicts)" % args.verdicts)

    if args.json:
        with open(args.json, "w") as f:
            json.dump({"khronos_version": kversion, "configs": list(configs), "cases": cases}, f, indent=1)
    for p in problems:
        print("FAIL: " + p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
