"""seamless from Python: track, reconstruct, simulate and run experiments, evaluate trajectories.

The functions run the same code as the `seamless` command's subcommands and write the same files
into the run's output folder; the results come back as NumPy arrays (docs/PYTHON.md):

    import seamless
    r = seamless.track("configs/tum_fr1.yaml", {"input.path": "data/fr1_rpy", "frames": 30})
    r.poses        # N x 4 x 4 camera-to-world matrices
    r.timestamps   # N seconds
"""
import json
import os
from collections import namedtuple

import numpy as np

from . import _seamless
from ._seamless import ConfigError, Error, InputError, UsageError, __version__, features, git_commit

__all__ = ["track", "reconstruct", "simulate", "run", "eval", "frames", "config", "Frame", "Result", "Mesh",
           "Particles", "Trajectory", "features", "Error", "ConfigError", "InputError", "UsageError", "__version__"]

# One RGB-D frame: depth in metres (float32, H x W, 0 = no reading), colour (uint8, H x W x 3, RGB),
# timestamp in seconds; accelerometer (m/s^2, camera frame) and ground_truth (4 x 4 camera to
# world) when known, else None.
Frame = namedtuple("Frame", "timestamp depth colour accelerometer ground_truth", defaults=(None, None))
Mesh = namedtuple("Mesh", "vertices faces colours normals")
Particles = namedtuple("Particles", "positions velocities inv_mass phase")
Trajectory = namedtuple("Trajectory", "poses timestamps tum")
Timing = namedtuple("Timing", "frame ms")


def _override_text(value):
    """A Python value as the right-hand side of a --set (YAML)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if value is None:
        return "null"
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_override_text(v) for v in value) + "]"
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, (np.integer, np.floating)):
        return repr(value.item())
    return repr(value) if isinstance(value, float) else str(value)


def _overrides(overrides):
    """{key: value} or ["key=value", ...] as the --set list, in order."""
    if overrides is None:
        return []
    if isinstance(overrides, dict):
        return [f"{k}={_override_text(v)}" for k, v in overrides.items()]
    if isinstance(overrides, str):
        raise UsageError(f"overrides is the string {overrides!r}; give a dict {{key: value}} or a list of 'key=value'")
    return [str(o) for o in overrides]


def _config(config):
    """(path, yaml text) of a config given as a file path or a dict."""
    if isinstance(config, dict):
        return "", json.dumps(config, default=lambda v: os.fspath(v) if isinstance(v, os.PathLike) else str(v))
    if isinstance(config, (str, os.PathLike)):
        path = os.fspath(config)
        if not os.path.isfile(path):
            raise ConfigError(f"{path}: no such experiment file")
        return path, ""
    raise UsageError(f"config is a {type(config).__name__}; give the path of an experiment file or a dict")


def config(config, overrides=None):
    """The effective experiment (every key, defaults included) as YAML text, as `seamless config`
    prints it; raises ConfigError with the CLI's messages for a config that does not load."""
    path, text = _config(config)
    return _seamless.effective_config(path, text, _overrides(overrides))


# --- frames --------------------------------------------------------------------------------------

def _frame_tuple(item, k):
    """A user's frame (Frame, dict, object with attributes, or tuple) as the module's tuple."""
    if isinstance(item, dict):
        get = item.get
    elif isinstance(item, tuple) and not hasattr(item, "_fields"):
        fields = dict(zip(Frame._fields, item))
        get = fields.get
    else:
        def get(name, default=None):
            return getattr(item, name, default)
    t, depth, colour = get("timestamp"), get("depth"), get("colour", get("color"))
    if t is None or depth is None or colour is None:
        raise InputError(f"frame {k}: needs timestamp, depth and colour (got {type(item).__name__})")
    depth = np.asarray(depth)
    if depth.dtype.kind != "f":
        raise InputError(f"frame {k}: depth is {depth.dtype}; give metres as float32 (divide raw depth by its "
                         "scale, e.g. TUM's 5000 units per metre)")
    depth = np.ascontiguousarray(depth, dtype=np.float32)
    colour = np.asarray(colour)
    if depth.ndim != 2:
        raise InputError(f"frame {k}: depth has shape {depth.shape}; expected H x W")
    if colour.dtype != np.uint8 or colour.shape != depth.shape + (3,):
        raise InputError(f"frame {k}: colour is {colour.dtype} {colour.shape}; expected uint8 "
                         f"{depth.shape + (3,)} (RGB, the depth's size)")
    colour = np.ascontiguousarray(colour)
    acc, gt = get("accelerometer"), get("ground_truth")
    if acc is not None:
        acc = [float(a) for a in np.asarray(acc, dtype=np.float64).reshape(3)]
    if gt is not None:
        gt = np.asarray(gt, dtype=np.float64)
        if gt.shape != (4, 4):
            raise InputError(f"frame {k}: ground_truth has shape {gt.shape}; expected 4 x 4 (camera to world)")
    return float(t), depth, colour, acc, gt


def _frame_iterator(source):
    """Frames from an iterable, an iterator or an object with next() (None at the end)."""
    if hasattr(source, "__iter__"):
        items = iter(source)
    elif callable(getattr(source, "next", None)):
        def items_from_next():
            while (item := source.next()) is not None:
                yield item
        items = items_from_next()
    else:
        raise UsageError(f"frames is a {type(source).__name__}; give an iterable of frames or an object with next()")
    for k, item in enumerate(items):
        yield _frame_tuple(item, k)


class FrameReader:
    """The frames a config's input section delivers (a TUM folder, a frame folder, the synthetic
    room, ...), as Frame tuples of NumPy arrays, undistorted as the pipeline sees them;
    .intrinsics holds their camera (a dict as the `intrinsics` argument of track takes)."""

    def __init__(self, config, overrides=None):
        path, text = _config(config)
        self._reader = _seamless.FrameReader(path, text, _overrides(overrides))
        self.intrinsics = self._reader.intrinsics()

    def __len__(self):
        n = self._reader.size()
        if n is None:
            raise TypeError("this source does not know its number of frames")
        return n

    def __iter__(self):
        return self

    def __next__(self):
        d = self._reader.next()
        if d is None:
            raise StopIteration
        return Frame(d["timestamp"], d["depth"], d["colour"], d["accelerometer"], d["ground_truth"])


def frames(config, overrides=None):
    """Reads the frames of config's input (see FrameReader)."""
    return FrameReader(config, overrides)


# --- running -------------------------------------------------------------------------------------

class Result:
    """What a run computed. Every run: command, out_dir (its files), exit_code (the CLI's: 0, or 3
    when tracking lost too many frames), interrupted, timings {stage: Timing(frame, ms)}.
    track / reconstruct / run: poses (N x 4 x 4, camera to world), timestamps (N), tum (N x 8 rows
    of trajectory.txt), ground_truth (Trajectory), frames {column: array} (tracking_stats),
    lost_frames, intrinsics, first_frame (Frame). reconstruct / run: mesh (Mesh). run: scene_particles
    (M x 3), summary (summary.json). simulate / run: particles (Particles, the last state), solver."""

    def __init__(self, command, d):
        self.command = command
        self.out_dir = d["out_dir"]
        self.exit_code = d["exit_code"]
        self.interrupted = d["interrupted"]
        self.timings = {k: Timing(v["frame"], v["ms"]) for k, v in d["timings"].items()}
        self.poses = d.get("poses")
        self.timestamps = d.get("timestamps")
        self.tum = d.get("tum")
        gt = d.get("ground_truth")
        self.ground_truth = Trajectory(gt["poses"], gt["timestamps"], gt["tum"]) if gt else None
        self.frames = d.get("frames")
        self.lost_frames = d.get("lost_frames")
        self.intrinsics = d.get("intrinsics")
        m = d.get("mesh")
        self.mesh = Mesh(m["vertices"], m["faces"], m["colours"], m["normals"]) if m else None
        f = d.get("first_frame")
        self.first_frame = Frame(f["timestamp"], f["depth"], f["colour"]) if f else None
        self.scene_particles = d.get("scene_particles")
        p = d.get("particles")
        self.particles = Particles(p["positions"], p["velocities"], p["inv_mass"], p["phase"]) if p else None
        self.solver = d.get("solver")
        summary = os.path.join(self.out_dir, "summary.json")
        self.summary = None
        if command == "run" and os.path.isfile(summary):
            with open(summary) as fh:
                self.summary = json.load(fh)

    @property
    def trajectory_path(self):
        """The run's trajectory.txt (TUM format)."""
        return os.path.join(self.out_dir, "trajectory.txt")

    def __repr__(self):
        parts = [f"command={self.command!r}", f"out_dir={self.out_dir!r}", f"exit_code={self.exit_code}"]
        if self.poses is not None:
            parts.append(f"poses={self.poses.shape[0]}")
        if self.mesh is not None:
            parts.append(f"mesh={len(self.mesh.vertices)} vertices, {len(self.mesh.faces)} faces")
        if self.particles is not None:
            parts.append(f"particles={len(self.particles.positions)}")
        return "Result(" + ", ".join(parts) + ")"


def _run(command, config, overrides, out, force, frames, intrinsics, device, progress, verbosity):
    path, text = _config(config)
    sets = _overrides(overrides)
    if device is not None:
        sets.append(f"device={device}")
    if progress is not None and not callable(progress):
        raise UsageError("progress is not callable; give a function (what, done, total, status) or None")
    size = None
    frame_items = None
    if frames is not None:
        if intrinsics is None and isinstance(getattr(frames, "intrinsics", None), dict):
            intrinsics = frames.intrinsics
        try:
            size = len(frames)
        except TypeError:
            size = None
        frame_items = _frame_iterator(frames)
    elif intrinsics is not None:
        raise UsageError("intrinsics are for frames given from Python (the frames argument)")
    d = _seamless.run_command(command, path, text, sets, "" if out is None else os.fspath(out), force, frame_items,
                              intrinsics, size, progress, verbosity)
    result = Result(command, d)
    if result.interrupted:
        raise KeyboardInterrupt(f"seamless {command} stopped by a signal; its outputs are in {result.out_dir}")
    return result


_RUN_DOC = """

    config: an experiment file's path or a dict of the same keys; overrides: {key: value} (or a list
    of "key=value"), the keys of `--set`; out: the output folder (default, as the CLI:
    <output.dir>/<config name>-<date-time>); force: clear an output folder holding an earlier run;
    device: "cpu", "cuda" or "auto" (as --device); progress: None (progress lines are logged) or a
    function (what, done, total, status) called as the loops go; verbosity: quiet, normal or verbose.
    Raises ConfigError, InputError, UsageError or Error with the CLI's messages.
"""
_FRAMES_DOC = """    frames: None (the config's input section), or frames from Python: an iterable or an object
    with next() (None at the end) of Frame tuples, dicts or objects with timestamp (s), depth
    (float32 H x W, metres) and colour (uint8 H x W x 3), optional accelerometer and ground_truth;
    intrinsics: their camera {fx, fy, cx, cy, width, height, dist (k1 k2 p1 p2 k3)}, default the
    config's input.intrinsics (lens distortion is removed as for the other sources).
"""


def track(config, overrides=None, *, out=None, force=False, frames=None, intrinsics=None, device=None,
          progress=None, verbosity="normal"):
    return _run("track", config, overrides, out, force, frames, intrinsics, device, progress, verbosity)


def reconstruct(config, overrides=None, *, out=None, force=False, frames=None, intrinsics=None, device=None,
                progress=None, verbosity="normal"):
    return _run("reconstruct", config, overrides, out, force, frames, intrinsics, device, progress, verbosity)


def run(config, overrides=None, *, out=None, force=False, frames=None, intrinsics=None, device=None,
        progress=None, verbosity="normal"):
    return _run("run", config, overrides, out, force, frames, intrinsics, device, progress, verbosity)


def simulate(config, overrides=None, *, out=None, force=False, device=None, progress=None, verbosity="normal"):
    return _run("simulate", config, overrides, out, force, None, None, device, progress, verbosity)


track.__doc__ = ("seamless track: the camera's trajectory over the input (refined when refine.enabled); "
                 "writes trajectory.txt and tracking_stats.csv. Returns a Result." + _RUN_DOC + _FRAMES_DOC)
reconstruct.__doc__ = ("seamless reconstruct: tracks and fuses the input into the TSDF volume; Result.mesh "
                       "holds the mesh (as mesh.ply)." + _RUN_DOC + _FRAMES_DOC)
run.__doc__ = ("seamless run: the whole experiment (scan, scene particles, physics; rendering as the "
               "config says). Returns a Result." + _RUN_DOC + _FRAMES_DOC)
simulate.__doc__ = ("seamless simulate: the particle solver on the synthetic room's exact SDF. Returns a "
                    "Result with particles." + _RUN_DOC)


def eval(groundtruth, estimate, *, align="se3", t_max_diff=None, offset=0.0):  # noqa: A001 (seamless eval)
    """seamless eval: ATE and RPE of `estimate` against `groundtruth` (TUM trajectory files; the
    estimate may be a Result, whose trajectory.txt is used), ground truth first as evo and TUM's
    tools take them. Returns the figures of `seamless eval --json` as a dict (schema
    seamless-eval/1, docs/TRACKING.md): ate_rmse_m, rpe_frame_trans_rmse_m, ..."""
    if isinstance(estimate, Result):
        estimate = estimate.trajectory_path
    if isinstance(groundtruth, Result):
        groundtruth = groundtruth.trajectory_path
    for name, p in (("groundtruth", groundtruth), ("estimate", estimate)):
        if not os.path.isfile(os.fspath(p)):
            raise InputError(f"{name}: {os.fspath(p)}: no such trajectory file")
    t = _seamless.default_t_max_diff if t_max_diff is None else float(t_max_diff)
    return json.loads(_seamless.eval_report(os.fspath(groundtruth), os.fspath(estimate), align, t, float(offset)))
