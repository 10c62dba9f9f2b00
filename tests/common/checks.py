"""The Python tests' checks, as tests/common/check.h is the C tests': check()
records a condition (printing what failed), fail() stops the test at once,
and the test's main ends with `return checks.summary(name)`.

A test imports it from tests/common next to its own folder:
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
    import checks
"""
import sys

failures = []  # what failed, in order
verbose = False  # print "ok: <what>" for the checks that pass too


def check(ok, what):
    """Records one check; prints "FAIL: <what>" when ok is false. Returns ok."""
    if ok:
        if verbose:
            print("ok:", what, flush=True)
    else:
        failures.append(what)
        print("FAIL:", what, flush=True)
    return ok


def fail(what):
    """A failure the test cannot go on after: prints it and exits 1."""
    print("FAIL:", what, flush=True)
    sys.exit(1)


def summary(name):
    """Prints "<name>: <n> failure(s)" and returns the exit code (0: none failed)."""
    print(f"{name}: {len(failures)} failure(s)", flush=True)
    return 1 if failures else 0
