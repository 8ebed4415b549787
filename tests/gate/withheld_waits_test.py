#!/usr/bin/env python3
"""The gate never hangs on a withheld submission (issue 26): scripts/asval-run over a program that ignores
vkQueueSubmit's VK_ERROR_VALIDATION_FAILED_EXT and then waits without a timeout for the withheld submission's fence,
for its binary semaphore through a next submission, for its timeline value on the host and for the device to go idle
(asval_integration_tests "[withheld-waits-child]", tests/integration/protect_synchronization_test.cpp). It must end on
its own with exit 65 (asval reported the update's error) well within this test's time, the report holding the error
and the withheld submission's notice. The expectations are written by hand.
"""
import argparse
import json
import os
import signal
import subprocess
import sys
import time

VUID = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03762"
WITHHELD = "ASVAL-Protect-Withheld"
LIMIT_S = 60  # the child takes about a second on lavapipe; a hang would take for ever


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--asval-run", required=True)
    p.add_argument("--layer-path", required=True)
    p.add_argument("--tests", required=True, help="asval_integration_tests")
    p.add_argument("--work", required=True)
    args = p.parse_args()
    report = os.path.join(args.work, "withheld-waits.jsonl")
    cmd = [sys.executable, args.asval_run, "--layer-path", args.layer_path, "--report", report, "--",
           args.tests, "[withheld-waits-child]"]
    start = time.monotonic()
    # Its own session: should it hang, the gate and the program under it are ended together.
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        stdout, stderr = proc.communicate(timeout=LIMIT_S)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        print("FAIL the gate did not end within %d s: the app was left waiting on a withheld submission" % LIMIT_S)
        return 1
    elapsed = time.monotonic() - start
    lines = []
    if os.path.exists(report):
        with open(report) as f:
            lines = [json.loads(line) for line in f if line.strip()]
    failures = []

    def expect(name, condition, detail=""):
        print("%s %s" % ("ok  " if condition else "FAIL", name))
        if not condition:
            failures.append(name)
            if detail:
                print(detail)

    expect("exit 65 within %d s (took %.1f s)" % (LIMIT_S, elapsed), proc.returncode == 65,
           "exit %d\n%s\n%s" % (proc.returncode, stdout[-3000:], stderr[-3000:]))
    expect("the update's error in the report", any(l.get("vuid") == VUID for l in lines), str(lines)[:3000])
    withheld = [l for l in lines if l.get("vuid") == WITHHELD]
    expect("one withheld submission, whose batches went down empty",
           len(withheld) == 1 and "its batches went down empty" in withheld[0].get("message", ""), str(withheld))
    expect("the app's own waits all returned (its test passed)", "All tests passed" in stdout, stdout[-3000:])
    if failures:
        print("%d check(s) failed" % len(failures))
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
