"""The Python module against the `seamless` command of the same build: the same poses, the same
evaluation figures, the same error messages, and frames fed from NumPy giving the poses the TUM
folder source gives (docs/PYTHON.md). A few seconds per test on 2 cores: 15 frames or fewer."""
import os

import numpy as np
import pytest

import seamless


def read_tum(path):
    """Rows timestamp tx ty tz qx qy qz qw of a TUM trajectory file."""
    return np.loadtxt(path, comments="#", ndmin=2)


def quaternion_matrices(rows):
    """Camera-to-world 4 x 4 matrices of TUM rows (unit quaternion x y z w)."""
    out = np.zeros((len(rows), 4, 4))
    for i, (_, tx, ty, tz, x, y, z, w) in enumerate(rows):
        n = np.sqrt(x * x + y * y + z * z + w * w)
        x, y, z, w = x / n, y / n, z / n, w / n
        out[i, :3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                          [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                          [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
        out[i, :3, 3] = tx, ty, tz
        out[i, 3, 3] = 1
    return out


def fr1_overrides(path, frames=15, refine=True):
    # Refinement needs Ceres; a build without it (the lean pip build) tracks without.
    return {"input.path": path, "frames": frames, "device": "cpu",
            "refine.enabled": refine and seamless.features["ceres"]}


def as_sets(overrides):
    return [a for k, v in overrides.items() for a in ("--set", f"{k}={seamless._override_text(v)}")]


@pytest.fixture(scope="module")
def fr1_config(source_dir):
    return os.path.join(source_dir, "configs", "tum_fr1.yaml")


@pytest.fixture(scope="module")
def cli_track(seamless_cli, fr1_rpy, fr1_config, tmp_path_factory):
    """`seamless track configs/tum_fr1.yaml` on 15 frames of fr1_rpy 150-299 (with its refinement)."""
    out = tmp_path_factory.mktemp("cli") / "track"
    seamless_cli("track", fr1_config, *as_sets(fr1_overrides(fr1_rpy)), "--out", out)
    return out


@pytest.fixture(scope="module")
def py_track(fr1_rpy, fr1_config, tmp_path_factory):
    return seamless.track(fr1_config, fr1_overrides(fr1_rpy), out=tmp_path_factory.mktemp("py") / "track")


def test_track_poses_equal_the_cli(cli_track, py_track):
    cli = read_tum(cli_track / "trajectory.txt")
    r = py_track
    assert r.exit_code == 0
    assert r.poses.shape == (15, 4, 4) and r.poses.dtype == np.float64
    assert r.timestamps.shape == (15,)
    # trajectory.txt prints seconds to 6 decimals, metres to 7 and the quaternion to 9.
    np.testing.assert_allclose(r.timestamps, cli[:, 0], rtol=0, atol=1e-6)
    np.testing.assert_allclose(r.poses, quaternion_matrices(cli), rtol=0, atol=2e-7)
    # The same code on the same input: the files the two runs wrote are the same, byte for byte.
    for name in ("trajectory.txt", "groundtruth.txt"):
        assert (cli_track / name).read_bytes() == (py_track_dir(r) / name).read_bytes(), name
    if seamless.features["ceres"]:  # the refined trajectory, as the CLI's
        assert (py_track_dir(r) / "trajectory_odometry.txt").is_file()
    # Camera to world: rotations, and the motion of fr1_rpy (rolling, pitching, yawing in place).
    R = r.poses[:, :3, :3]
    np.testing.assert_allclose(R @ R.transpose(0, 2, 1), np.broadcast_to(np.eye(3), R.shape), atol=1e-6)
    np.testing.assert_array_equal(r.poses[:, 3], np.broadcast_to([0, 0, 0, 1], (15, 4)))


def py_track_dir(r):
    import pathlib
    return pathlib.Path(r.out_dir)


def test_eval_equals_the_cli(seamless_cli, cli_track, py_track, fr1_rpy, tmp_path):
    gt = os.path.join(fr1_rpy, "groundtruth.txt")
    seamless_cli("eval", gt, cli_track / "trajectory.txt", "--json", tmp_path / "eval.json")
    import json
    cli = json.loads((tmp_path / "eval.json").read_text())
    figures = seamless.eval(gt, py_track)
    assert figures.pop("estimate") == py_track.trajectory_path
    cli.pop("estimate")
    assert figures == cli
    assert 0 < figures["ate_rmse_m"] < 0.05 and figures["pairs"] == 15  # a few centimetres on fr1_rpy


def tum_frames(folder, n):
    """The first n frames of a TUM folder read as a user would (PIL, the folder's associations.txt,
    depth / 5000 as float32, the nearest accelerometer sample within 0.1 s)."""
    Image = pytest.importorskip("PIL.Image")
    pairs = [line.split() for line in open(os.path.join(folder, "associations.txt")) if not line.startswith("#")]
    acc = np.loadtxt(os.path.join(folder, "accelerometer.txt"), comments="#")
    for t_rgb, rgb, _, depth in pairs[:n]:
        t = float(t_rgb)
        raw = np.asarray(Image.open(os.path.join(folder, depth)), dtype=np.uint16)
        colour = np.asarray(Image.open(os.path.join(folder, rgb)).convert("RGB"))
        k = min(np.searchsorted(acc[:, 0], t), len(acc) - 1)
        if k > 0 and abs(acc[k - 1, 0] - t) < abs(acc[k, 0] - t):
            k -= 1
        # The Kinect's accelerometer axes are the camera's turned half a turn about z (TUM's files
        # keep the sensor's): in the camera frame (x right, y down, z forward) -ax, -ay, az.
        a = acc[k, 1:] * [-1, -1, 1] if abs(acc[k, 0] - t) <= 0.1 else None
        yield seamless.Frame(t, raw.astype(np.float32) * np.float32(1 / 5000), colour, a)


def test_numpy_frames_give_the_tum_source_poses(fr1_rpy, fr1_config, tmp_path):
    overrides = fr1_overrides(fr1_rpy, frames=8, refine=False)
    folder = seamless.track(fr1_config, overrides, out=tmp_path / "folder")
    # Raw frames with the config's freiburg1 intrinsics (lens distortion removed on input, as the
    # TUM source does); the frames' own timestamps and accelerometer.
    fed = seamless.track(fr1_config, overrides, out=tmp_path / "numpy", frames=tum_frames(fr1_rpy, 8))
    np.testing.assert_array_equal(fed.timestamps, folder.timestamps)
    np.testing.assert_array_equal(fed.poses, folder.poses)
    # The frames as seamless reads them (undistorted, so with distortion-free intrinsics), through
    # an object with next(), give them too.
    reader = seamless.frames(fr1_config, {"input.path": fr1_rpy, "input.max_frames": 8})
    assert reader.intrinsics["dist"] == [0.0] * 5 and len(reader) == 8

    class Camera:  # a user's camera class: next() gives a frame, None at the end
        def next(self):
            return next(reader, None)
    again = seamless.track(fr1_config, overrides, out=tmp_path / "reader", frames=Camera(),
                           intrinsics=reader.intrinsics)
    np.testing.assert_array_equal(again.poses, folder.poses)


def test_reconstruct_mesh_arrays_are_the_mesh_ply(fr1_rpy, fr1_config, tmp_path):
    calls = []
    r = seamless.reconstruct(fr1_config, {"input.path": fr1_rpy, "frames": 5, "device": "cpu", "volume.capacity": 16384,
                                          "volume.voxel_size": 0.02, "volume.truncation": 0.08},
                             out=tmp_path / "rec", progress=lambda *a: calls.append(a))
    m = r.mesh
    assert m.vertices.dtype == np.float32 and m.vertices.shape[1] == 3 and len(m.vertices) > 1000
    assert m.faces.dtype == np.int32 and m.faces.shape[1] == 3 and 0 <= m.faces.min() and m.faces.max() < len(m.vertices)
    assert m.colours.dtype == np.uint8 and m.colours.shape == m.vertices.shape
    assert not m.vertices.flags.owndata  # a view of the C++ mesh, not a copy
    ply = (tmp_path / "rec" / "mesh.ply").read_bytes()
    header, body = ply.split(b"end_header\n", 1)
    assert f"element vertex {len(m.vertices)}\n".encode() in header
    assert f"element face {len(m.faces)}\n".encode() in header
    props = header.count(b"property float") * 4 + header.count(b"property uchar") * 1
    rows = np.frombuffer(body[:props * len(m.vertices)], dtype=np.uint8).reshape(len(m.vertices), props)
    np.testing.assert_array_equal(rows[:, :12].copy().view(np.float32), m.vertices)
    # progress: the scan's frames, in order, to the total
    scan = [c for c in calls if c[0] == "scan"]
    assert [c[1] for c in scan] == [1, 2, 3, 4, 5] and scan[-1][2] == 5
    assert set(r.timings) >= {"preprocess", "track", "fuse", "frame"}
    assert len(r.timings["track"].ms) == 5
    assert r.first_frame.depth.shape == (480, 640) and r.first_frame.colour.shape == (480, 640, 3)


def test_errors_carry_the_cli_messages(seamless_cli, tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("volume:\n  voxel_size: -1\n")
    cli = seamless_cli("config", bad, check=False)
    assert cli.returncode != 0
    with pytest.raises(seamless.ConfigError) as e:
        seamless.track(bad, out=tmp_path / "out")
    assert str(e.value).splitlines()[0] in cli.stderr
    assert "volume.voxel_size" in str(e.value)
    with pytest.raises(seamless.ConfigError, match="volume.voxel_size"):
        seamless.config({"volume": {"voxel_size": -1}})
    with pytest.raises(seamless.ConfigError, match="nonexistent.yaml"):
        seamless.track(tmp_path / "nonexistent.yaml")


def test_bad_frames_are_named(fr1_config, tmp_path):
    depth16 = np.zeros((480, 640), np.uint16)
    with pytest.raises(seamless.InputError, match="float32"):
        seamless.track(fr1_config, {"device": "cpu", "refine.enabled": False}, out=tmp_path / "a",
                       frames=[(0.0, depth16, np.zeros((480, 640, 3), np.uint8))])
    with pytest.raises(seamless.InputError, match="320x240 but the intrinsics say 640x480"):
        seamless.track(fr1_config, {"device": "cpu", "refine.enabled": False}, out=tmp_path / "b",
                       frames=[(0.0, np.zeros((240, 320), np.float32), np.zeros((240, 320, 3), np.uint8))])


def read_particles(path):
    """Positions, velocities and phases of a particles PLY (x y z vx vy vz float, phase uint)."""
    header, body = path.read_bytes().split(b"end_header\n", 1)
    n = int(header.split(b"element vertex ")[1].split(b"\n")[0])
    rows = np.frombuffer(body, dtype=np.dtype([("xv", "<f4", 6), ("phase", "<u4")]), count=n)
    return rows["xv"][:, :3], rows["xv"][:, 3:], rows["phase"]


def test_run_equals_the_cli(seamless_cli, source_dir, tmp_path):
    """The demo experiment, reduced (4 synthetic frames, 0.05 s of physics, no rendering), through
    `seamless run` and seamless.run: the same particles, written and returned."""
    config = os.path.join(source_dir, "configs", "demo.yaml")
    overrides = {"device": "cpu", "input.synthetic.frames": 4, "duration": 0.05, "render.mode": "none",
                 "volume.capacity": 16384}
    seamless_cli("run", config, *as_sets(overrides), "--out", tmp_path / "cli")
    r = seamless.run(config, overrides, out=tmp_path / "py")
    x, v, phase = read_particles(tmp_path / "py" / "particles.ply")
    np.testing.assert_array_equal(r.particles.positions, x)
    np.testing.assert_array_equal(r.particles.velocities, v)
    np.testing.assert_array_equal(r.particles.phase, phase)
    assert r.solver["particles"] == len(x) > 0
    scene, _, _ = read_particles(tmp_path / "py" / "scene_particles.ply")
    np.testing.assert_array_equal(r.scene_particles, scene)
    assert r.summary["frames"]["read"] == 4 and r.poses.shape == (4, 4, 4) and len(r.mesh.faces) > 0
    for name in ("particles.ply", "scene_particles.ply", "trajectory.txt"):
        assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "py" / name).read_bytes(), name
