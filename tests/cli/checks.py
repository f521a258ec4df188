"""The CLI tests' assertion counter: check() records and prints a failure without stopping the
script, finish() prints the tally and exits 0 (all passed) or 1."""
import sys

failures = []
count = 0


def check(cond, what):
    global count
    count += 1
    if not cond:
        failures.append(what)
        print("FAIL:", what)


def finish():
    print(f"{count - len(failures)}/{count} checks passed")
    sys.exit(1 if failures else 0)
