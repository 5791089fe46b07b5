#!/usr/bin/python3
"""Another system's trajectory in compare_trackers' tables (--extra NAME=FILE), with the
field's figures: the row's ATE and RPE are checked against numbers computed by others on the same
files, evo 1.38.1 (`evo_ape tum GT EST -a --t_max_diff 0.02`, `evo_rpe ... -d 1 -u f`) and TUM's
evaluate_rpe.py (`--fixed_delta --delta 1 --delta_unit s`); their provenance is in
tests/eval/evo_reference_test.cpp. The external file is tests/eval/data/tum_fr1_rpy_000-149_icp.txt
under a name with spaces and parentheses; the ground-truth tracker on 40 frames is the row beside it.

usage: compare_trackers_extra_test.py SEAMLESS SOURCE_DIR DATA_DIR OUT_DIR
Exit 77 (ctest: skipped) without snakemake or the shared data. About 30 s on 2 cores.
"""
import json
import os
import shutil
import subprocess
import sys

SKIP = 77
SEQ = "tum_fr1_rpy_000-149"
NAME = "other SLAM (v1)"
# evo / TUM's script on the same two files; the JSON carries full doubles, the tolerance is far
# below the 0.1 mm the comparison asks for and far above rounding.
REFERENCE = {"ate_rmse_m": 0.07952194358521113, "rpe_frame_trans_rmse_m": 0.009301277588343601,
             "rpe_frame_rot_rmse_deg": 0.6971432995627898, "rpe_second_trans_rmse_m": 0.14336711476163944,
             "rpe_second_rot_rmse_deg": 4.3116877057608045}


def main():
    seamless, src, data, out = sys.argv[1:5]
    seq = os.path.join(data, SEQ)
    if not os.path.isdir(seq):
        print(f"SKIP: {seq} is absent (shared test data)")
        return SKIP
    if not shutil.which("snakemake"):
        print("SKIP: snakemake is not installed (compare_trackers runs its grid through it)")
        return SKIP
    shutil.rmtree(out, ignore_errors=True)
    extra = os.path.join(src, "tests", "eval", "data", "tum_fr1_rpy_000-149_icp.txt")
    cmd = [sys.executable, os.path.join(src, "scripts", "compare_trackers"), seq, "--seamless", seamless,
           "--out", out, "--kinds", "ground_truth", "--no-ceres", "--frames", "40", "--device", "cpu",
           "--extra", f"{NAME}={extra}"]
    print(" ".join(cmd), flush=True)
    subprocess.run(cmd, check=True)
    rows = {r["tracker"]: r for r in json.load(open(os.path.join(out, "results.json")))}
    ext = rows[NAME]
    assert ext["status"] == "ok" and ext["kind"] == "external", ext
    assert ext["pairs"] == 150 and ext["lost"] is None, ext
    for key, want in REFERENCE.items():
        assert abs(ext[key] - want) < 1e-9, f"{key}: {ext[key]!r}, evo/TUM {want!r}"
    assert rows["ground_truth"]["status"] == "ok" and rows["ground_truth"]["ate_rmse_m"] < 0.001
    table = open(os.path.join(out, "trackers.md")).read()
    assert "RPE/s (cm/s)" in table and f"| {SEQ} | {NAME} | 7.95 | 0.93 | 0.70 | 14.34 | 4.31 | – | – |" in table, table
    assert os.path.exists(os.path.join(out, SEQ + ".png"))
    print(f"{NAME}: the table's row holds evo's and TUM's figures")
    return 0


if __name__ == "__main__":
    sys.exit(main())
