#!/usr/bin/env python3
"""`mpirun -np 2 simsr datagen --scenario softdeca|face` and `mpirun -np 2 simsr train` (issue #16, a
build with -DSIMSR_WITH_MPI=ON):
the 2-rank run writes the single process's files (every array equal, the wall-clock seconds
aside) and prints its summary once; a rank killed mid-run (SIGKILL) ends the run with every
finished sample file whole, and the same command resumes it to the single process's files; the
face's performances on two ranks, one of them in two chunks of its frames, give the single
process's files; commands that do not
share their work are refused under 2 ranks; training on 2 ranks writes the single process's model
and checkpoint bit for bit, a checkpoint resumes on the other rank count, and a rank killed
mid-training leaves a whole checkpoint that resumes to the uninterrupted run's model.

    /usr/bin/python3 tests/cli/test_cli_mpi.py SIMSR_EXE MPIEXEC WORK_DIR ICT_KIT_DIR

Exit 0: all checks passed; 1: a check failed; 77: numpy is missing (1 with SIMSR_REQUIRE_PEERS=1)."""
import glob
import json
import os
import shutil
import signal
import subprocess
import sys
import time

from checks import check, finish, missing_peer, tool

try:
    import numpy as np
except ImportError as e:
    missing_peer(e)

SIMSR, MPIEXEC, WORK, KIT = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
ENV = {**os.environ, "OMP_NUM_THREADS": "1", "OMPI_MCA_btl_vader_single_copy_mechanism": "none"}
MPIRUN = [MPIEXEC, "-np", "2", "--oversubscribe", "--allow-run-as-root"]
simsr = tool(SIMSR)


def mpirun(*args):
    return subprocess.run([*MPIRUN, SIMSR, *args], capture_output=True, text=True, env=ENV)


def arrays(path):
    with np.load(path, allow_pickle=False) as z:
        return {k: z[k] for k in z.files}


def same_files(a, b, what):
    """Every .npz of folder a equals b's, array for array (`seconds`, wall-clock, aside)."""
    names = sorted(os.path.relpath(f, a) for f in glob.glob(os.path.join(a, "**", "*.npz"), recursive=True))
    check(names and names == sorted(os.path.relpath(f, b) for f in glob.glob(os.path.join(b, "**", "*.npz"), recursive=True)),
          f"{what}: the same .npz files ({len(names)})")
    for n in names:
        x, y = arrays(os.path.join(a, n)), arrays(os.path.join(b, n))
        check(x.keys() == y.keys(), f"{what}: {n}: the same arrays")
        for k in x:
            if k != "seconds" and k in y:
                check(x[k].dtype == y[k].dtype and np.array_equal(x[k], y[k]), f"{what}: {n}: {k} equal")


# 1. two ranks against one process
small = ["datagen", "--scenario", "softdeca", "--template", "sphere", "--sphere-level", "2", "--samples", "6", "--steps", "2"]
simsr(*small, "--out", os.path.join(WORK, "single"))
p = mpirun(*small, "--out", os.path.join(WORK, "ranks"))
check(p.returncode == 0, f"mpirun -np 2 simsr datagen: exit {p.returncode}; stderr: {p.stderr[-600:]}")
lines = [l for l in p.stdout.splitlines() if l.strip()]
check(len(lines) == 1, f"the summary printed once (rank 0), got {len(lines)} lines")
summary = json.loads(lines[0]) if lines else {}
check(summary.get("ranks") == 2 and summary.get("simulated") == 6 and summary.get("kept") == 6, f"summary: {summary.get('ranks')} ranks, "
      f"{summary.get('simulated')} simulated, {summary.get('kept')} kept")
check("softdeca (rank 1 of 2): sample 4/6" in p.stderr, "rank 1's progress lines name it (its block starts at sample 4)")
same_files(os.path.join(WORK, "ranks"), os.path.join(WORK, "single"), "2 ranks vs 1")

# 2. a rank killed mid-run: finished files whole, the rerun resumes to the same files
big = ["datagen", "--scenario", "softdeca", "--template", "sphere", "--sphere-level", "3", "--samples", "6", "--steps", "2"]
killed = os.path.join(WORK, "killed")
run = subprocess.Popen([*MPIRUN, SIMSR, *big, "--out", killed], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV)
first = os.path.join(killed, "samples", "sample_000000.npz")  # rank 0's first sample
deadline = time.time() + 300
while not os.path.exists(first) and run.poll() is None and time.time() < deadline:
    time.sleep(0.05)
ranks = subprocess.run(["pgrep", "-f", "--", f"--out {killed}"], capture_output=True, text=True).stdout.split()
victims = [int(pid) for pid in ranks if int(pid) != run.pid]
check(run.poll() is None and len(victims) >= 1, f"the run was still going when its first sample was written ({len(victims)} rank processes)")
if victims:
    os.kill(victims[-1], signal.SIGKILL)
out, err = run.communicate(timeout=300)
check(run.returncode != 0, f"mpirun ends non-zero when a rank is killed (exit {run.returncode})")
done = sorted(glob.glob(os.path.join(killed, "samples", "sample_*.npz")))
check(0 < len(done) < 6, f"the killed run left {len(done)} of 6 sample files")
for f in done:
    try:
        check("skin" in arrays(f), f"{os.path.basename(f)} whole")
    except Exception as e:  # a torn file: the atomic writes failed their promise
        check(False, f"{os.path.basename(f)} unreadable after the kill: {e}")
check(not os.path.exists(os.path.join(killed, "softdeca_samples.npz")), "no data set written by the killed run")
p = mpirun(*big, "--out", killed)
check(p.returncode == 0, f"the rerun: exit {p.returncode}; stderr: {p.stderr[-600:]}")
resumed = json.loads(p.stdout.strip().splitlines()[-1]) if p.returncode == 0 else {}
check(resumed.get("resumed", 0) >= len(done) and resumed.get("simulated", 0) + resumed.get("resumed", 0) == 6,
      f"the rerun resumed {resumed.get('resumed')} and simulated {resumed.get('simulated')} samples")
simsr(*big, "--out", os.path.join(WORK, "big_single"))
same_files(killed, os.path.join(WORK, "big_single"), "killed and resumed vs 1 process")

# 3. what does not share its work is refused under 2 ranks (every rank alike: nothing hangs)
p = mpirun("datagen", "--scenario", "sheet", "--cells", "3", "--levels", "1", "--sequences", "1", "--out", os.path.join(WORK, "sheet"))
check(p.returncode != 0 and "runs on one process" in p.stderr and "rank 0 of 2" in p.stderr,
      f"datagen --scenario sheet under 2 ranks refused: exit {p.returncode}; {p.stderr[-300:]}")
p = mpirun("info", os.path.join(WORK, "single", "template_skin.obj"))
check(p.returncode != 0 and "simsr info runs on one process" in p.stderr, f"simsr info under 2 ranks refused: exit {p.returncode}")

# 4. data-parallel training: 2 ranks write the single process's model and checkpoint bit for bit,
# and a checkpoint resumes on the other rank count as the uninterrupted run
from test_cli_nn import write_box_pair  # noqa: E402  (the small synthetic pair of the train tests)

tw = os.path.join(WORK, "train")
os.makedirs(tw)
write_box_pair(tw, 4, 7, 12, 5)  # 12 frames: 9 trained on (batches of 3), 3 held out
T = lambda *a: os.path.join(tw, *a)  # noqa: E731
def train_args(batch):
    return ["train", "--lr-rest", T("lr.mesh"), "--hr-rest", T("hr.obj"), "--frames", T("frames.npz"), "--knn", "3", "--upk", "4",
            "--batch-size", str(batch), "--quiet"]


train = train_args(3)


def same_arrays(a, b, what):
    x, y = arrays(a), arrays(b)
    check(x.keys() == y.keys() and len(x) > 10, f"{what}: the same {len(x)} arrays")
    differ = [k for k in x if k in y and not (x[k].dtype == y[k].dtype and x[k].shape == y[k].shape and
                                             (np.array_equal(x[k], y[k]) if x[k].dtype.kind in "OUS" else x[k].tobytes() == y[k].tobytes()))]
    check(not differ, f"{what}: every array equal bit for bit{'' if not differ else ' (differ: ' + ', '.join(differ[:5]) + ')'}")


simsr(*train, "--epochs", "2", "--out", T("single.npz"), "--checkpoint", T("single_ckpt.npz"))
p = mpirun(*train, "--epochs", "2", "--out", T("ranks.npz"), "--checkpoint", T("ranks_ckpt.npz"))
check(p.returncode == 0, f"mpirun -np 2 simsr train: exit {p.returncode}; stderr: {p.stderr[-600:]}")
lines = [l for l in p.stdout.splitlines() if l.strip()]
check(len(lines) == 1 and json.loads(lines[0]).get("ranks") == 2 and json.loads(lines[0]).get("steps") == 6,
      f"the train summary printed once, 2 ranks, 6 steps: {lines[:1]}")
same_arrays(T("ranks.npz"), T("single.npz"), "train: the 2-rank model vs 1 process")
same_arrays(T("ranks_ckpt.npz"), T("single_ckpt.npz"), "train: the 2-rank checkpoint vs 1 process")
p = mpirun(*train, "--epochs", "1", "--out", T("half.npz"), "--checkpoint", T("half_ckpt.npz"))
check(p.returncode == 0, f"mpirun -np 2 simsr train --epochs 1: exit {p.returncode}")
simsr(*train, "--epochs", "2", "--resume", T("half_ckpt.npz"), "--out", T("resumed_on_1.npz"))
same_arrays(T("resumed_on_1.npz"), T("single.npz"), "train: 2 ranks' epoch-1 checkpoint resumed on 1 process vs uninterrupted")
simsr(*train, "--epochs", "1", "--out", T("half1.npz"), "--checkpoint", T("half1_ckpt.npz"))
p = mpirun(*train, "--epochs", "2", "--resume", T("half1_ckpt.npz"), "--out", T("resumed_on_2.npz"))
check(p.returncode == 0, f"mpirun -np 2 simsr train --resume: exit {p.returncode}; {p.stderr[-300:]}")
same_arrays(T("resumed_on_2.npz"), T("single.npz"), "train: 1 process's epoch-1 checkpoint resumed on 2 ranks vs uninterrupted")
# a rank killed mid-training: the checkpoint left is whole (atomic), and --resume from it ends
# with the uninterrupted run's model
long_run = [*train, "--epochs", "20"]
simsr(*long_run, "--out", T("long_single.npz"))
ckpt = T("killed_ckpt.npz")
run = subprocess.Popen([*MPIRUN, SIMSR, *long_run, "--out", T("killed.npz"), "--checkpoint", ckpt], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, text=True, env=ENV)
deadline, epoch = time.time() + 300, 0
while run.poll() is None and time.time() < deadline and epoch < 3:
    time.sleep(0.05)
    try:
        epoch = int(arrays(ckpt)["train/epoch"]) if os.path.exists(ckpt) else 0
    except Exception:  # noqa: BLE001  (only the rename makes it appear: never torn)
        epoch = -1
        break
victims = [int(pid) for pid in subprocess.run(["pgrep", "-f", "--", f"--out {T('killed.npz')}"], capture_output=True,
                                              text=True).stdout.split() if int(pid) != run.pid]
check(run.poll() is None and epoch >= 3 and victims, f"training still going at checkpoint epoch {epoch} ({len(victims)} rank processes)")
if victims:
    os.kill(victims[-1], signal.SIGKILL)
run.communicate(timeout=300)
check(run.returncode != 0 and not os.path.exists(T("killed.npz")), f"the killed run ends non-zero (exit {run.returncode}), no model written")
z = arrays(ckpt)
left = int(z["train/epoch"])
check(3 <= left < 20, f"the checkpoint left is whole: epoch {left}")
p = mpirun(*long_run, "--resume", ckpt, "--out", T("killed_resumed.npz"))
check(p.returncode == 0, f"mpirun -np 2 simsr train --resume after the kill: exit {p.returncode}; {p.stderr[-300:]}")
same_arrays(T("killed_resumed.npz"), T("long_single.npz"), f"train: killed at epoch {left}, resumed on 2 ranks vs uninterrupted on 1")

p = mpirun(*train_args(4), "--epochs", "1", "--out", T("x.npz"))
check(p.returncode != 0 and "end with a batch of 1" in p.stderr and "simsr (rank " in p.stderr,
      f"batches of 4 (the last of 1 frame) refused on 2 ranks, naming it: exit {p.returncode}; {p.stderr[-300:]}")

# 5. the face over 2 ranks on the coarse model: a 1-frame performance whole (fewer frames than
# chunks) and a 2-frame one in 2 chunks (--chunks 2) after a 1-frame lead-in, which reaches frame 0
# (so every frame is the single process's, bitwise). Units jaw, smile[0,1) | smile[1,2): rank 0
# the first two, rank 1 the third, so smile's chunks are simulated on different ranks.
if not (os.path.exists(os.path.join(KIT, "full_neutral.obj")) and shutil.which("tetgen")):
    missing_peer(f"the ICT kit ({KIT}) or the tetgen program")
for name, weights in (("smile", [[0.3, 0.3], [0.6, 0.6]]), ("jaw", [[0.3]])):  # few frames: the HR solves are the cost
    names = ["mouthSmile_L", "mouthSmile_R"] if name == "smile" else ["jawOpen"]
    np.savez(os.path.join(WORK, f"{name}_controls.npz"), names=np.array(names), weights=np.array(weights))
def face_args(*performances):
    controls = [a for name in performances for a in ("--controls", os.path.join(WORK, f"{name}_controls.npz"))]
    return ["datagen", "--scenario", "face", "--kit", KIT, "--performances", "", *controls, "--lr-cell", "2", "--skull-lattice", "1.6",
            "--hr-max-volume", "1", "--vtk-every", "0", "--no-unseen-forces"]


face = face_args("jaw", "smile")
p = mpirun(*face, "--chunks", "2", "--chunk-overlap", "1", "--out", os.path.join(WORK, "face_ranks"))
check(p.returncode == 0, f"mpirun -np 2 simsr datagen --scenario face --chunks 2: exit {p.returncode}; stderr: {p.stderr[-600:]}")
lines = [l for l in p.stdout.splitlines() if l.strip()]
summary = json.loads(lines[0]) if len(lines) == 1 else {}
check(summary.get("ranks") == 2 and summary.get("chunks_per_performance") == 2 and summary.get("chunk_overlap") == 1,
      f"the face summary printed once, with its ranks and chunks: {lines[:1]}")
perf = {q["name"]: q for q in summary.get("performances", [])}
check(perf.get("smile", {}).get("chunks") == 2 and perf["smile"].get("lead_in_frames_solved") == 1 and perf["smile"].get("simulated") == 2,
      f"smile: 2 chunks, 1 lead-in frame, 2 frames simulated, added over the ranks: {perf.get('smile')}")
check(perf.get("jaw", {}).get("simulated") == 1 and "chunks" not in perf["jaw"], f"jaw: one frame, whole: {perf.get('jaw')}")
rank1 = [l for l in p.stderr.splitlines() if l.endswith("(rank 1 of 2)")]
check(any(l.startswith("datagen: smile      lead-in    1/2") for l in rank1) and any(l.startswith("datagen: smile      frame    2/2") for l in rank1)
      and not any(l.startswith("datagen: jaw") for l in rank1), "rank 1's progress lines: smile's lead-in and its second frame, no jaw")
check(not glob.glob(os.path.join(WORK, "face_ranks", ".state", "smile.chunk*")), "the chunk parts removed once assembled")
# the single process, smile whole, from the ranks' settled neutral (its fingerprint matches: read,
# not solved again; each HR solve is ~20 s here)
alone = os.path.join(WORK, "face_single")
os.makedirs(os.path.join(alone, ".state"))
shutil.copy(os.path.join(WORK, "face_ranks", ".state", "neutral.npz"), os.path.join(alone, ".state", "neutral.npz"))
simsr(*face_args("smile"), "--out", alone)
x, y = arrays(os.path.join(WORK, "face_ranks", "smile.npz")), arrays(os.path.join(alone, "smile.npz"))
check(x.keys() - y.keys() == {"chunk_first_frames", "chunk_overlap"} and not y.keys() - x.keys(), f"smile: the chunked file's arrays: {sorted(x.keys())}")
check(list(x.get("chunk_first_frames", [])) == [0, 1] and int(x.get("chunk_overlap", -1)) == 1, "smile: its chunks recorded")
check(all(np.array_equal(x[k], y[k]) for k in y), "face: smile.npz of 2 ranks in 2 chunks = the single process's, every array bitwise")
for name in ("smile_controls.npz", "hr_lips.npz"):
    x, y = arrays(os.path.join(WORK, "face_ranks", name)), arrays(os.path.join(alone, name))
    check(x.keys() == y.keys() and all(np.array_equal(x[k], y[k]) for k in x), f"face: {name} of 2 ranks = the single process's")
p = mpirun(*face, "--chunks", "-1", "--out", os.path.join(WORK, "face_bad"))
check(p.returncode != 0 and "--chunks" in p.stderr, f"--chunks -1 refused, naming it: {p.stderr[-300:]}")

finish()
