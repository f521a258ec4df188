#!/usr/bin/env python3
"""The `simsr` tool when an output cannot be written: /dev/full (a full disk), a missing folder, a
regular file used as a folder, a write that fails midway (a file-size limit: EFBIG) and a writer
killed inside write(2) (SIGXFSZ at the limit) each end with a non-zero exit and a message naming
the file, and leave the previous file byte for byte as it was. Every failure here binds for root
too; an unwritable folder (mode 0555) is checked as well when not running as root. Needs no peer.

    /usr/bin/python3 tests/cli/test_cli_write_errors.py SIMSR_EXE TMP_DIR

Exit 0: all checks passed; 1: a check failed."""
import os
import resource
import shutil
import signal
import stat
import struct
import subprocess
import sys

from checks import check, finish

EXE, TMP = sys.argv[1], sys.argv[2]
MESH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "io", "cube_meshio.mesh")
EXIT_FILE = 2  # ParseError / WriteError (examples/simsr/errors.hpp)

shutil.rmtree(TMP, ignore_errors=True)
os.makedirs(TMP)


def limited(size, ignore_sigxfsz):
    """preexec_fn: files may not grow beyond `size` bytes; SIGXFSZ ignored (write fails with EFBIG)
    or left to its default action (the process is killed inside the write); no core file."""
    def f():
        resource.setrlimit(resource.RLIMIT_CORE, (0, resource.getrlimit(resource.RLIMIT_CORE)[1]))
        resource.setrlimit(resource.RLIMIT_FSIZE, (size, resource.getrlimit(resource.RLIMIT_FSIZE)[1]))
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN if ignore_sigxfsz else signal.SIG_DFL)
    return f


def run(*args, preexec=None, stdout=subprocess.PIPE):
    p = subprocess.run([EXE, *args], stdout=stdout, stderr=subprocess.PIPE, text=True, timeout=120, preexec_fn=preexec)
    return p.returncode, p.stderr.strip()


def temporaries(folder):
    return [n for n in os.listdir(folder) if n.startswith(".") and n.endswith(".simsr-tmp")]


def failed(what, rc, err, file, reason):
    check(rc == EXIT_FILE, f"{what}: exit {EXIT_FILE} (got {rc}: {err})")
    check(file in err, f"{what}: the message names {file} ({err})")
    check(reason in err, f"{what}: the message says '{reason}' ({err})")


def write_npy(path, rows):
    """A float64 N×3 .npy, written by hand (no numpy needed)."""
    header = "{'descr': '<f8', 'fortran_order': False, 'shape': (%d, 3), }" % len(rows)
    header += " " * (63 - (10 + len(header)) % 64) + "\n"
    with open(path, "wb") as f:
        f.write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode())
        for r in rows:
            f.write(struct.pack("<3d", *r))


# A good write: the file, and nothing else in the folder.
ok = os.path.join(TMP, "ok.mesh")
rc, err = run("convert", MESH, ok)
check(rc == 0 and os.path.getsize(ok) > 16, f"convert to .mesh exits 0 ({rc}: {err})")
check(sorted(os.listdir(TMP)) == ["ok.mesh"], f"no temporary file left ({os.listdir(TMP)})")
with open(ok, "rb") as f:
    before = f.read()

# /dev/full behind a name with the format's extension, and /dev/full itself for a .npz output.
full = os.path.join(TMP, "full.vtu")
os.symlink("/dev/full", full)
rc, err = run("convert", MESH, full)
failed("convert to a link to /dev/full", rc, err, full, "No space left on device")
check(stat.S_ISCHR(os.stat("/dev/full").st_mode), "/dev/full is still a device")
os.remove(full)
points = os.path.join(TMP, "points.npy")
write_npy(points, [(0, 0, 0), (1, 0, 0), (0, 1, 0)])
rc, err = run("knn", "--points", points, "--queries", points, "--k", "1", "--out", "/dev/full")
failed("knn --out /dev/full", rc, err, "/dev/full", "No space left on device")

# The JSON on stdout: a full stdout is an error too.
with open("/dev/full", "w") as devfull:
    rc, err = run("info", MESH, stdout=devfull)
failed("info > /dev/full", rc, err, "<stdout>", "No space left on device")

# A missing folder, a regular file as the folder.
missing = os.path.join(TMP, "missing", "out.msh")
rc, err = run("convert", MESH, missing)
failed("convert into a missing folder", rc, err, missing, "No such file or directory")
check(not os.path.exists(os.path.dirname(missing)), "the missing folder is not created")
plain = os.path.join(TMP, "plain")
with open(plain, "w") as f:
    f.write("a regular file")
under = os.path.join(plain, "out.mesh")
rc, err = run("convert", MESH, under)
failed("convert into a file used as a folder", rc, err, under, "Not a directory")
os.remove(plain)
os.remove(points)

# An unwritable folder binds only when not root.
if os.geteuid() != 0:
    ro = os.path.join(TMP, "readonly")
    os.mkdir(ro, 0o555)
    rc, err = run("convert", MESH, os.path.join(ro, "out.msh"))
    failed("convert into a folder of mode 0555", rc, err, os.path.join(ro, "out.msh"), "Permission denied")
    check(os.listdir(ro) == [], "nothing written into the unwritable folder")
    os.chmod(ro, 0o755)
    os.rmdir(ro)

# A write that fails midway: the previous file is kept, no temporary left.
rc, err = run("convert", MESH, ok, preexec=limited(16, True))
failed("convert over ok.mesh with a 16-byte file-size limit", rc, err, ok, "File too large")
with open(ok, "rb") as f:
    check(f.read() == before, "ok.mesh is byte-identical after the failed write")
check(sorted(os.listdir(TMP)) == ["ok.mesh"], f"no temporary file left after the failure ({os.listdir(TMP)})")

# A writer killed inside write(2): the previous file is kept; only its hidden temporary remains.
rc, err = run("convert", MESH, ok, preexec=limited(16, False))
check(rc == -signal.SIGXFSZ, f"the writer is killed by SIGXFSZ at the limit (got {rc}: {err})")
with open(ok, "rb") as f:
    check(f.read() == before, "ok.mesh is byte-identical after the killed write")
temps = temporaries(TMP)
check(len(temps) == 1 and temps[0].startswith(".ok.mesh."), f"the killed writer's temporary file is all that is left ({os.listdir(TMP)})")
for t in temps:
    check(os.path.getsize(os.path.join(TMP, t)) == 16, "it holds what was written before the kill")
    os.remove(os.path.join(TMP, t))
rc, err = run("info", ok)
check(rc == 0, f"the kept ok.mesh still reads ({rc}: {err})")

finish()
