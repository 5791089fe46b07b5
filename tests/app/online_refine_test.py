#!/usr/bin/python3
"""Online refinement (refine.online) on 30 real frames of tum_fr1_rpy_150-299 (frames the
tracker was not tuned on), CPU, `seamless track` with configs/tum_fr1.yaml:
- default (refine.online off, the offline stage off too): today's outputs, no online files;
- online: trajectory.txt (the final online graph's) no worse than the odometry's ATE, solves done
  in the background, and the tracking thread's handover never as long as a keyframe's background work.
usage: online_refine_test.py SEAMLESS_BINARY SOURCE_DIR DATA_DIR
Exits 77 (skipped) when the real data is absent; registered only in builds with Ceres."""
import csv
import json
import os
import subprocess
import sys
import tempfile
import unittest

from tum_subset import tum_subset

EXE, SRC, DATA = sys.argv[1], sys.argv[2], sys.argv[3]
TUM = os.path.abspath(os.path.join(DATA, "tum_fr1_rpy_150-299"))
CFG = os.path.join(SRC, "configs", "tum_fr1.yaml")
FRAMES = 30  # 1 s of fr1_rpy: 6 keyframes at the config's keyframe_every 5, enough for loop edges
STATS_HEADER = ("frame,timestamp,status,fused,inlier_ratio,inliers,residual_rms,condition,iterations,"
                "translation_jump_m,rotation_jump_deg,preprocess_ms,track_ms,fuse_ms,frame_ms")


def track(seq, out, *sets):
    args = [EXE, "track", CFG, "--device", "cpu", "--out", out, "--set", f"input.path={seq}",
            "--set", "refine.enabled=false"]
    for s in sets:
        args += ["--set", s]
    r = subprocess.run(args, capture_output=True, text=True, timeout=600)
    if r.returncode != 0:
        raise AssertionError(f"{' '.join(args)} exited {r.returncode}:\n{r.stderr}")
    return r


def ate(out, name="trajectory.txt"):
    j = os.path.join(out, name + ".ate.json")
    r = subprocess.run([EXE, "eval", os.path.join(out, "groundtruth.txt"), os.path.join(out, name), "--json", j],
                       capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        raise AssertionError(f"seamless eval exited {r.returncode}:\n{r.stderr}")
    with open(j) as f:
        return json.load(f)["ate_rmse_m"]


def poses(path):
    with open(path) as f:
        return [l for l in f if l.strip() and not l.startswith("#")]


class OnlineRefine(unittest.TestCase):
    def test_default_off_and_online(self):
        with tempfile.TemporaryDirectory() as d:
            seq = os.path.join(d, "seq")
            tum_subset(TUM, seq, FRAMES)
            off, on = os.path.join(d, "off"), os.path.join(d, "on")
            track(seq, off)
            # Default off: the outputs of a run without the online refinement, unchanged.
            for name in ["trajectory_live.txt", "trajectory_odometry.txt", "online_refine_stats.csv"]:
                self.assertFalse(os.path.exists(os.path.join(off, name)), name)
            with open(os.path.join(off, "tracking_stats.csv")) as f:
                self.assertEqual(f.readline().strip(), STATS_HEADER)
            self.assertEqual(len(poses(os.path.join(off, "trajectory.txt"))), FRAMES)

            r = track(seq, on, "refine.online=true")
            for name in ["trajectory.txt", "trajectory_live.txt", "trajectory_odometry.txt"]:
                self.assertEqual(len(poses(os.path.join(on, name))), FRAMES, name)
            with open(os.path.join(on, "online_refine_stats.csv")) as f:
                s = {row["key"]: row["value"] for row in csv.DictReader(f)}
            self.assertEqual(int(s["keyframes"]), FRAMES // 5)  # frames 0, 5, ..., 25
            self.assertGreaterEqual(int(s["solves"]), 1)
            self.assertGreater(int(s["pair_edges"]), 0)
            # The tracking thread never waited for the background: had it waited for a solve, its
            # longest handover would be at least one keyframe's background work (pyramid, pair
            # alignments, Ceres); it is a copy of the frame and a pointer swap.
            self.assertLess(float(s["handover_ms_max"]), 1000 * float(s["keyframe_s_median"]))
            self.assertIn("online refinement:", r.stderr + r.stdout)
            odometry, online = ate(off), ate(on)
            # No worse than the odometry alone, within one frame's tracking error of our tracker on
            # these frames (RPE/frame 0.39 cm, docs/TRACKING.md): when solutions arrive
            # depends on thread timing, so the online result is not bit-reproducible, but a graph
            # that made the trajectory worse by more than one frame's error would fail here.
            self.assertLessEqual(online, odometry + 0.004, f"online {online:.4f} m, odometry {odometry:.4f} m")
            print(f"ATE odometry {100 * odometry:.2f} cm, online {100 * online:.2f} cm; "
                  f"live {100 * ate(on, 'trajectory_live.txt'):.2f} cm; handover max {s['handover_ms_max']} ms, "
                  f"keyframe median {s['keyframe_s_median']} s, {s['solves']} solves")


if __name__ == "__main__":
    if not os.path.isdir(TUM):
        print(f"skipped: {TUM} is absent")
        sys.exit(77)
    unittest.main(argv=[sys.argv[0]] + sys.argv[4:])
