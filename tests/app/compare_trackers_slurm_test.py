#!/usr/bin/python3
"""Scripts/compare_trackers on a Slurm cluster, with the exact command docs/REPRODUCE.md
gives (snakemake 7's --slurm executor), against a stand-in Slurm: sbatch, sacct, srun and sacctmgr
are small scripts in front of PATH that run each submitted job on this machine in the background
and report its state the way Slurm's commands print it. It checks what this repository controls:
that every (sequence, tracker) cell is submitted as its own sbatch job with the partition, account,
run time, memory and CPUs asked for, that the cells' jobs run `seamless track` and `seamless eval`
through the workflow, and that the tables come out right. (Whether a real cluster accepts the
same sbatch lines is Slurm's business; snakemake's executor writes them.)

usage: compare_trackers_slurm_test.py SEAMLESS SOURCE_DIR DATA_DIR WORK_DIR
Exit 77 (ctest: skipped) without snakemake or without the shared TUM excerpt.

Against truth: 40 frames of freiburg1_rpy (the least needed for the 1 s RPE), tracked by the
ground-truth tracker (which replays groundtruth.txt at the images' time stamps: its ATE against the
same file is the interpolation error between the ground truth's 100 Hz samples, well below 1 mm,
so 0.1 cm is a bound any tracking error exceeds) and by ICP frame to frame, the cheapest tracker that
runs a real cell (a sanity bound of 10 cm:
the camera rolls through about 20 degrees in these 40 frames, and a diverged ICP lands decimetres
off; docs/TRACKING.md has the quality figures).
"""
import json
import os
import shutil
import stat
import subprocess
import sys
import time

SKIP = 77
SEQ = "tum_fr1_rpy_000-149"
FRAMES = 40
PARTITION, ACCOUNT = "fakegpu", "fakelab"

# One script, installed under each Slurm command's name; it dispatches on the name it was called by.
FAKE_SLURM = r'''#!/usr/bin/python3
import os, subprocess, sys
state = os.environ["FAKE_SLURM_STATE"]
name = os.path.basename(sys.argv[0])
args = sys.argv[1:]
with open(os.path.join(state, "calls.txt"), "a") as f:
    f.write(name + "\t" + "\t".join(args) + "\n")
if name == "sbatch":
    wrap = next(a[len("--wrap="):] for a in args if a.startswith("--wrap="))
    log = args[args.index("-o") + 1]
    cwd = args[args.index("-D") + 1]
    with open(os.path.join(state, "next_id"), "a+") as f:
        f.seek(0)
        jid = int(f.read() or 1000) + 1
        f.seek(0); f.truncate(); f.write(str(jid))
    log = os.path.join(cwd, log.replace("%j", str(jid)))
    os.makedirs(os.path.dirname(log), exist_ok=True)
    env = dict(os.environ, SLURM_JOB_ID=str(jid), SLURM_CPUS_ON_NODE="2")
    rc = os.path.join(state, f"{jid}.rc")
    subprocess.Popen(["/bin/sh", "-c", wrap + f"; echo $? > {rc}.tmp; mv {rc}.tmp {rc}"], cwd=cwd, env=env,
                     stdout=open(log, "w"), stderr=subprocess.STDOUT, start_new_session=True)
    print(f"Submitted batch job {jid}")
elif name == "sacct":
    jid = args[args.index("-j") + 1]
    rc = os.path.join(state, f"{jid}.rc")
    st = "RUNNING" if not os.path.exists(rc) else "COMPLETED" if open(rc).read().strip() == "0" else "FAILED"
    print(f"{jid}|{st}")
elif name == "srun":
    while args and args[0].startswith("-"):
        args.pop(0)
    os.execvp(args[0], args)
elif name == "sacctmgr":
    print("  " + os.environ["FAKE_SLURM_ACCOUNT"])
else:
    sys.exit(f"fake slurm: {name} not faked")
'''


def install_fake_slurm(work):
    bindir, state = os.path.join(work, "fake_slurm_bin"), os.path.join(work, "fake_slurm_state")
    os.makedirs(bindir)
    os.makedirs(state)
    script = os.path.join(bindir, "fake_slurm")
    with open(script, "w") as f:
        f.write(FAKE_SLURM)
    os.chmod(script, os.stat(script).st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
    for cmd in ("sbatch", "sacct", "srun", "sacctmgr", "scontrol"):
        os.symlink(script, os.path.join(bindir, cmd))
    return bindir, state


def main():
    seamless, src, data, work = sys.argv[1:5]
    if not shutil.which("snakemake"):
        print("SKIP: snakemake is not installed (apt-get install snakemake)")
        return SKIP
    seq = os.path.join(data, SEQ)
    if not os.path.isdir(seq):
        print(f"SKIP: {seq} is absent (shared test data)")
        return SKIP
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    bindir, state = install_fake_slurm(work)
    env = dict(os.environ, PATH=bindir + os.pathsep + os.environ["PATH"], FAKE_SLURM_STATE=state,
               FAKE_SLURM_ACCOUNT=ACCOUNT, USER=os.environ.get("USER", "ci"))
    out = os.path.join(work, "out")
    # The documented command (docs/REPRODUCE.md), plus a faster status poll than snakemake's 30 s.
    cmd = [sys.executable, os.path.join(src, "scripts", "compare_trackers"), seq, "--seamless", seamless,
           "--out", out, "--kinds", "ground_truth,icp", "--modes", "frame_to_frame", "--no-ceres",
           "--frames", str(FRAMES), "--device", "cpu", "--no-plots",
           "--slurm", "--jobs", "4", "--default-resources", f"slurm_partition={PARTITION}",
           f"slurm_account={ACCOUNT}", "--snakemake-arg=--max-status-checks-per-second=1"]
    print(" ".join(cmd), flush=True)
    t0 = time.monotonic()
    subprocess.run(cmd, check=True, env=env, timeout=900)
    print(f"took {time.monotonic() - t0:.0f} s")

    calls = [l.rstrip("\n").split("\t") for l in open(os.path.join(state, "calls.txt"))]
    sbatch = [c[1:] for c in calls if c[0] == "sbatch"]
    print(f"{len(sbatch)} sbatch calls, {sum(c[0] == 'srun' for c in calls)} srun calls")
    # one job per cell; the aggregate job is a local rule and runs on the submitting machine
    assert len(sbatch) == 2, f"expected 2 sbatch calls (one per cell), got {len(sbatch)}: {sbatch}"
    for a in sbatch:
        line = " ".join(a)
        for want in (f"-p {PARTITION}", f"-A {ACCOUNT}", "-t 60", "--mem 8000", "--cpus-per-task=4"):
            assert want in line, f"sbatch call lacks '{want}': {line}"
        assert "snakejob" in line and "cell" in line, f"not a cell job: {line}"
    assert sum(c[0] == "srun" for c in calls) == 2, "each job runs its cell through srun"

    with open(os.path.join(out, "results.json")) as f:
        rows = {r["tracker"]: r for r in json.load(f)}
    assert set(rows) == {"ground_truth", "icp f2frame"}, f"rows: {sorted(rows)}"
    for name, r in rows.items():
        assert r["status"] == "ok", f"{name}: {r['status']}"
        assert r["frames"] == FRAMES and r["lost"] == 0, f"{name}: {r['lost']} of {r['frames']} lost"
        assert r["pairs"] == FRAMES, f"{name}: {r['pairs']} of {FRAMES} poses evaluated"
        print(f"{name}: ATE {100 * r['ate_rmse_m']:.3f} cm")
    assert rows["ground_truth"]["ate_rmse_m"] < 0.001, "the ground-truth tracker does not replay the ground truth"
    assert rows["icp f2frame"]["ate_rmse_m"] < 0.10, "ICP diverged"
    for f in ("trackers.md", "trackers.tex"):
        assert os.path.getsize(os.path.join(out, f)) > 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
