#!/usr/bin/python3
"""scripts/step_bias against a trajectory built with a known bias: the ground truth turns 1 degree a
frame about the camera's y axis while moving 10 mm a frame forward; the estimate turns 0.95 of each
step and adds 1 mm along the earlier frame's x to each step's translation. The script must report
rotation scale 0.950, translation scale 1.000 (the added 1 mm is orthogonal to the 10 mm forward
step) and a mean translation error of (1, 0, 0) mm; the printed values have 3 and 2 decimals, so
a tolerance of one unit in the last printed place.
usage: step_bias_test.py SOURCE_DIR WORK_DIR"""
import os
import re
import subprocess
import sys

import numpy as np


def rot_y(deg):
    a = np.radians(deg)
    return np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])


def quat(R):
    w = np.sqrt(max(1e-12, 1 + R[0, 0] + R[1, 1] + R[2, 2])) / 2
    return [(R[2, 1] - R[1, 2]) / (4 * w), (R[0, 2] - R[2, 0]) / (4 * w), (R[1, 0] - R[0, 1]) / (4 * w), w]


def write(path, stamps, poses):
    with open(path, "w") as f:
        for t, M in zip(stamps, poses):
            f.write(f"{t:.6f} " + " ".join(f"{v:.9f}" for v in list(M[:3, 3]) + quat(M[:3, :3])) + "\n")


def trajectory(n, deg, extra):
    M, out = np.eye(4), [np.eye(4)]
    for _ in range(n - 1):
        S = np.eye(4)
        S[:3, :3], S[:3, 3] = rot_y(deg), np.array([0.0, 0.0, 0.010]) + extra
        M = M @ S
        out.append(M.copy())
    return out


def main():
    src, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    n = 30
    stamps = [1.0 + i / 30 for i in range(n)]
    # The ground truth brackets every estimate's time stamp (the script interpolates inside it).
    # Its pose k + 1 is at stamps[k], moved so that both start at the same pose.
    gt = trajectory(n + 2, 1.0, np.zeros(3))
    est = trajectory(n, 0.95, np.array([0.001, 0.0, 0.0]))
    write(os.path.join(work, "est.txt"), stamps, est)
    write(os.path.join(work, "gt.txt"), [stamps[0] - 1 / 30] + stamps + [stamps[-1] + 1 / 30],
          [np.linalg.inv(gt[1]) @ g for g in gt])
    out = subprocess.run(["/usr/bin/python3", os.path.join(src, "scripts", "step_bias"), os.path.join(work, "gt.txt"),
                          os.path.join(work, "est.txt")], check=True, capture_output=True, text=True).stdout
    print(out)
    m = re.search(r"all: +rotation scale ([\d.]+), translation scale ([\d.]+); mean error t \[([^\]]+)\] mm", out)
    assert m, "no 'all:' line"
    rot, trans = float(m.group(1)), float(m.group(2))
    t = [float(v) for v in m.group(3).split()]
    assert out.count("frame pairs") == 1 and f"{n - 1} frame pairs" in out, "every pair evaluated"
    assert abs(rot - 0.95) <= 0.001, f"rotation scale {rot}, built 0.95"
    assert abs(trans - 1.0) <= 0.001, f"translation scale {trans}, built 1.0"
    assert abs(t[0] - 1.0) <= 0.01 and abs(t[1]) <= 0.01 and abs(t[2]) <= 0.01, f"mean error {t} mm, built (1, 0, 0)"
    return 0


if __name__ == "__main__":
    sys.exit(main())
