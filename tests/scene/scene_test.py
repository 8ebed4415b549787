#!/usr/bin/env python3
"""Runs the sample scene (examples/scene) and checks what the validation layers reported.

Modes (the environment selects the driver and the layers, see tests/scene/CMakeLists.txt):
  clean           the scene runs and no layer reports anything (no message, empty asval report)
  fault NAME      if asval checks NAME's VUID (scripts/checks/*.json says "checked"), the run reports exactly
                  that VUID as an error and no other error; otherwise the run must still finish cleanly, and
                  the test is skipped (exit 77) until the check lands
  image           the PNG rendered without any layer and with asval are byte for byte identical
  vuids           every fault's VUID is a VUID of the specification chapter under its newest name
"""
import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile

SKIP = 77
LAYER = "VK_LAYER_ASVAL_as_validation"
REPORT_ENV = "VK_ASVAL_AS_VALIDATION_REPORT_FILE"


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def run_scene(scene, args, env, report=None):
    env = dict(env)
    if report:
        env[REPORT_ENV] = report
        if os.path.exists(report):
            os.remove(report)  # the layer appends
    proc = subprocess.run([scene] + args, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          universal_newlines=True, timeout=600)
    sys.stdout.write(proc.stdout)
    if proc.returncode != 0:
        fail("asval_scene %s exited with %d" % (" ".join(args), proc.returncode))
    return proc.stdout


def read_report(path):
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


def list_faults(scene):
    out = subprocess.run([scene, "--list-faults"], stdout=subprocess.PIPE, universal_newlines=True, check=True).stdout
    faults = {}
    for line in out.splitlines():
        if line.strip() and not line.startswith("#"):
            name, vuid = line.split()[:2]
            faults[name] = vuid
    return faults


def checked_vuids(checks_dir):
    checked = set()
    for path in sorted(glob.glob(os.path.join(checks_dir, "*.json"))):
        with open(path) as f:
            for entry in json.load(f):
                if entry.get("status") in ("checked", "partial"):  # partial: the scene's fault is in the checked part
                    checked.add(entry["vuid"])
    return checked


def message_count_line(output):
    for line in output.splitlines():
        if line.startswith("validation messages:"):
            return line
    fail("the scene printed no summary line")


def mode_clean(opts):
    with tempfile.TemporaryDirectory() as tmp:
        report = os.path.join(tmp, "report.jsonl")
        out = run_scene(opts.scene, ["--frames", str(opts.frames)], os.environ, report)
        summary = message_count_line(out)
        if summary != "validation messages: 0 error(s), 0 warning(s)":
            fail("expected no validation message, got: " + summary)
        lines = read_report(report)
        if lines:
            fail("asval's report is not empty: %s" % lines[0])
    print("PASS: no validation message")


def mode_fault(opts):
    faults = list_faults(opts.scene)
    if opts.name not in faults:
        fail("asval_scene --list-faults has no fault %s" % opts.name)
    vuid = faults[opts.name]
    exists = vuid in checked_vuids(opts.checks)
    with tempfile.TemporaryDirectory() as tmp:
        report = os.path.join(tmp, "report.jsonl")
        args = ["--frames", "2", "--instances", "300", "--size", "64x64", "--inject", opts.name]
        out = run_scene(opts.scene, args, os.environ, report)
        lines = read_report(report)
    errors = sorted({l["vuid"] for l in lines if l.get("severity") == "error"})
    if not exists:
        print("SKIP: %s is not checked by asval yet (scripts/checks); the run finished, asval reported %s"
              % (vuid, errors or "nothing"))
        sys.exit(SKIP)
    if "fault %s: expected %s: reported" % (opts.name, vuid) not in out:
        fail("the scene's messenger did not receive %s" % vuid)
    if errors != [vuid]:
        fail("expected exactly the error %s in asval's report, got %s" % (vuid, errors))
    print("PASS: %s reported %s" % (opts.name, vuid))


def mode_image(opts):
    with tempfile.TemporaryDirectory() as tmp:
        plain_env = dict(os.environ)
        plain_env.pop("VK_INSTANCE_LAYERS", None)
        layered_env = dict(os.environ)
        layered_env["VK_INSTANCE_LAYERS"] = LAYER
        images = []
        for name, env in (("without", plain_env), ("with", layered_env)):
            path = os.path.join(tmp, name + ".png")
            out = run_scene(opts.scene, ["--frames", str(opts.frames), "--out", path], env)
            if "validation messages: 0 error(s), 0 warning(s)" not in out:
                fail("the %s-layer run reported something" % name)
            with open(path, "rb") as f:
                images.append(f.read())
    if len(images[0]) < 1000:
        fail("the PNG is suspiciously small (%d bytes)" % len(images[0]))
    if images[0] != images[1]:
        fail("the PNGs rendered without and with the layer differ")
    print("PASS: identical PNGs (%d bytes)" % len(images[0]))


def mode_vuids(opts):
    with open(opts.vuids) as f:
        table = json.load(f)
    chapter = set(table["chapter_vuids"])
    older = {old: new for new, olds in table["aliases"].items() for old in olds}
    for name, vuid in sorted(list_faults(opts.scene).items()):
        if vuid not in chapter:
            fail("%s: %s is not a VUID of the chapter" % (name, vuid))
        if vuid in older:
            fail("%s: %s is an older name of %s" % (name, vuid, older[vuid]))
    print("PASS: every fault names a chapter VUID under its newest name")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scene", required=True)
    parser.add_argument("--checks", help="scripts/checks (the registry of asval's checks)")
    parser.add_argument("--vuids", help="scripts/vuids_newer.json")
    parser.add_argument("--frames", type=int, default=4)
    parser.add_argument("mode", choices=["clean", "fault", "image", "vuids"])
    parser.add_argument("name", nargs="?")
    opts = parser.parse_args()
    {"clean": mode_clean, "fault": mode_fault, "image": mode_image, "vuids": mode_vuids}[opts.mode](opts)


if __name__ == "__main__":
    main()
