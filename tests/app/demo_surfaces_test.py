#!/usr/bin/python3
"""In configs/demo.yaml no fluid may fall through the desk top (fluid poured on the desk
fell through desk areas the scan never saw), end inside it, or end below the floor. Runs the demo
on the CPU without pictures, saving the particles every 5 steps, and follows every fluid particle.
usage: demo_surfaces_test.py SEAMLESS_BINARY SOURCE_DIR [RUN_DIR]   (RUN_DIR: check a finished run
made with output.particles_every set)

Bounds (tracker world of the demo: gravity -y, metres; configs/demo.yaml explains the frame):
- heights come from the run itself: the floor plane's from the log, the desk top's as the median
  height of the scene particles over the desk, so the camera's shake (a few cm) does not matter;
- a fluid particle resting on a surface has its centre a radius r above it, and contacts compress
  by well under a radius: a centre more than d = 2r below the surface has gone into or through it;
- "over the desk" is its 1.4 x 0.7 m top (kernels/scene/synthetic_room.hpp, moved to the first
  camera) shrunk by 0.1 m a side: the world's yaw is off by up to ~2 degrees (5.6 cm at 1.6 m);
- a crossing is a particle over the desk and above desk - d in one snapshot and over the desk
  below desk - d in the next, 0.05 s later: fluid spilling over an edge moves well under the
  0.1 m margin in that time (~0.5 m/s), so it is not counted, while a particle that spread
  under the desk on the floor was never above the top there.
"""
import glob
import os
import re
import struct
import subprocess
import sys
import tempfile

import yaml

FLUID = 1 << 24
DESK_X = (-0.7, 0.7)       # room x of the desk top = world x (the first camera looks along room +y)
DESK_Z = (1.25, 1.95)      # room y 0.25..0.95; the first camera stands at room y = -1.0
MARGIN = 0.1
THICKNESS = 0.04           # of the desk top


def read_ply(path):
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    n = int(re.search(rb"element vertex (\d+)", data[:end]).group(1))
    rec = [struct.unpack_from("<6fI", data, end + 28 * i) for i in range(n)]
    return [r[0:3] for r in rec], [r[6] for r in rec]


def over_desk(p):
    return DESK_X[0] + MARGIN < p[0] < DESK_X[1] - MARGIN and DESK_Z[0] + MARGIN < p[2] < DESK_Z[1] - MARGIN


def snapshots(run):
    files = glob.glob(os.path.join(run, "particles_*.ply"))
    return [read_ply(f) for f in sorted(files, key=lambda f: int(re.search(r"_(\d+)\.ply$", f).group(1)))]


def check(run):
    with open(os.path.join(run, "config.yaml")) as f:
        d = yaml.safe_load(f)["solver"]["particle_diameter"]  # 2r
    with open(os.path.join(run, "log.txt")) as f:
        m = re.search(r"floor plane at height (-?[\d.]+) m", f.read())
    assert m, "no floor plane in the log"
    floor = float(m.group(1))  # height along -gravity = (0, 1, 0): the plane's y
    scene, _ = read_ply(os.path.join(run, "scene_particles.ply"))
    top = sorted(p[1] for p in scene if over_desk(p) and -0.7 < p[1] < -0.5)
    assert top, "no scene particles on the desk top"
    desk = top[len(top) // 2]
    snaps = snapshots(run)
    assert len(snaps) > 10, "run with --set output.particles_every=5"
    crossed = set()
    for (x0, ph0), (x1, _) in zip(snaps, snaps[1:]):
        for i, (a, b) in enumerate(zip(x0, x1)):
            if ph0[i] & FLUID and over_desk(a) and over_desk(b) and a[1] >= desk - d > b[1]:
                crossed.add(i)
    x, ph = read_ply(os.path.join(run, "particles.ply"))
    fluid = [p for p, f in zip(x, ph) if f & FLUID]
    below_floor = sum(p[1] < floor - d for p in fluid)
    inside_desk = sum(over_desk(p) and desk - THICKNESS - d < p[1] < desk - d for p in fluid)
    on_desk = sum(over_desk(p) and p[1] >= desk - d for p in fluid)
    print(f"{len(fluid)} fluid particles: {len(crossed)} fell through the desk top (y = {desk:.3f}), {inside_desk} "
          f"end inside it, {on_desk} on it, {below_floor} below the floor (y = {floor:.3f})")
    return len(fluid), len(crossed), inside_desk, below_floor


def main():
    exe, src = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory() as tmp:
        run = sys.argv[3] if len(sys.argv) > 3 else os.path.join(tmp, "demo")
        if len(sys.argv) <= 3:
            subprocess.run([exe, "run", os.path.join(src, "configs", "demo.yaml"), "--device", "cpu", "--out", run,
                            "--set", "render.mode=none", "--set", "output.particles_every=5"], check=True, timeout=1500)
        n, crossed, inside, below = check(run)
    assert n > 0, "the demo spawned no fluid"
    assert crossed == 0 and inside == 0 and below == 0, "fluid went into or through the desk top or the floor"


if __name__ == "__main__":
    main()
