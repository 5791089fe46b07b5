#!/usr/bin/python3
"""`seamless run` with render.mode: window: under a virtual X server (xvfb-run) the run
opens the GLFW window, which drives the simulation, and --window-frames closes it after N frames
with exit code 0; without a display it says so and renders headless instead.
usage: window_run_test.py SEAMLESS_BINARY SOURCE_DIR. Exits 77 (skipped) without GLFW or xvfb-run."""
import glob
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import yaml

EXE, SRC = sys.argv[1], sys.argv[2]
SKIP = 77


def tiny_config(d, mode="scan_then_simulate"):
    """The demo, shrunk: 6 scanned frames on a coarse volume, one small fluid block, a small window."""
    with open(os.path.join(SRC, "configs", "demo.yaml")) as f:
        cfg = yaml.safe_load(f)
    cfg["mode"] = mode
    cfg["frames"] = 6
    cfg["volume"].update({"voxel_size": 0.02, "truncation": 0.08})
    cfg["spawn"] = [{"kind": "fluid_block", "position": [-0.35, -0.3, 1.55], "size": [0.12, 0.12, 0.12]}]
    cfg["render"] = {"mode": "window", "width": 160, "height": 90}
    path = os.path.join(d, f"tiny_{mode}.yaml")
    with open(path, "w") as f:
        yaml.safe_dump(cfg, f)
    return path


def run(args, env=None, xvfb=True):
    cmd = [EXE, "run", *args, "--device", "cpu"]
    if xvfb:  # -a: a free display number; the screen is larger than the window
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 640x480x24", *cmd]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=env)
    return r, r.stdout + r.stderr


class WindowRun(unittest.TestCase):
    def check_window(self, out, text, frames):
        if "this build has no GLFW" in text or "no renderer" in text:
            raise unittest.SkipTest("this build has no window front end")
        self.assertNotIn("rendering headless", text)
        self.assertIn(f"window closed after {frames} frames", text)
        self.assertTrue(os.path.getsize(os.path.join(out, "particles.ply")) > 0)
        self.assertEqual(glob.glob(os.path.join(out, "frames", "*.png")), [])  # shown, not written

    def test_scan_then_simulate_closes_after_n_frames(self):
        # 0.5 s at dt 0.01 is 50 steps, 3 a frame at 30 fps (render.fps): 8 frames stop it early (24 steps).
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "run")
            r, text = run([tiny_config(d), "--out", out, "--set", "duration=0.5", "--window-frames", "8"])
            self.assertEqual(r.returncode, 0, text)
            self.check_window(out, text, 8)
            self.assertIn("before the run was complete", text)
            self.assertRegex(text, r"stopped after 24 of 5[01] steps")  # ceil(0.5 / 0.01f): 50 or 51

    def test_window_stays_open_after_the_run(self):
        # 0.06 s is 6 steps, done after 2 frames; the window stays until frame 5 closes it.
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "run")
            r, text = run([tiny_config(d), "--out", out, "--set", "duration=0.06", "--window-frames", "5"])
            self.assertEqual(r.returncode, 0, text)
            self.check_window(out, text, 5)
            self.assertIn("the run is complete", text)
            self.assertNotIn("before the run was complete", text)

    def test_live_mode(self):
        # One input frame per shown frame: 6 frames, all tracked, then 2 more shown.
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "run")
            r, text = run([tiny_config(d, "live"), "--out", out, "--window-frames", "8"])
            self.assertEqual(r.returncode, 0, text)
            self.check_window(out, text, 8)
            with open(os.path.join(out, "trajectory.txt")) as t:
                self.assertEqual(len([l for l in t if l.strip() and not l.startswith("#")]), 6)

    def test_no_display_falls_back_to_headless(self):
        env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "run")
            r, text = run([tiny_config(d), "--out", out, "--set", "duration=0.06", "--set", "render.write_frames=true"],
                          env=env, xvfb=False)
            self.assertEqual(r.returncode, 0, text)
            if "this build has no GLFW" in text:
                raise unittest.SkipTest("this build has no window front end")
            self.assertIn("no window can be opened: no display", text)
            self.assertGreater(len(glob.glob(os.path.join(out, "frames", "*.png"))), 0)


if __name__ == "__main__":
    if shutil.which("xvfb-run") is None:
        print("xvfb-run is not installed (apt-get install xvfb): skipped")
        sys.exit(SKIP)
    if "render" not in subprocess.run([EXE, "bench", "--list"], capture_output=True, text=True).stdout:
        print("this build has no renderer (GL module off): skipped")
        sys.exit(SKIP)
    sys.argv[1:] = []
    unittest.main()
