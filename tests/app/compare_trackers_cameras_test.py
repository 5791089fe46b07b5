#!/usr/bin/python3
"""Scripts/compare_trackers gives every sequence its own camera's intrinsics and config
instead of freiburg1's for all, and refuses a folder whose camera it cannot tell unless --preset
names it. A dry run (snakemake -n: nothing is tracked) over three folders made here, each holding
only a groundtruth.txt, is enough: the choices are in OUT/grid.json and each cell's spec.json.

usage: compare_trackers_cameras_test.py SEAMLESS SOURCE_DIR WORK_DIR
Exit 77 (ctest: skipped) without snakemake. A few seconds.
"""
import json
import os
import shutil
import subprocess
import sys

SKIP = 77


def folder(work, name, calibration=False):
    d = os.path.join(work, "data", name)
    os.makedirs(d)
    with open(os.path.join(d, "groundtruth.txt"), "w") as f:
        f.write("# timestamp tx ty tz qx qy qz qw\n1.0 0 0 0 0 0 0 1\n")
    if calibration:
        with open(os.path.join(d, "calibration.txt"), "w") as f:
            f.write("600 600 320 240 640 480 0 0 0 0 0\n")
    return d


def compare(src, seamless, out, seqs, *extra):
    cmd = [sys.executable, os.path.join(src, "scripts", "compare_trackers"), *seqs, "--seamless", seamless,
           "--out", out, "--kinds", "icp", "--modes", "frame_to_model", "--no-ceres", "-n", *extra]
    return subprocess.run(cmd, capture_output=True, text=True)


def main():
    seamless, src, work = sys.argv[1:4]
    if not shutil.which("snakemake"):
        print("SKIP: snakemake is not installed (compare_trackers runs its grid through it)")
        return SKIP
    shutil.rmtree(work, ignore_errors=True)
    fr2 = folder(work, "rgbd_dataset_freiburg2_desk")
    fr3 = folder(work, "tum_fr3_office")
    recorded = folder(work, "my_recording", calibration=True)
    unknown = folder(work, "living_room")

    out = os.path.join(work, "out")
    r = compare(src, seamless, out, [fr2, fr3, recorded])
    print(r.stdout + r.stderr)
    assert r.returncode == 0, "dry run failed"
    grid = json.load(open(os.path.join(out, "grid.json")))
    want = {"rgbd_dataset_freiburg2_desk": ("freiburg2", "tum_fr2.yaml"),
            "tum_fr3_office": ("freiburg3", "tum_fr3.yaml"),
            "my_recording": ("auto", "tum_fr1.yaml")}  # auto: the run reads calibration.txt
    for name, (preset, config) in want.items():
        cam = grid["cameras"][name]
        assert cam["intrinsics"] == preset, f"{name}: preset {cam['intrinsics']}, expected {preset}"
        assert os.path.basename(cam["config"]) == config, f"{name}: config {cam['config']}, expected {config}"
        spec = json.load(open(os.path.join(out, name, "icp_f2model", "spec.json")))
        assert spec["intrinsics"] == preset and os.path.basename(spec["config"]) == config, spec
    assert "calibration.txt" in grid["cameras"]["my_recording"]["intrinsics_why"]

    r = compare(src, seamless, os.path.join(work, "out2"), [fr2, unknown])
    print(r.stdout + r.stderr)
    assert r.returncode != 0, "a folder whose camera cannot be told was accepted"
    assert "cannot tell the camera of" in r.stderr and "--preset" in r.stderr, r.stderr

    # Named by the user: every sequence gets that preset; --config names one file for all.
    one = os.path.join(src, "configs", "tum_fr1.yaml")
    r = compare(src, seamless, os.path.join(work, "out3"), [fr2, unknown], "--preset", "kinect_v1", "--config", one)
    print(r.stdout + r.stderr)
    assert r.returncode == 0, "--preset did not make the unknown folder acceptable"
    grid = json.load(open(os.path.join(work, "out3", "grid.json")))
    for name in ("rgbd_dataset_freiburg2_desk", "living_room"):
        assert grid["cameras"][name]["intrinsics"] == "kinect_v1", grid["cameras"][name]
        assert grid["cameras"][name]["config"] == os.path.abspath(one)
    print("cameras chosen per sequence; unknown camera refused without --preset")
    return 0


if __name__ == "__main__":
    sys.exit(main())
