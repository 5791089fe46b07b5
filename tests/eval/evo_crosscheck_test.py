#!/usr/bin/python3
"""`seamless eval GT EST` against evo (Grupp, github.com/MichaelGrupp/evo) on the same files,
where evo is installed (`pip install evo`, optional: exit 77, ctest "skipped", without it). The
files: the shared tum_fr1_rpy_000-149 ground truth and tests/eval/data/tum_fr1_rpy_000-149_icp.txt
(a drifting ICP estimate). evo_ape with -a / -as / no alignment and evo_rpe per frame
(trans_part, angle_deg) against seamless eval's JSON, to 1e-7 m (deg): both compute in double from
the same pairs, so any difference beyond rounding is a difference of method.
evo has no RPE over seconds; TUM's RPE/s is checked against hand-made cases in
tests/eval/trajectory_eval_test.cpp.

usage: evo_crosscheck_test.py SEAMLESS SOURCE_DIR DATA_DIR WORK_DIR  (evo_ape/evo_rpe on PATH, or EVO_BIN=dir)
"""
import json
import os
import shutil
import subprocess
import sys
import zipfile

SKIP = 77
TOL = 1e-7


def evo(bindir, tool, args, work, name):
    out = os.path.join(work, name + ".zip")
    cmd = [os.path.join(bindir, tool) if bindir else tool] + args + ["--save_results", out, "--no_warnings"]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    with zipfile.ZipFile(out) as z:
        return json.loads(z.read("stats.json"))


def ours(seamless, gt, est, work, align):
    out = os.path.join(work, f"seamless_{align}.json")
    subprocess.run([seamless, "eval", gt, est, "--align", align, "--t_max_diff", "0.02", "--json", out],
                   check=True, capture_output=True, text=True)
    with open(out) as f:
        return json.load(f)


def compare(what, mine, theirs, prefix, unit):
    for stat in ("rmse", "mean", "median", "std", "min", "max"):
        a, b = mine[f"{prefix}_{stat}_{unit}"], theirs[stat]
        assert abs(a - b) <= TOL, f"{what} {stat}: seamless {a!r}, evo {b!r}"
    print(f"{what}: rmse seamless {mine[f'{prefix}_rmse_{unit}']:.9f}, evo {theirs['rmse']:.9f}")


def main():
    seamless, src, data, work = sys.argv[1:5]
    bindir = os.environ.get("EVO_BIN", "")
    if not (os.path.exists(os.path.join(bindir, "evo_ape")) if bindir else shutil.which("evo_ape")):
        print("SKIP: evo is not installed (pip install evo; optional, for this cross-check only)")
        return SKIP
    gt = os.path.join(data, "tum_fr1_rpy_000-149", "groundtruth.txt")
    if not os.path.exists(gt):
        print(f"SKIP: {gt} is absent (shared test data)")
        return SKIP
    est = os.path.join(src, "tests", "eval", "data", "tum_fr1_rpy_000-149_icp.txt")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    common = ["tum", gt, est, "--t_max_diff", "0.02"]
    for align, flags in (("se3", ["-a"]), ("sim3", ["-as"]), ("none", [])):
        mine = ours(seamless, gt, est, work, align)
        compare(f"ATE {align}", mine, evo(bindir, "evo_ape", common + flags, work, "ape_" + align), "ate", "m")
        rpe_flags = ["-d", "1", "-u", "f"] + (["-as"] if align == "sim3" else [])
        compare(f"RPE/frame trans {align}", mine,
                evo(bindir, "evo_rpe", common + rpe_flags + ["-r", "trans_part"], work, "rpe_t_" + align),
                "rpe_frame_trans", "m")
        compare(f"RPE/frame rot {align}", mine,
                evo(bindir, "evo_rpe", common + rpe_flags + ["-r", "angle_deg"], work, "rpe_r_" + align),
                "rpe_frame_rot", "deg")
    print("seamless eval agrees with evo")
    return 0


if __name__ == "__main__":
    sys.exit(main())
