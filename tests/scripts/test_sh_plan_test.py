#!/usr/bin/env python3
"""Tests of scripts/test.sh's choice of builds: the normal build alone by default, all four with --all,
ASVAL_TEST_BUILDS exact when set (with or without --all), ctest arguments let through, a bad name refused.
Run through `--plan`, which prints the builds and exits before installing or building anything."""
import os
import subprocess
import sys

failures = []


def plan(script, args, builds=None):
    env = dict(os.environ)
    env.pop("ASVAL_TEST_BUILDS", None)
    if builds is not None:
        env["ASVAL_TEST_BUILDS"] = builds
    proc = subprocess.run(["bash", script, "--plan"] + args, env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True, timeout=30)
    return proc.returncode, proc.stdout.strip(), proc.stderr


def expect(name, got, want):
    ok = got == want
    print("%s %s" % ("ok  " if ok else "FAIL", name))
    if not ok:
        print("  got %r, want %r" % (got, want))
        failures.append(name)


def main():
    script = sys.argv[1]
    expect("default: the normal build only", plan(script, [])[:2], (0, "normal"))
    expect("--all: the four builds", plan(script, ["--all"])[:2], (0, "normal asan tsan fuzz"))
    expect("--all found among ctest arguments", plan(script, ["-R", "gate", "--all", "-V"])[:2],
           (0, "normal asan tsan fuzz"))
    expect("ASVAL_TEST_BUILDS picks, run in the fixed order", plan(script, [], "fuzz normal")[:2],
           (0, "normal fuzz"))
    expect("ASVAL_TEST_BUILDS wins over --all", plan(script, ["--all"], "tsan")[:2], (0, "tsan"))
    status, out, err = plan(script, [], "normal asna")
    expect("a misspelt build: status 2", (status, out), (2, ""))
    expect("a misspelt build: the message names it and the builds",
           "names 'asna'; the builds are: normal asan tsan fuzz" in err, True)
    expect("ASVAL_TEST_BUILDS set to blanks: status 2", plan(script, [], " ")[0], 2)
    if failures:
        print("%d check(s) failed" % len(failures))
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
