#!/usr/bin/env python3
"""Tests of scripts/asval-run --timeout: the command and its children are ended at the deadline (SIGTERM to its
process group, SIGKILL 5 s later), the report is kept and summarised, the status is 65 when asval reported an error
and 124 otherwise; signals sent to asval-run reach the command's group; bad values are refused (64).

Children are followed by the pid they write to a file, then looked up in /proc: a process still there (not a zombie)
after asval-run returned was not ended. Expectations written by hand; times are bounds loose enough for a loaded
machine, the SIGTERM/SIGKILL distinction is read from the gate's own words.
"""
import argparse
import ctypes
import os
import signal
import subprocess
import sys
import time

from asval_run_test import VUID, by_id, expect, failures, run

GRACE = 5  # asval-run's SIGKILL grace, as its --help states
PR_SET_CHILD_SUBREAPER = 36  # <linux/prctl.h>


def alive(pid):
    """True when pid is a live process (a zombie has ended; it only waits for its parent to read its status)."""
    try:
        with open("/proc/%d/stat" % pid) as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return False


def reap_orphans():
    """Reaps the zombies this process adopted as a subreaper; returns how many."""
    count = 0
    while True:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return count
        if pid == 0:
            return count  # a child still running (none expected): not waited for
        count += 1


def end_survivor(pid):
    """After a failed check: kills the group of a process the gate left running, so the test leaves nothing behind."""
    if pid is not None and alive(pid):
        try:
            os.killpg(os.getpgid(pid), signal.SIGKILL)
        except OSError:
            pass


def read_pid(path, wait=30):
    """The pid a command wrote to path, waiting up to `wait` seconds for it; None when none came."""
    deadline = time.monotonic() + wait
    while True:
        if os.path.exists(path):
            with open(path) as f:
                text = f.read().strip()
            if text:
                return int(text)
        if time.monotonic() >= deadline:
            return None
        time.sleep(0.05)


def default_signals():
    """In asval-run's process: SIGINT and SIGTERM as by default, whatever ctest was started with (a shell's background
    job ignores SIGINT, and the command would inherit that)."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, signal.SIG_DFL)


def timed(args, gate_args, command, report_name):
    started = time.monotonic()
    proc, lines = run(args, gate_args, command, report_name)
    return proc, lines, time.monotonic() - started


def fresh(path):
    if os.path.exists(path):
        os.remove(path)
    return path


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--asval-run", required=True)
    p.add_argument("--layer-path", required=True)
    p.add_argument("--minimal", required=True)
    p.add_argument("--work", required=True)
    args = p.parse_args()

    # 1. Ended before the deadline: as without --timeout (the command now runs in a group of its own): the error,
    # exit 65; a passing command, 0. The first run's time sets the deadline of test 3, which must let
    # minimal_build finish first.
    proc, lines, took = timed(args, ["--timeout", "60"], [args.minimal], "timeout-minimal.jsonl")
    expect("finished in time, an error: exit 65", proc.returncode == 65, proc.stderr)
    expect("finished in time, an error: in the report", len(by_id(lines, VUID)) == 1, str(lines))
    expect("finished in time: no word of the timeout", "--timeout" not in proc.stderr, proc.stderr)
    proc, lines, _ = timed(args, ["--timeout", "60"], ["true"], "timeout-true.jsonl")
    expect("finished in time, passing: exit 0", proc.returncode == 0 and "passed" in proc.stderr, proc.stderr)

    # 2. Runs forever, nothing reported: ended by SIGTERM at the deadline, exit 124, said so.
    proc, lines, took_sleep = timed(args, ["--timeout", "2"], ["sleep", "1000"], "timeout-sleep.jsonl")
    out = proc.stderr
    expect("sleeps forever: exit 124", proc.returncode == 124, out)
    expect("sleeps forever: not ended before the deadline", took_sleep >= 2, "%.1f s" % took_sleep)
    expect("sleeps forever: ended within seconds", took_sleep < 2 + GRACE, "%.1f s" % took_sleep)
    expect("sleeps forever: the gate says the timeout ended it, when and how",
           "FAILED: the command was ended by --timeout after 2 s, with SIGTERM (exit 124)" in out, out)
    expect("sleeps forever: the empty report still summarised", "asval reported nothing" in out, out)

    # 3. An error, then a hang, with a child in the background: exit 65, the report kept, the child ended too.
    pidfile = fresh(os.path.join(args.work, "timeout-child.pid"))
    deadline = "%d" % (5 + 2 * took)
    script = 'sleep 1000 & echo $! > "$1"; "$0"; sleep 1000'
    proc, lines, _ = timed(args, ["--timeout", deadline], ["sh", "-c", script, args.minimal, pidfile],
                           "timeout-hang.jsonl")
    out = proc.stderr
    expect("error then hang: exit 65", proc.returncode == 65, out)
    expect("error then hang: the error kept in the report", len(by_id(lines, VUID)) == 1, str(lines))
    expect("error then hang: the summary names it", VUID in out, out)
    expect("error then hang: the gate says the timeout ended the command",
           "the command was ended by --timeout after %s s, with SIGTERM" % deadline in out, out)
    expect("error then hang: not called expected (the withheld calls did not end it)", "(expected:" not in out, out)
    child = read_pid(pidfile, wait=0)
    expect("error then hang: the background child was started", child is not None)
    expect("error then hang: the background child was ended", child is not None and not alive(child), str(child))
    end_survivor(child)

    # 4. Ignores SIGTERM (inherited by its children): SIGKILL after the grace, exit 124.
    pidfile = fresh(os.path.join(args.work, "timeout-trap.pid"))
    script = "trap '' TERM; echo $$ > \"$0\"; while :; do sleep 0.2; done"
    proc, lines, took_trap = timed(args, ["--timeout", "1"], ["sh", "-c", script, pidfile], "timeout-trap.jsonl")
    out = proc.stderr
    expect("ignores SIGTERM: exit 124", proc.returncode == 124, out)
    expect("ignores SIGTERM: SIGKILL after the grace, said so",
           "FAILED: the command was ended by --timeout after 1 s, with SIGKILL, %d s after SIGTERM (exit 124)" % GRACE
           in out, out)
    expect("ignores SIGTERM: the grace was waited", took_trap >= 1 + GRACE, "%.1f s" % took_trap)
    shell = read_pid(pidfile, wait=0)
    expect("ignores SIGTERM: the shell was ended", shell is not None and not alive(shell), str(shell))
    end_survivor(shell)

    # 5. Signals sent to asval-run reach the command's group (no longer the terminal's): SIGTERM ends the shell and
    # its background child (128+15); SIGINT ends the command (128+2). The report is summarised either way.
    for signum, script in ((signal.SIGTERM, 'sleep 1000 & echo $! > "$0"; wait'),
                           (signal.SIGINT, 'echo $$ > "$0"; exec sleep 1000')):
        name = signal.Signals(signum).name
        pidfile = fresh(os.path.join(args.work, "timeout-%s.pid" % name))
        report = os.path.join(args.work, "timeout-%s.jsonl" % name)
        # Output to a file, not a pipe: a child the gate failed to end would hold a pipe open.
        with open(os.path.join(args.work, "timeout-%s.log" % name), "w+") as log:
            gate = subprocess.Popen([sys.executable, args.asval_run, "--layer-path", args.layer_path, "--report",
                                     report, "--timeout", "60", "--", "sh", "-c", script, pidfile],
                                    stdout=log, stderr=log, preexec_fn=default_signals)
            target = read_pid(pidfile)
            if target is not None:
                time.sleep(0.5)  # asval-run sets its handlers just after starting the command
                gate.send_signal(signum)
            try:
                gate.wait(timeout=30)
            except subprocess.TimeoutExpired:
                gate.kill()
                gate.wait()
            log.seek(0)
            out = log.read()
        expect("%s to asval-run: the command was started" % name, target is not None, out)
        expect("%s to asval-run: exit 128+%d" % (name, signum), gate.returncode == 128 + signum, out)
        expect("%s to asval-run: said so, summary printed" % name,
               "the command was killed by signal %d" % signum in out and "asval reported nothing" in out, out)
        expect("%s to asval-run: the command's process ended" % name, target is not None and not alive(target),
               str(target))
        end_survivor(target)

    # 6. Zombies do not hold the gate. This process becomes a child subreaper, so the command's orphans become its
    # children, and reaps none until asval-run returned: as in a container whose first process reaps no orphan. The
    # background sleep, ended by SIGTERM, stays a zombie in the group; the gate must not wait the grace for it.
    libc = ctypes.CDLL(None, use_errno=True)
    subreaper = libc.prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) == 0
    expect("zombies: this test became a subreaper", subreaper, os.strerror(ctypes.get_errno()))
    if subreaper:
        proc, lines, _ = timed(args, ["--timeout", "1"], ["sh", "-c", "sleep 1000 & wait"], "timeout-zombie.jsonl")
        orphans = reap_orphans()
        libc.prctl(PR_SET_CHILD_SUBREAPER, 0, 0, 0, 0)
        expect("zombies: exit 124", proc.returncode == 124, proc.stderr)
        expect("zombies: ended with SIGTERM, no grace waited for a zombie",
               "was ended by --timeout after 1 s, with SIGTERM (exit 124)" in proc.stderr, proc.stderr)
        expect("zombies: the orphan was there, left to this process", orphans >= 1, str(orphans))

    # 7. Bad values: exit 64 with a message, and the command never runs.
    for value in ("0", "-3", "soon", "nan", "inf"):
        marker = fresh(os.path.join(args.work, "timeout-bad-ran"))
        proc, lines, _ = timed(args, ["--timeout", value], ["touch", marker], "timeout-bad.jsonl")
        expect("--timeout %s: exit 64" % value, proc.returncode == 64, proc.stderr)
        expect("--timeout %s: the message" % value,
               "--timeout wants a positive number of seconds, not '%s'" % value in proc.stderr, proc.stderr)
        expect("--timeout %s: the command did not run" % value, not os.path.exists(marker))

    if failures:
        print("%d check(s) failed" % len(failures))
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
