#!/usr/bin/python3
"""Reliability: exit codes that tell the truth, runs stopped by Ctrl-C or by a bad
frame keep what they computed, an output folder holds one run, and limits that used to act
silently are reported. Each test is one way a run used to fail.
usage: reliability_test.py SEAMLESS_BINARY SOURCE_DIR DATA_DIR"""
import csv
import glob
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

from tum_subset import tum_subset

EXE, SRC, DATA = sys.argv[1], sys.argv[2], sys.argv[3]
TUM = os.path.abspath(os.path.join(DATA, "tum_fr1_rpy_000-149"))
DEMO = os.path.join(SRC, "configs", "demo.yaml")
TUM_CFG = os.path.join(SRC, "configs", "tum_fr1.yaml")
# README, "Exit codes and interrupted runs"
USAGE, CONFIG, INPUT, LOST, SIGINT_CODE = 2, 4, 5, 6, 130


def seamless(*args, timeout=900):
    return subprocess.run([EXE, *args], capture_output=True, text=True, timeout=timeout)


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def poses(path):
    with open(path) as f:
        return [l for l in f if l.strip() and not l.startswith("#")]


def list_lines(path):
    with open(path) as f:
        return [l.split() for l in f if l.strip() and not l.startswith("#")]


def interrupt_when(cmd, ready, timeout=300, group=False):
    """Starts cmd, sends SIGINT once ready() is true (polled), returns (returncode, stderr).
    group: to cmd's whole process group, as a Ctrl-C in a terminal does (its children too)."""
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=group)
    t0 = time.monotonic()
    while not ready():
        if p.poll() is not None:
            out, err = p.communicate()
            raise AssertionError(f"{' '.join(cmd)} ended before it was interrupted ({p.returncode}):\n{err}")
        if time.monotonic() - t0 > timeout:
            p.kill()
            raise AssertionError(f"{' '.join(cmd)}: never got ready to be interrupted")
        time.sleep(0.05)
    if group:
        os.killpg(p.pid, signal.SIGINT)
    else:
        p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=600)
    return p.returncode, err


def count_poses(path):
    try:
        return len(poses(path))
    except OSError:
        return 0


def tum_copy(dest, frames, corrupt_depth_of=None):
    """The first `frames` associated pairs of the real fr1_rpy folder; frame `corrupt_depth_of`'s
    depth PNG replaced by its first 200 bytes (a truncated file)."""
    def truncated(i, src, out):
        if i == corrupt_depth_of:
            with open(src, "rb") as f, open(out, "wb") as g:
                g.write(f.read(200))
        return i == corrupt_depth_of
    tum_subset(TUM, dest, frames, truncated)


def track_tum(path, out, *sets):
    """configs/tum_fr1.yaml on the CPU, without the optional Ceres refinement."""
    args = ["track", TUM_CFG, "--device", "cpu", "--out", out, "--set", f"input.path={path}",
            "--set", "refine.enabled=false"]
    for s in sets:
        args += ["--set", s]
    return args


class ExitCodes(unittest.TestCase):
    def test_help_lists_the_codes(self):
        out = seamless("--help").stdout
        for text in ["Exit codes", "4 config error", "5 input error", "output.max_lost_fraction", "130"]:
            self.assertIn(text, out)

    def test_bad_usage_is_2_and_config_error_is_4(self):
        self.assertEqual(seamless("run", DEMO, "--no-such-option").returncode, USAGE)
        r = seamless("run", DEMO, "--dry-run", "--set", "volume.voxel_sise=0.01")
        self.assertEqual(r.returncode, CONFIG, r.stderr)
        self.assertIn("did you mean 'voxel_size'", r.stderr)
        # Regression: one --set that cannot be applied hid the file's other errors; all are listed now.
        with tempfile.TemporaryDirectory() as d:
            bad = os.path.join(d, "bad.yaml")
            with open(bad, "w") as f:
                f.write("name: x\nvolume:\n  voxel_sise: 0.01\ntracker:\n  kindd: icp\n")
            r = seamless("run", bad, "--dry-run", "--set", "name.first=x")
            self.assertEqual(r.returncode, CONFIG, r.stderr)
            for text in ["3 problems", "bad.yaml:3:3: volume.voxel_sise", "bad.yaml:5:3: tracker.kindd",
                         "(from --set name.first=x)"]:
                self.assertIn(text, r.stderr)

    @unittest.skipUnless(os.path.isdir(TUM), f"no test data at {TUM}")
    def test_wrong_depth_scale_loses_frames_and_says_so(self):
        # Regression: 9 of 10 frames lost at depth_scale 1000 (TUM is 5000), exit 0. The median depth of
        # 6 m passes the reader's 0.2-10 m plausibility check. The depth-scale check (the Kinect's
        # disparity steps) now stops it as a config error naming the right scale; with that
        # check off, tracking is what tells, and the lost frames give their own exit code. Frame to
        # model: depth five times too far falls beyond volume.max_depth, the model stays empty and the
        # frames are lost (frame to frame, configs/tum_fr1.yaml's tracker, tracks the
        # scaled room consistently and loses nothing; only the depth-scale check can tell there).
        fm = "tracker.mode=frame_to_model"
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "trk")
            r = seamless(*track_tum(TUM, out, "frames=10", "input.depth_scale=1000"))
            self.assertEqual(r.returncode, CONFIG, r.stderr)
            self.assertIn("set input.depth_scale: 5000", r.stderr)
            r = seamless(*track_tum(TUM, out, "frames=10", "input.depth_scale=1000", "input.check_depth_scale=false", fm),
                         "--force")
            self.assertEqual(r.returncode, LOST, r.stderr)
            self.assertIn("more than output.max_lost_fraction = 0.2", r.stderr)
            self.assertIn("input.depth_scale", r.stderr)
            stats = rows(os.path.join(out, "tracking_stats.csv"))
            self.assertEqual(len(stats), 10)  # the outputs are written all the same
            self.assertGreater(sum(s["status"] != "ok" for s in stats), 2)
            # The threshold is the key's: at 1 the same run passes.
            r = seamless(*track_tum(TUM, out, "frames=10", "input.depth_scale=1000", "input.check_depth_scale=false", fm,
                                    "output.max_lost_fraction=1"), "--force")
            self.assertEqual(r.returncode, 0, r.stderr)

    @unittest.skipUnless(os.path.isdir(TUM), f"no test data at {TUM}")
    def test_zero_tracker_iterations_lose_every_frame(self):
        # Regression: tracker.iterations [0,0,0] lost every frame but the first, exit 0.
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "trk")
            r = seamless(*track_tum(TUM, out, "frames=10", "tracker.iterations=[0,0,0]"))
            self.assertEqual(r.returncode, LOST, r.stderr)
            stats = rows(os.path.join(out, "tracking_stats.csv"))
            self.assertEqual([s["status"] == "ok" for s in stats], [True] + [False] * 9)


class Interrupted(unittest.TestCase):
    def test_record_stopped_by_ctrl_c_loads(self):
        # Regression: the lists were written only at the end; a stopped recording did not load.
        with tempfile.TemporaryDirectory() as d:
            room = os.path.join(d, "room")
            code, err = interrupt_when(
                [EXE, "record", "--source", "synthetic", "--out", room, "--frames", "300", "--device", "cpu"],
                lambda: count_poses(os.path.join(room, "rgb.txt")) >= 3)
            self.assertEqual(code, SIGINT_CODE, err)
            rgb = list_lines(os.path.join(room, "rgb.txt"))
            self.assertGreaterEqual(len(rgb), 3)
            self.assertLess(len(rgb), 300)
            for name in ["depth.txt", "associations.txt", "groundtruth.txt"]:
                self.assertEqual(len(list_lines(os.path.join(room, name))), len(rgb), name)
            self.assertEqual(len(glob.glob(os.path.join(room, "depth", "*.png"))), len(rgb))
            self.assertEqual(glob.glob(os.path.join(room, "*.partial")), [])
            # It loads: every frame is read (ground-truth poses: no tracking needed).
            out = os.path.join(d, "trk")
            r = seamless("track", DEMO, "--device", "cpu", "--out", out, "--set", "input.source=tum",
                         "--set", f"input.path={room}", "--set", "input.intrinsics.preset=auto",
                         "--set", "tracker.kind=ground_truth")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertEqual(len(poses(os.path.join(out, "trajectory.txt"))), len(rgb))

    @unittest.skipUnless(os.path.isdir(TUM), f"no test data at {TUM}")
    def test_track_stopped_by_ctrl_c_writes_everything(self):
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "trk")
            code, err = interrupt_when([EXE, *track_tum(TUM, out)],
                                       lambda: count_poses(os.path.join(out, "trajectory.txt.partial")) >= 3)
            self.assertEqual(code, SIGINT_CODE, err)
            n = len(poses(os.path.join(out, "trajectory.txt")))
            self.assertGreaterEqual(n, 3)
            self.assertLess(n, 150)
            stats = rows(os.path.join(out, "tracking_stats.csv"))
            self.assertEqual([int(s["frame"]) for s in stats], list(range(n)))
            timed = {int(r["frame"]) for r in rows(os.path.join(out, "timings.csv"))}
            self.assertEqual(timed, set(range(n)))
            with open(os.path.join(out, "log.txt")) as f:
                self.assertIn("SIGINT", f.read())
            self.assertEqual(glob.glob(os.path.join(out, "*.partial")), [])

    def test_run_stopped_by_ctrl_c_writes_everything(self):
        # Regression: `run` stopped by SIGINT left log.txt empty and no timings.csv or tracking_stats.csv.
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "run")
            code, err = interrupt_when(
                [EXE, "run", DEMO, "--device", "cpu", "--out", out, "--set", "input.synthetic.frames=60",
                 "--set", "render.mode=none", "--set", "volume.voxel_size=0.02", "--set", "volume.truncation=0.08"],
                lambda: count_poses(os.path.join(out, "trajectory.txt.partial")) >= 2)
            self.assertEqual(code, SIGINT_CODE, err)
            n = len(poses(os.path.join(out, "trajectory.txt")))
            self.assertLess(n, 60)
            self.assertEqual(len(rows(os.path.join(out, "tracking_stats.csv"))), n)
            self.assertTrue(rows(os.path.join(out, "timings.csv")))
            for f in ["log.txt", "mesh.ply", "particles.ply", "config.yaml"]:
                self.assertGreater(os.path.getsize(os.path.join(out, f)), 0, f)


    @unittest.skipUnless(shutil.which("ffprobe"), "no ffprobe (Debian package ffmpeg)")
    def test_live_run_with_video_stopped_by_ctrl_c_in_a_terminal(self):
        # A Ctrl-C in a terminal reaches the whole process group: it killed the video encoder too,
        # whose failure then stopped the live run before tracking_stats.csv, particles.ply and
        # summary.json were written. The encoder runs in its own session now, and the video holds
        # every frame rendered.
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "live")
            code, err = interrupt_when(
                [EXE, "run", DEMO, "--device", "cpu", "--out", out, "--set", "mode=live",
                 "--set", "input.synthetic.frames=1000", "--set", "render.mode=headless",
                 "--set", "render.view=kinect", "--set", "render.width=160", "--set", "render.height=120",
                 "--set", "render.video=true", "--set", "output.particles_every=0",
                 "--set", "volume.voxel_size=0.02", "--set", "volume.truncation=0.08"],
                lambda: count_poses(os.path.join(out, "trajectory.txt.partial")) >= 3, group=True)
            self.assertEqual(code, SIGINT_CODE, err)
            n = len(poses(os.path.join(out, "trajectory.txt")))
            self.assertEqual(len(rows(os.path.join(out, "tracking_stats.csv"))), n)
            for f in ["log.txt", "particles.ply", "summary.json", "timings.csv", "video.mp4"]:
                self.assertGreater(os.path.getsize(os.path.join(out, f)), 0, f)
            probe = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-show_entries",
                                    "stream=nb_read_frames", "-of", "csv=p=0", os.path.join(out, "video.mp4")],
                                   capture_output=True, text=True)
            self.assertEqual(probe.returncode, 0, probe.stderr)
            self.assertGreaterEqual(int(probe.stdout.strip()), n)  # one rendered frame per input frame


class FailedMidway(unittest.TestCase):
    @unittest.skipUnless(os.path.isdir(TUM), f"no test data at {TUM}")
    def test_corrupt_png_keeps_the_frames_before_it(self):
        # Regression: a corrupt PNG in frame 4 stopped the run (good) but frames 0-3 were not written.
        with tempfile.TemporaryDirectory() as d:
            seq, out = os.path.join(d, "seq"), os.path.join(d, "trk")
            tum_copy(seq, 6, corrupt_depth_of=4)
            r = seamless(*track_tum(seq, out))
            self.assertEqual(r.returncode, INPUT, r.stderr)
            self.assertIn("truncated or corrupt", r.stderr)
            self.assertIn("stopped at frame 4", r.stderr)
            self.assertEqual([int(s["frame"]) for s in rows(os.path.join(out, "tracking_stats.csv"))], [0, 1, 2, 3])
            self.assertEqual({int(r["frame"]) for r in rows(os.path.join(out, "timings.csv"))}, {0, 1, 2, 3})
            self.assertEqual(len(poses(os.path.join(out, "trajectory.txt"))), 4)


class OutputFolder(unittest.TestCase):
    def test_a_folder_holds_one_run(self):
        # Regression: a run into an existing folder left the old run's other files beside its own.
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "run")
            args = ["reconstruct", DEMO, "--device", "cpu", "--out", out, "--set", "input.synthetic.frames=2",
                    "--set", "tracker.kind=ground_truth", "--set", "volume.voxel_size=0.02",
                    "--set", "volume.truncation=0.08"]
            self.assertEqual(seamless(*args).returncode, 0)
            self.assertEqual(glob.glob(os.path.join(out, "*.partial")), [])  # every file renamed when complete
            with open(os.path.join(out, "config.yaml")) as f:
                first = f.read()
            with open(os.path.join(out, "stale.txt"), "w") as f:
                f.write("from an earlier run\n")
            r = seamless(*args, "--set", "name=second")
            self.assertEqual(r.returncode, USAGE, r.stderr)
            self.assertIn("--force", r.stderr)
            with open(os.path.join(out, "config.yaml")) as f:
                self.assertEqual(f.read(), first)  # refused before writing anything
            r = seamless(*args, "--set", "name=second", "--force")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertFalse(os.path.exists(os.path.join(out, "stale.txt")))
            with open(os.path.join(out, "config.yaml")) as f:
                self.assertIn("name: second", f.read())


class Limits(unittest.TestCase):
    def test_hash_table_keeps_up_with_a_tiny_capacity(self):
        # Regression: capacity 64 doubled 4 times in frame 0, then dropped 530,045 insertions, advised
        # grow_when_full: true (already on) and lost every later frame, exit 0.
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "rec")
            r = seamless("reconstruct", DEMO, "--device", "cpu", "--out", out, "--set", "input.synthetic.frames=10",
                         "--set", "volume.capacity=64")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertNotIn("failed in frame", r.stderr)
            self.assertIn("grew it from 64 to", r.stderr)
            self.assertTrue(all(s["status"] == "ok" for s in rows(os.path.join(out, "tracking_stats.csv"))))

    def test_emitters_and_spawns_report_what_they_change(self):
        # Regression: an emitter asking for 100000 particles/s gave 15 without a word; an emitter past
        # solver.max_particles dropped particles silently; a spawn at (1000, 1000, 1000) was moved
        # into the room silently.
        with tempfile.TemporaryDirectory() as d:
            def simulate(name, spawn, *sets):
                args = ["simulate", DEMO, "--device", "cpu", "--out", os.path.join(d, name), "--set", f"spawn=[{spawn}]",
                        "--set", "duration=0.1", "--set", "output.particles_every=0", "--set", "render.mode=none",
                        "--set", "solver.particle_diameter=0.04"]  # the counts below are for 4 cm particles
                for s in sets:
                    args += ["--set", s]
                r = seamless(*args)
                self.assertEqual(r.returncode, 0, r.stderr)
                return r.stderr

            # `simulate` runs in the synthetic room's own frame: z up, the room x -2..2, y -2.5..2.5, z 0..2.6.
            # A nozzle of radius 0.02 m and particles of 0.04 m: one particle a layer, a layer per 0.04 m
            # the jet travels: 1 m/s carries 25 particles/s.
            jet = "{kind: emitter, position: [0, 0, 2.0], velocity: [0, 0, -1], rate: 100000, nozzle_radius: 0.02}"
            err = simulate("fast", jet)
            self.assertIn("rate 100000 particles/s is more than its jet carries (1 particles a layer", err)
            self.assertIn("25 particles/s); it emits 25/s", err)
            self.assertNotIn("inside the scene's solid", err)  # the nozzle is in the room's free space
            # 0.08 m: 13 particles a layer (|i|, |j| <= 2 diameters within the radius), 50 layers/s at
            # 2 m/s: 600 particles/s for 0.2 s is 120 particles, 80 or so over a budget of 40.
            wide = "{kind: emitter, position: [0, 0, 2.0], velocity: [0, 0, -2], rate: 600, nozzle_radius: 0.08}"
            err = simulate("full", wide, "solver.max_particles=40", "duration=0.2")
            self.assertRegex(err, r"emitters could not create [1-9][0-9]* particles \(solver.max_particles = 40")
            self.assertNotIn("more than its jet carries", err)
            err = simulate("far", "{kind: fluid_block, position: [1000, 1000, 1000], size: [0.1, 0.1, 0.1]}")
            self.assertRegex(err, r"spawn fluid_block at \(1000.00, 1000.00, 1000.00\): ([0-9]+) of \1 particles start "
                                  r"inside the scene's solid")


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
