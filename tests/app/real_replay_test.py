#!/usr/bin/env python3
"""The Kinect view of a scan-then-simulate run on real frames shows the recording.

configs/real/tum_desk.yaml on the first 12 frames of ../shared/data/tum_fr1_rpy_000-149 (ground-truth
poses, so the test costs no tracking; no undistortion, so the view is the raw PNG), rendered headless
at 320x240 with Mesa:
- render.camera: fixed: every output frame is the first recorded image (before, the view was black);
- render.camera: recorded: output frame k is recorded frame k (it matches frame k better than the
  frames three before or after it: the hand-held rpy camera turns several degrees per frame), there
  is one output frame per recorded frame, and the virtual objects are in the picture.
A rendered pixel differs from the recorded one by resampling (640x480 to 320x240) and where the
virtual objects cover it; the median over the image ignores the objects, and resampling a real
image changes its median pixel by a few grey levels, so 12 levels separate "the same image" from
"another image" (neighbouring rpy frames differ by 20-60 in their median).

Usage: real_replay_test.py SEAMLESS ROOT DATA OUT; exit 77 (skip) without the data folder or a GL build.
"""
import json
import os
import shutil
import subprocess
import sys

import numpy as np
from PIL import Image

W, H, N = 320, 240, 12


def recorded_frames(folder):
    names = []
    for line in open(os.path.join(folder, "rgb.txt")):
        if not line.startswith("#") and line.strip():
            names.append(line.split()[1])
    return [np.asarray(Image.open(os.path.join(folder, n)).convert("RGB").resize((W, H), Image.BILINEAR), float)
            for n in names[:N + 3]]


def median_diff(a, b):
    return float(np.median(np.abs(a - b).mean(axis=2)))


def run(exe, root, folder, out, camera):
    shutil.rmtree(out, ignore_errors=True)
    cmd = [exe, "run", os.path.join(root, "configs/real/tum_desk.yaml"), "--device", "cpu", "--out", out,
           "--set", f"input.path={folder}", "--set", f"frames={N}", "--set", "tracker.kind=ground_truth",
           "--set", "input.undistort=false", "--set", f"render.camera={camera}", "--set", f"render.width={W}",
           "--set", f"render.height={H}", "--set", "render.video=false", "--set", "duration=0.3"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        print(r.stdout[-3000:], r.stderr[-3000:])
    if "no renderer" in r.stderr + r.stdout:
        sys.exit(77)
    assert r.returncode == 0, f"seamless run ({camera}) failed with {r.returncode}"
    frames = sorted(f for f in os.listdir(os.path.join(out, "frames")) if f.endswith(".png"))
    return [np.asarray(Image.open(os.path.join(out, "frames", f)).convert("RGB"), float) for f in frames]


def main():
    exe, root, data, out = sys.argv[1:5]
    folder = os.path.join(data, "tum_fr1_rpy_000-149")
    if not os.path.isdir(folder):
        print(f"skip: {folder} not found")
        return 77
    rec = recorded_frames(folder)

    fixed = run(exe, root, folder, os.path.join(out, "fixed"), "fixed")
    assert fixed, "no frames rendered"
    for k, f in enumerate(fixed):
        d = median_diff(f, rec[0])
        assert d < 12, f"fixed camera: output frame {k} is not the first recorded image (median difference {d:.1f})"
    print(f"fixed: {len(fixed)} frames, each the first recorded image")

    replay = run(exe, root, folder, os.path.join(out, "recorded"), "recorded")
    assert len(replay) == N, f"recorded camera: {len(replay)} output frames for {N} recorded frames"
    for k, f in enumerate(replay):
        same = median_diff(f, rec[k])
        others = [median_diff(f, rec[j]) for j in (k - 3, k + 3) if 0 <= j < len(rec)]
        assert same < 12 and all(same < o for o in others), \
            f"output frame {k}: median difference {same:.1f} to recorded frame {k}, {others} to frames k-3/k+3"
    # The objects are drawn: some pixels of the last frame differ strongly from the recording.
    s = json.load(open(os.path.join(out, "recorded", "summary.json")))
    assert s["particles"]["dynamic"] > 0
    changed = (np.abs(replay[-1] - rec[N - 1]).mean(axis=2) > 40).mean()
    assert changed > 0.001, f"no virtual object visible in the last frame ({changed:.4%} of pixels changed)"
    print(f"recorded: {len(replay)} frames, frame k = recorded frame k; objects cover {changed:.2%} of the last")
    return 0


if __name__ == "__main__":
    sys.exit(main())
