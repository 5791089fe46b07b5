#!/usr/bin/python3
"""A real Kinect v1 recording made by libfreenect's fakenect-record (../shared/data/kinect_v1_planes:
raw 11-bit disparity, colour, accelerometer, device.json) through `seamless track` twice: read
directly (input.source: fakenect) and replayed by Debian's fakenect library into the live Kinect
source (input.source: kinect, FAKENECT_PATH, LD_LIBRARY_PATH; render.camera: fixed, since a live
source cannot be replayed after the scan; a queue that holds the whole recording, since fakenect
replays at 30 Hz and a slower tracker would otherwise see the live source drop frames). Both register depth with the same
code and pair colour and accelerometer records by the same rule, so they must give the same
trajectory; the camera stood still on a table, so every pose must stay near the identity and no
frame may be lost.

Tolerances: the two runs see the same frames (tests/io/test_fakenect.cpp checks that), so their
poses differ only by the order of OpenMP's floating-point reductions: 1e-4 m and 1e-4 (rotation
matrix entries) leave two orders of magnitude of room and are a tenth of a voxel. Static camera: the
people in front of it move their hands and heads; the tracked pose must stay within 1 cm and 0.5
degrees of the first frame.

usage: kinect_fakenect_test.py SEAMLESS SOURCE_DIR DATA_DIR OUT FAKENECT_LIB_DIR; exit 77 (skip)
without the data folder or without fakenect's library (apt-get install libfreenect-bin).
"""
import csv
import math
import os
import shutil
import subprocess
import sys

FRAMES = 4


def read_tum(path):
    with open(path) as f:
        return [[float(x) for x in l.split()] for l in f if l.strip() and not l.startswith("#")]


def rotation(q):
    x, y, z, w = q
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def track(exe, root, out, extra, env=None):
    shutil.rmtree(out, ignore_errors=True)
    cmd = [exe, "track", os.path.join(root, "configs/real/kinect_v1_planes.yaml"), "--device", "cpu", "--out", out,
           "--set", f"input.max_frames={FRAMES}", *extra]
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=600)
    if "has no libfreenect" in r.stderr:
        print("skipped the fakenect half: this build has no libfreenect (apt-get install libfreenect-dev)")
        sys.exit(77)
    if r.returncode != 0:
        print(" ".join(cmd), "\n", r.stdout[-3000:], r.stderr[-3000:])
    assert r.returncode == 0, f"seamless track exited {r.returncode}"
    return read_tum(os.path.join(out, "trajectory.txt")), r.stderr + r.stdout


def main():
    exe, root, data, out, lib = sys.argv[1:6]
    planes = os.path.join(data, "kinect_v1_planes")
    if not os.path.isdir(planes):
        print(f"skipped: no {planes}")
        return 77
    direct, log = track(exe, root, os.path.join(out, "direct"), ["--set", f"input.path={planes}"])
    assert "stored little-endian" in log, log[-2000:]
    assert len(direct) == FRAMES, f"direct reader: {len(direct)} poses for {FRAMES} frames"
    with open(os.path.join(out, "direct", "tracking_stats.csv")) as f:
        status = [row["status"] for row in csv.DictReader(f)]
    assert status == ["ok"] * FRAMES, f"frames not tracked: {status}"
    r0 = rotation(direct[0][4:8])
    for p in direct:
        dt = math.dist(p[1:4], direct[0][1:4])
        r = rotation(p[4:8])
        trace = sum(r[i][k] * r0[i][k] for i in range(3) for k in range(3))
        angle = math.degrees(math.acos(max(-1.0, min(1.0, (trace - 1) / 2))))
        print(f"frame at {p[0]:.3f}: {100 * dt:.2f} cm, {angle:.3f} deg from the first")
        assert dt < 0.01 and angle < 0.5, "the static camera moved"
    if not os.path.exists(os.path.join(lib, "libfreenect.so.0.5")):
        print(f"skipped the fakenect half: no fakenect library in {lib} (apt-get install libfreenect-bin)")
        return 77
    env = dict(os.environ, FAKENECT_PATH=planes, LD_LIBRARY_PATH=lib)
    replay, log = track(exe, root, os.path.join(out, "fakenect"), ["--set", "input.source=kinect",
                                                                     "--set", "input.path=",
                                                                     "--set", "render.camera=fixed",
                                                                     "--set", "input.kinect.queue_size=64"], env)
    assert "raw 11-bit disparity" in log, log[-2000:]
    assert len(replay) == FRAMES, f"fakenect: {len(replay)} poses for {FRAMES} frames"
    worst_t = worst_r = 0.0
    for a, b in zip(direct, replay):
        worst_t = max(worst_t, math.dist(a[1:4], b[1:4]))
        ra, rb = rotation(a[4:8]), rotation(b[4:8])
        worst_r = max(worst_r, max(abs(ra[i][k] - rb[i][k]) for i in range(3) for k in range(3)))
    print(f"direct against fakenect: largest position difference {worst_t:.2e} m, rotation entry {worst_r:.2e}")
    assert worst_t < 1e-4 and worst_r < 1e-4, "the two paths tracked differently"
    print("ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
