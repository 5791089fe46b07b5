#!/usr/bin/python3
"""The Snakemake sweep (scripts/sweep/Snakefile) runs locally end to end on a tiny case and
its table is right. Exits 77 (skipped) when snakemake is not installed (it is optional:
`apt-get install snakemake`).
usage: sweep_test.py SEAMLESS_BINARY SOURCE_DIR WORK_DIR

The case: the synthetic room recorded for 6 frames (`seamless record`, exact ground truth), tracked
with the ground-truth tracker and with ICP, through a sweep file given with --configfile (which must
replace the default sweep's sequences and configs, not add to them). Checks against truth:
- one table row per sequence x config x tracker, each with every frame paired for evaluation;
- the ground-truth tracker's ATE is 0 up to rounding: trajectories are written with 7 decimals in
  metres (src/io/trajectory.cpp, 5e-8 m), and poses are float32 (2.4e-7 m at the room's ~2 m) moved
  through a few tens of operations (gravity levelling, world change, alignment), so 1e-4 m
  (0.01 cm) is a bound with a wide margin that any real tracking error (millimetres) exceeds;
- ICP's ATE is finite and below 5 cm, a loose sanity bound (not a quality goal): 6 frames of the
  orbit move the camera about 1.5 cm, and a tracker that diverged lands decimetres off.
"""
import csv
import math
import os
import shutil
import subprocess
import sys

FRAMES = 6


def main():
    exe, src, work = sys.argv[1], sys.argv[2], sys.argv[3]
    snakemake = shutil.which("snakemake")
    if not snakemake:
        print("snakemake is not installed (apt-get install snakemake): skipped")
        return 77
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    out = os.path.join(work, "out")
    sweep = os.path.join(work, "sweep.yaml")
    with open(sweep, "w") as f:
        f.write(f"seamless: {exe}\nout: {out}\ndevice: cpu\nframes: {FRAMES}\n"
                "sequences:\n  room: synthetic\n"
                "trackers: [ground_truth, icp]\ntracker_modes: [frame_to_model]\n"
                f"configs:\n  demo: {os.path.join(src, 'configs', 'demo.yaml')}\n")
    # --directory keeps snakemake's .snakemake/ state in the work folder, not in the source tree.
    subprocess.run([snakemake, "-s", os.path.join(src, "scripts", "sweep", "Snakefile"), "--cores", "2",
                    "--directory", work, "--configfile", sweep], check=True, timeout=600)
    with open(os.path.join(out, "table.csv")) as f:
        rows = {r["tracker"]: r for r in csv.DictReader(f)}
    assert set(rows) == {"ground_truth frame_to_model", "icp frame_to_model"}, f"table rows: {sorted(rows)}"
    for name, r in rows.items():
        assert r["sequence"] == "room" and r["config"] == "demo", r
        assert int(r["pairs"]) == FRAMES, f"{name}: {r['pairs']} of {FRAMES} frames evaluated"
    gt = float(rows["ground_truth frame_to_model"]["ate_rmse_cm"])
    icp = float(rows["icp frame_to_model"]["ate_rmse_cm"])
    print(f"ATE rmse: ground truth {gt:.4f} cm, icp {icp:.3f} cm")
    assert gt <= 0.01, "the ground-truth tracker's trajectory does not match the ground truth"
    assert math.isfinite(icp) and icp < 5.0, "ICP diverged on the synthetic room"
    assert os.path.getsize(os.path.join(out, "table.md")) > 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
