"""The CLI tests' assertion counter: check() records and prints a failure without stopping the
script, finish() prints the tally and exits 0 (all passed) or 1; missing_peer() ends a script
whose peer (a Python package, a tool's optional component) is absent."""
import os
import subprocess
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


def missing_peer(reason):
    """A peer is missing: a failure under SIMSR_REQUIRE_PEERS=1 (the README test command, CI) or
    after a failed check, otherwise exit 77 (ctest's skip: the checks so far passed, the rest
    could not run)."""
    print(f"MISSING (a failure under SIMSR_REQUIRE_PEERS=1, a skip otherwise): {reason}")
    required = os.environ.get("SIMSR_REQUIRE_PEERS", "0") not in ("", "0")
    sys.exit(1 if required or failures else 77)


def tool(exe):
    """A runner of the executable: run(*args, expect=0) checks that it exits 0 (expect=0) or
    non-zero (any other expect), the stderr tail in the failure, and returns the process."""
    def run(*args, expect=0):
        p = subprocess.run([exe, *args], capture_output=True, text=True)
        ok = p.returncode == 0 if expect == 0 else p.returncode != 0
        check(ok, f"{os.path.basename(exe)} {' '.join(args)}: exit {p.returncode}, expected {'0' if expect == 0 else 'non-zero'}; "
                  f"stderr: {p.stderr.strip()[-400:]}")
        return p
    return run
