#!/usr/bin/env python3
"""Tests of scripts/asval-run (the CI gate): exit status, summary and report, protect mode on and off.

examples/minimal records one valid build and one whose scratch address breaks the alignment rule
(VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710). With its messenger it submits the invalid command buffer
too; with --no-messenger it never submits it. The expectations below are what the layer must do, written by hand.
"""
import argparse
import json
import os
import subprocess
import sys

VUID = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710"
WITHHELD = "ASVAL-Protect-Withheld"
failures = []


def run(args, gate_args, command, report_name):
    report = os.path.join(args.work, report_name)
    cmd = [sys.executable, args.asval_run, "--layer-path", args.layer_path, "--report", report] + gate_args
    proc = subprocess.run(cmd + ["--"] + command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          timeout=120)
    lines = []
    if os.path.exists(report):
        with open(report) as f:
            lines = [json.loads(line) for line in f if line.strip()]
    return proc, lines


def expect(name, condition, detail=""):
    print("%s %s" % ("ok  " if condition else "FAIL", name))
    if not condition:
        failures.append(name)
        if detail:
            print(detail)


def by_id(lines, vuid):
    return [l for l in lines if l.get("vuid") == vuid]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--asval-run", required=True)
    p.add_argument("--layer-path", required=True)
    p.add_argument("--minimal", required=True)
    p.add_argument("--work", required=True)
    args = p.parse_args()

    # 1. Protect on (the default): the invalid build and then its submission are withheld; minimal_build's
    # vkQueueSubmit fails (VK_ERROR_VALIDATION_FAILED_EXT) and it exits 1; the gate exits 65 and says why.
    proc, lines = run(args, [], [args.minimal], "protect.jsonl")
    out = proc.stderr
    expect("protect: exit 65", proc.returncode == 65, out)
    expect("protect: the error in the report", len(by_id(lines, VUID)) == 1, str(lines))
    withheld = by_id(lines, WITHHELD)
    expect("protect: two withheld calls in the report (the build, then the submission)",
           [l.get("function") for l in withheld] == ["vkCmdBuildAccelerationStructuresKHR", "vkQueueSubmit"],
           str(withheld))
    expect("protect: each notice names the finding", all(VUID in l.get("message", "") for l in withheld))
    expect("protect: the summary counts the withheld calls",
           "protect: 2 call(s) kept from the driver" in out, out)
    expect("protect: the summary says the command failed, as expected",
           "the command exited with status 1 (expected: protect mode kept 2 call(s) from the driver" in out, out)
    expect("protect: counted in ASVAL-History-Summary",
           any("recorded_commands_withheld=1 submissions_withheld=1 host_commands_withheld=0" in l.get("message", "")
               for l in by_id(lines, "ASVAL-History-Summary")), str(lines))

    # 2. --no-protect: every call goes down (the messenger's VK_TRUE still drops the invalid build): exit 65 on the
    # error alone, the command succeeds, no notice.
    proc, lines = run(args, ["--no-protect"], [args.minimal], "no-protect.jsonl")
    expect("no-protect: exit 65", proc.returncode == 65, proc.stderr)
    expect("no-protect: the error, no notice", len(by_id(lines, VUID)) == 1 and not by_id(lines, WITHHELD), str(lines))
    expect("no-protect: the command succeeded", "the command exited" not in proc.stderr, proc.stderr)

    # 3. Protect on, no messenger: the build is withheld, its command buffer never submitted: one notice.
    proc, lines = run(args, [], [args.minimal, "--no-messenger"], "no-messenger.jsonl")
    expect("no-messenger: exit 65", proc.returncode == 65, proc.stderr)
    expect("no-messenger: one notice", len(by_id(lines, WITHHELD)) == 1, str(lines))

    # 4. No error: the command's own status, whatever protect says.
    proc, lines = run(args, [], ["false"], "false.jsonl")
    expect("a failing command without findings: its own status", proc.returncode == 1, proc.stderr)
    expect("a failing command: FAILED line", "FAILED: the command exited with status 1" in proc.stderr, proc.stderr)
    proc, lines = run(args, [], ["sh", "-c", "kill -TERM $$"], "signal.jsonl")
    expect("a command killed by SIGTERM: 128+15", proc.returncode == 128 + 15, proc.stderr)
    proc, lines = run(args, [], ["true"], "true.jsonl")
    expect("a passing command: 0", proc.returncode == 0 and "asval reported nothing" in proc.stderr, proc.stderr)

    # 5. The summary's capture skips (ASVAL-History-Summary's "capture_skipped" field, one line per device): printed
    # per reason, summed over the devices, zeros left out. The command writes two devices' summary lines into the
    # report itself (the layer's own lines with that field are asserted by tests/integration/capture_skip_test.cpp).
    summaries = [
        {"severity": "info", "vuid": "ASVAL-History-Summary", "function": "vkDestroyDevice", "message": "device 1",
         "capture_skipped": {"over_capture_budget_mb": 2, "unknown_address": 0, "geometry_not_captured": 1}},
        {"severity": "info", "vuid": "ASVAL-History-Summary", "function": "vkDestroyDevice", "message": "device 2",
         "capture_skipped": {"over_capture_budget_mb": 1, "unknown_address": 3, "geometry_not_captured": 0}},
    ]
    write = ("import json, os, sys\n"
             "with open(os.environ['VK_ASVAL_AS_VALIDATION_REPORT_FILE'], 'a') as f:\n"
             "    f.write(sys.argv[1])\n")
    text = "".join(json.dumps(l) + "\n" for l in summaries)
    proc, lines = run(args, [], [sys.executable, "-c", write, text], "skips.jsonl")
    expect("capture skips: the command passes", proc.returncode == 0, proc.stderr)
    expect("capture skips: summed over devices, per reason",
           "capture: 7 build input(s) a rule needed could not be captured, their checks skipped: "
           "over_capture_budget_mb 3, unknown_address 3, geometry_not_captured 1" in proc.stderr, proc.stderr)
    proc, lines = run(args, [], [sys.executable, "-c", write, json.dumps(dict(summaries[0], capture_skipped={
        "over_capture_budget_mb": 0})) + "\n"], "no-skips.jsonl")
    expect("capture skips: none, no line", "capture:" not in proc.stderr, proc.stderr)

    if failures:
        print("%d check(s) failed" % len(failures))
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
