#!/usr/bin/python3
"""Relocalisation that checks itself. A covered sensor (frames 10-14 of real
freiburg1_rpy with all-zero depth) loses tracking; the first frame accepted after the gap must
agree with ground truth, and the run's ATE must stay near the ATE of the same frames without the
gap. Before the fix, frame 15 "recovered" with a 22.8 cm / 11.4 degree jump marked ok (ground truth
moved 1.6 cm) and the rest of the trajectory was offset.
usage: relocalisation_test.py SEAMLESS_BINARY SOURCE_DIR DATA_DIR [TEST_NAME]  (e.g. CoveredSensor.test_icp)
Exits 77 (skipped) only when the real data is absent."""
import csv
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import unittest
import zlib

from tum_subset import tum_subset

EXE, SRC, DATA = sys.argv[1], sys.argv[2], sys.argv[3]
TUM = os.path.abspath(os.path.join(DATA, "tum_fr1_rpy_000-149"))
TUM_CFG = os.path.join(SRC, "configs", "tum_fr1.yaml")
FRAMES = 20             # frames 0-19 of the sequence: 10 to build the model, 5 covered, 5 after
GAP = range(10, 15)     # all-zero depth: the sensor covered for 5 frames (~0.17 s)


def list_lines(path):
    with open(path) as f:
        return [l.split() for l in f if l.strip() and not l.startswith("#")]


def zero_depth_png(path, width=640, height=480):
    """A 16-bit greyscale PNG of zeros (no depth anywhere), as a covered Kinect gives."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    raw = b"".join(b"\0" + bytes(2 * width) for _ in range(height))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 16, 0, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def tum_copy(dest, gap):
    """The first FRAMES associated pairs of the real folder, the depth of the frames in `gap`
    replaced by all-zero PNGs."""
    def covered(i, _src, out):
        if i in gap:
            zero_depth_png(out)
        return i in gap
    tum_subset(TUM, dest, FRAMES, covered)


def track(seq, out, kind):
    """configs/tum_fr1.yaml on the CPU with tracker `kind`, without the Ceres refinement (it would
    hide what the tracker did). Lost frames are expected here: the exit-code threshold is lifted."""
    args = [EXE, "track", TUM_CFG, "--device", "cpu", "--out", out, "--set", f"input.path={seq}",
            "--set", "refine.enabled=false", "--set", f"tracker.kind={kind}", "--set", "output.max_lost_fraction=1",
            # 1 cm voxels instead of the config's 5 mm: fusion and raycast ~4 times cheaper (CI time);
            # the false recovery this test guards against happens the same way at both sizes (checked).
            "--set", "volume.voxel_size=0.01", "--set", "volume.truncation=0.04"]
    r = subprocess.run(args, capture_output=True, text=True, timeout=600)
    if r.returncode != 0:
        raise AssertionError(f"{' '.join(args)} exited {r.returncode}:\n{r.stderr}")
    return r


def poses(path):
    """timestamp -> (t, q) with q = (x, y, z, w)."""
    return {round(float(l[0]), 4): ([float(v) for v in l[1:4]], [float(v) for v in l[4:8]])
            for l in list_lines(path)}


def qmul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def qconj(q):
    return (-q[0], -q[1], -q[2], q[3])


def qrot(q, v):
    x, y, z, _ = qmul(qmul(q, (v[0], v[1], v[2], 0.0)), qconj(q))
    return (x, y, z)


def relative(a, b):
    """a^-1 b of two poses (t, q)."""
    qa_inv = qconj(a[1])
    d = [b[0][i] - a[0][i] for i in range(3)]
    return qrot(qa_inv, d), qmul(qa_inv, b[1])


def motion_error(est_a, est_b, gt_a, gt_b):
    """The error of the estimated motion from a to b against ground truth's (the relative pose error
    of that pair, Sturm et al. 2012): metres, degrees."""
    e, g = relative(est_a, est_b), relative(gt_a, gt_b)
    dt, dq = relative(g, e)
    angle = 2 * math.degrees(math.acos(min(1.0, abs(dq[3]))))
    return math.sqrt(sum(v * v for v in dt)), angle


def ate(out):
    r = subprocess.run([EXE, "eval", os.path.join(out, "groundtruth.txt"), os.path.join(out, "trajectory.txt"),
                        "--json", os.path.join(out, "ate.json")], capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        raise AssertionError(f"seamless eval exited {r.returncode}:\n{r.stderr}")
    with open(os.path.join(out, "ate.json")) as f:
        return json.load(f)["ate_rmse_m"]


def stats(out):
    with open(os.path.join(out, "tracking_stats.csv")) as f:
        return list(csv.DictReader(f))


class CoveredSensor(unittest.TestCase):
    def check(self, kind):
        keep = os.environ.get("RELOCALISATION_TEST_KEEP")  # set: the outputs stay in a /tmp/reloc_* folder
        d = tempfile.mkdtemp(prefix="reloc_") if keep else None
        with tempfile.TemporaryDirectory() as tmp:
            d = d or tmp
            full, gapped = os.path.join(d, "seq_full"), os.path.join(d, "seq_gap")
            tum_copy(full, gap=())
            tum_copy(gapped, gap=GAP)
            out_full, out_gap = os.path.join(d, f"{kind}_full"), os.path.join(d, f"{kind}_gap")
            track(full, out_full, kind)
            track(gapped, out_gap, kind)
            rows = stats(out_gap)
            self.assertEqual(len(rows), FRAMES)
            # The covered frames have nothing to track: lost, not fused.
            for i in GAP:
                self.assertNotEqual(rows[i]["status"], "ok", f"frame {i} has no depth but was accepted")
                self.assertEqual(rows[i]["fused"], "0")
            accepted = [i for i, r in enumerate(rows) if r["status"] == "ok"]
            after = [i for i in accepted if i > max(GAP)]
            # It recovers (the camera still sees what the model holds): at least 4 of the 5 frames after
            # the gap are accepted (the first may be rejected and the next one retried).
            self.assertGreaterEqual(len(after), 4, f"only frames {after} accepted after the gap")
            est = poses(os.path.join(out_gap, "trajectory.txt"))
            gt = poses(os.path.join(out_gap, "groundtruth.txt"))
            stamps = sorted(est)
            last_before = max(i for i in accepted if i < min(GAP))
            first_after = after[0]
            # No accepted frame jumps: the motion from the last good frame before the gap to the
            # first accepted after it, against ground truth's. The tracker's own frame-to-frame error
            # on freiburg1 is a few millimetres and a fraction of a degree (docs/TRACKING.md); the
            # false recovery this catches was 22.8 cm / 11.4 degrees. 3 cm / 3 degrees leaves room for
            # a few frames' worth of drift and still catches any jump to a wrong minimum (ICP's
            # basin on this scene is wider than 3 cm).
            a, b = stamps[last_before], stamps[first_after]
            dt, dr = motion_error(est[a], est[b], gt[a], gt[b])
            print(f"{kind}: frames {last_before} -> {first_after} across the gap: error {100 * dt:.2f} cm, "
                  f"{dr:.2f} deg; accepted after the gap: {after}")
            self.assertLess(dt, 0.03, f"frame {first_after}: {100 * dt:.1f} cm off ground truth's motion")
            self.assertLess(dr, 3.0, f"frame {first_after}: {dr:.1f} degrees off ground truth's motion")
            # Consecutive accepted frames after the gap: no jump either (the same bound per pair).
            for i, j in zip(after, after[1:]):
                dt, dr = motion_error(est[stamps[i]], est[stamps[j]], gt[stamps[i]], gt[stamps[j]])
                self.assertLess(dt, 0.03, f"frames {i} -> {j}: {100 * dt:.1f} cm off ground truth's motion")
                self.assertLess(dr, 3.0, f"frames {i} -> {j}: {dr:.1f} degrees off ground truth's motion")
            # The whole run: ATE (SE(3)-aligned, every frame, lost ones at their kept pose) near the
            # ATE without the gap. The lost frames hold the last good pose while the camera turned
            # (0.3-1.5 cm and 3-13 degrees of ground-truth motion), which adds ~0.5 cm RMS over 20
            # frames (measured: +0.2 to +0.3 cm); a false recovery offsets every later frame by ~20 cm.
            ate_full, ate_gap = ate(out_full), ate(out_gap)
            print(f"{kind}: ATE without the gap {100 * ate_full:.2f} cm, with it {100 * ate_gap:.2f} cm")
            self.assertLess(ate_gap, ate_full + 0.015)

    def test_icp(self):
        self.check("icp")

    def test_rgbd(self):
        self.check("rgbd")


if __name__ == "__main__":
    if not os.path.isdir(TUM):
        print(f"skipped: no test data at {TUM}")
        sys.exit(77)
    unittest.main(argv=sys.argv[:1] + sys.argv[4:])
