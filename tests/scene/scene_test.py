#!/usr/bin/env python3
"""Runs the sample scene (examples/scene) and checks what the validation layers reported.

Modes (the environment selects the driver and the layers, see tests/scene/CMakeLists.txt):
  clean           the scene runs and no layer reports anything (no message, empty asval report)
  fault NAME      the scene runs with asval's protect mode on (it chains the setting itself) and exits 0. If asval
                  checks NAME's VUID (scripts/checks/*.json says "checked"), the run reports exactly that VUID as
                  an error and no other error, and a fault found at record time or at submission never reaches
                  the driver: asval's ASVAL-Protect-Withheld notices name it (the command and its submission, or
                  the submission), the scene saw the submission fail with VK_ERROR_VALIDATION_FAILED_EXT, and the
                  protect summary counts them; a fault found at execution runs (no notice). Otherwise the run
                  must still finish, and the test is skipped (exit 77) until the check lands
  unprotected     every record-time (hang-prone) fault, run without any layer and then under asval with protect
                  forced off (VK_ASVAL_AS_VALIDATION_PROTECT=false wins over the scene's chained setting): no
                  ASVAL-Protect-Withheld notice arrives, so the scene never submits the command buffer, says so
                  and exits 0 (under asval the VUID is still reported)
  image           the PNG rendered without any layer and with asval are byte for byte identical
  vuids           every fault's VUID is a VUID of the specification chapter under its newest name, or a
                  layer-specific id (ASVAL-...) that a check defines, for a rule the specification gives no VUID
"""
import argparse
import glob
import json
import os
import re
import subprocess
import sys
import tempfile

SKIP = 77
LAYER = "VK_LAYER_ASVAL_as_validation"
NOTICE = "ASVAL-Protect-Withheld"
SUMMARY = "ASVAL-History-Summary"
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
    """{name: (vuid, when)}, when being record, submit, execution or destroy."""
    out = subprocess.run([scene, "--list-faults"], stdout=subprocess.PIPE, universal_newlines=True, check=True).stdout
    faults = {}
    for line in out.splitlines():
        if line.strip() and not line.startswith("#"):
            name, vuid, when = line.split()[:3]
            faults[name] = (vuid, when)
    return faults


def layer_ids(checks_dir):
    """The layer-specific ids (ASVAL-...) the layer's checks define (layer/checks/*.h), for rules of the
    specification that have no VUID: each exists only as part of a check, so a fault naming one is checked."""
    root = os.path.dirname(os.path.dirname(os.path.abspath(checks_dir)))
    ids = set()
    for path in glob.glob(os.path.join(root, "layer", "checks", "*.h")):
        with open(path) as f:
            ids |= set(re.findall(r'constexpr const char k\w+\[\] = "(ASVAL-[A-Za-z]+-[A-Za-z]+)"', f.read()))
    return ids


def checked_vuids(checks_dir):
    checked = layer_ids(checks_dir)
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


def check_protected(name, vuid, when, out, lines):
    """A fault found at record time or at submission: asval kept it from the driver and said so."""
    notices = [l for l in lines if l.get("vuid") == NOTICE]
    if not notices:
        fail("no %s notice in asval's report" % NOTICE)
    for n in notices:
        if n.get("severity") != "info" or vuid not in n.get("message", ""):
            fail("a %s notice that is not an information message naming %s: %s" % (NOTICE, vuid, n))
    functions = [n["function"] for n in notices]
    # The recorded command (record faults), then the submission of its command buffer, or the submission alone.
    expected = ["vkCmd", "vkQueueSubmit"] if when == "record" else ["vkQueueSubmit"]
    if len(functions) != len(expected) or not all(f.startswith(e) for f, e in zip(functions, expected)):
        fail("expected %s notices for %s, got them for %s" % (NOTICE, " then ".join(expected), functions))
    if "fault %s: %d %s notice(s)" % (name, len(notices), NOTICE) not in out:
        fail("the scene's messenger did not receive the %d %s notice(s) of the report" % (len(notices), NOTICE))
    if when == "record" and "fault: asval withheld the command while recording; submitting its buffer" not in out:
        fail("the scene did not see the recorded command withheld")
    if "fault: asval withheld the submission (VK_ERROR_VALIDATION_FAILED_EXT)" not in out:
        fail("the scene did not see its submission fail with VK_ERROR_VALIDATION_FAILED_EXT")
    summary = "Protect mode kept from the driver: recorded_commands_withheld=%d submissions_withheld=1 " \
              "host_commands_withheld=0" % (1 if when == "record" else 0)
    if not any(l.get("vuid") == SUMMARY and summary in l.get("message", "") for l in lines):
        fail("asval's report lacks the summary line '%s'" % summary)


def mode_fault(opts):
    faults = list_faults(opts.scene)
    if opts.name not in faults:
        fail("asval_scene --list-faults has no fault %s" % opts.name)
    vuid, when = faults[opts.name]
    exists = vuid in checked_vuids(opts.checks)
    with tempfile.TemporaryDirectory() as tmp:
        report = os.path.join(tmp, "report.jsonl")
        args = ["--frames", "2", "--instances", "300", "--size", "64x64", "--inject", opts.name]
        out = run_scene(opts.scene, args, os.environ, report)  # exit status 0, or the test fails
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
    if when in ("record", "submit"):
        check_protected(opts.name, vuid, when, out, lines)
        print("PASS: %s reported %s; protect mode withheld it (%s)" % (opts.name, vuid, when))
    elif when == "destroy":
        # A destroy while the work using the object was pending: asval kept it back until that work completed.
        notices = [l for l in lines if l.get("vuid") == NOTICE]
        if len(notices) != 1 or not notices[0].get("function", "").startswith("vkDestroy") or \
                vuid not in notices[0].get("message", ""):
            fail("expected one %s notice for the destroy naming %s, got %s" % (NOTICE, vuid, notices))
        if "fault: asval withheld" in out:
            fail("a destroy fault, yet the scene saw a command or submission withheld")
        print("PASS: %s reported %s; protect mode kept the destroy back until the work completed" % (opts.name, vuid))
    else:
        # Judged once the work completed: it ran, so neither the command nor its submission was withheld.
        if "fault: asval withheld" in out:
            fail("a fault found at execution was withheld before it ran")
        if any(l.get("vuid") == NOTICE and "not passed down" in l.get("message", "") for l in lines):
            fail("a fault found at execution, yet asval announced a command or submission it did not pass down")
        print("PASS: %s reported %s at execution (it ran: nothing to withhold before)" % (opts.name, vuid))


def mode_unprotected(opts):
    withheld_by_scene = "fault: no %s notice while recording; the command buffer is withheld by the scene" % NOTICE
    plain_env = dict(os.environ)
    plain_env.pop("VK_INSTANCE_LAYERS", None)
    off_env = dict(os.environ)
    off_env["VK_ASVAL_AS_VALIDATION_PROTECT"] = "false"
    record_faults = sorted(n for n, (_, when) in list_faults(opts.scene).items() if when == "record")
    if not record_faults:
        fail("asval_scene --list-faults lists no record-time fault")
    for name in record_faults:
        vuid = list_faults(opts.scene)[name][0]
        args = ["--frames", "2", "--instances", "300", "--size", "64x64", "--inject", name]
        for label, env in (("without asval", plain_env), ("asval, protect off", off_env)):
            out = run_scene(opts.scene, args, env)  # exit status 0, or the test fails
            if withheld_by_scene not in out or "fault: asval withheld" in out:
                fail("%s (%s): the scene did not keep the command buffer to itself" % (name, label))
            if "fault %s: 0 %s notice(s)" % (name, NOTICE) not in out:
                fail("%s (%s): a %s notice arrived" % (name, label, NOTICE))
            if env is off_env and "fault %s: expected %s: reported" % (name, vuid) not in out:
                fail("%s (asval, protect off): %s was not reported" % (name, vuid))
    print("PASS: %d record-time faults never submitted without protect mode" % len(record_faults))


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
    # VUIDs of other chapters that acceleration-structure work breaks (scripts/vuids_beyond_chapter.json).
    beyond_path = os.path.join(os.path.dirname(opts.vuids), "vuids_beyond_chapter.json")
    with open(beyond_path) as f:
        chapter |= set(json.load(f)["vuids"])
    older = {old: new for new, olds in table["aliases"].items() for old in olds}
    ids = layer_ids(opts.checks)
    for name, (vuid, _) in sorted(list_faults(opts.scene).items()):
        if vuid.startswith("ASVAL-"):
            if vuid not in ids:
                fail("%s: %s is no layer-specific id a check defines (layer/checks/*.h)" % (name, vuid))
            continue
        if vuid not in chapter:
            fail("%s: %s is not a VUID of the chapter (nor of scripts/vuids_beyond_chapter.json)" % (name, vuid))
        if vuid in older:
            fail("%s: %s is an older name of %s" % (name, vuid, older[vuid]))
    print("PASS: every fault names a chapter VUID under its newest name (or a layer-specific id a check defines)")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scene", required=True)
    parser.add_argument("--checks", help="scripts/checks (the registry of asval's checks)")
    parser.add_argument("--vuids", help="scripts/vuids_newer.json")
    parser.add_argument("--frames", type=int, default=4)
    parser.add_argument("mode", choices=["clean", "fault", "unprotected", "image", "vuids"])
    parser.add_argument("name", nargs="?")
    opts = parser.parse_args()
    {"clean": mode_clean, "fault": mode_fault, "unprotected": mode_unprotected, "image": mode_image,
     "vuids": mode_vuids}[opts.mode](opts)


if __name__ == "__main__":
    main()
