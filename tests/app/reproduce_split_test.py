#!/usr/bin/python3
"""The split scripts/reproduce for a machine without Python's yaml or matplotlib (the GPU
machine): `--plan FILE` writes the run's seamless commands as a bash script, the script runs with
nothing but bash, mkdir, rm and the seamless binary on PATH, and `--from-runs DIR` builds the tables
and figures from what it left. At the smoke size (one figure, the fluid case of table 5.1, a
two-point figure 5.8 sweep).

usage: reproduce_split_test.py SEAMLESS SOURCE_DIR WORK_DIR

Checks, against what the plan is meant to do rather than against printed numbers:
- the plan runs with PATH holding only bash, mkdir and rm (so no python3 or other tool);
- every step leaves its .done marker, wall time and log, and a second call skips finished steps;
- --from-runs reports the run's own commit (the plan's) and device (host.txt), writes a table
  5.1 row with a positive time for the fluid case and one figure 5.8 row per layout and size;
- a broken binary makes the plan exit non-zero and name the failed steps;
- with ../shared/data beside the source tree: the real set's smoke step (fig5_1 on the
  first 8 frames of tum_fr1_rpy_000-149) reads DATA, finishes, and --from-runs lists its settings
  as run: 8 frames (120-127), ground-truth poses and the config's 14 x 8 x 14 = 1568 water
  particles (a 0.28 x 0.16 x 0.28 m block of 2 cm particles); its figure is there whenever the
  synthetic one is (both need a GL renderer). Without DATA's recording the step is skipped, not
  failed.
"""
import csv
import json
import os
import re
import shutil
import subprocess
import sys


def run(cmd, **kw):
    print(" ".join(cmd), flush=True)
    return subprocess.run(cmd, text=True, capture_output=True, **kw)


def bare_path(work):
    """A PATH with bash, mkdir and rm only."""
    d = os.path.join(work, "bare_bin")
    os.makedirs(d)
    for tool in ("bash", "mkdir", "rm"):
        os.symlink(shutil.which(tool), os.path.join(d, tool))
    return d


def main():
    exe, src, work = sys.argv[1:4]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    reproduce = os.path.join(src, "scripts", "reproduce")
    plan, runs, out = os.path.join(work, "plan.sh"), os.path.join(work, "runs"), os.path.join(work, "out")
    r = run([sys.executable, reproduce, "--smoke", "--plan", plan, "--device", "cpu"], cwd=src)
    assert r.returncode == 0, r.stdout + r.stderr
    steps = re.findall(r"^(?:step|data_step \S+) (\S+) ", open(plan).read(), re.M)
    data = os.path.normpath(os.path.join(src, "..", "shared", "data"))
    real = os.path.isdir(os.path.join(data, "tum_fr1_rpy_000-149"))
    assert "real_fig5_1_fluid_desk" in steps, steps
    assert steps[0] == "fig5_1_fluid_desk" and "bench_physics" in steps, steps
    assert sum(s.startswith("recon_") for s in steps) == 4, steps

    env = {"PATH": bare_path(work), "SEAMLESS": os.path.abspath(exe), "RUNS": runs}
    r = run(["bash", plan], cwd=src, env=env)
    print(r.stdout, r.stderr)
    assert r.returncode == 0, "the plan failed with only bash, mkdir and rm on PATH"
    if not real:
        assert "real_fig5_1_fluid_desk: skipped, no recording" in r.stdout, r.stdout
        print(f"no {data}/tum_fr1_rpy_000-149: the real step was skipped (as it should); not checked further")
        steps.remove("real_fig5_1_fluid_desk")
    for s in steps:
        for ext in (".done", ".ms", ".log"):
            assert os.path.exists(os.path.join(runs, s + ext)), f"{s}{ext} missing"
        assert int(open(os.path.join(runs, s + ".ms")).read()) >= 0
    r = run(["bash", plan, "bench"], cwd=src, env=env)
    assert r.returncode == 0 and "bench_physics: done before, skipped" in r.stdout, r.stdout + r.stderr

    r = run([sys.executable, reproduce, "--smoke", "--from-runs", runs, "--out", out, "--no-paper"], cwd=src)
    print(r.stdout, r.stderr)
    assert r.returncode == 0, "--from-runs failed"
    plan_meta = json.load(open(os.path.join(runs, "plan.json")))
    host = dict(l.split(":", 1) for l in open(os.path.join(runs, "host.txt")) if ":" in l)
    meta = open(os.path.join(out, "meta.tex")).read()
    assert f"\\ReproCommit}}{{{plan_meta['commit']}}}" in meta, meta
    assert host["cpu"].strip().split()[0] in meta, f"device of host.txt ({host['cpu']}) not in {meta}"
    assert "\\ReproMode}{smoke}" in meta, meta
    tables = open(os.path.join(out, "tables.md")).read()
    m = re.search(r"\| Fluid \| 10,000 \| 8\.33 ms \| ([0-9.]+) ms \|", tables)
    assert m and float(m.group(1)) > 0, tables
    with open(os.path.join(out, "fig5_8_recon.csv")) as f:
        rows = list(csv.DictReader(f))
    assert sorted((r["layout"], r["side"]) for r in rows) == [("dense", "100"), ("dense", "64"), ("hash", "100"),
                                                              ("hash", "64")], rows
    assert all(float(r["frame_ms"]) > 0 for r in rows), rows
    assert os.path.getsize(os.path.join(out, "figures", "fig5_8_recon.png")) > 0

    if real:
        settings = open(os.path.join(out, "real_settings.md")).read()
        row = re.search(r"^\| 5\.1 \| tum_fr1_rpy_000-149 \| (\S+) \| (\S+) \| (\d+) fluid \|", settings, re.M)
        assert row and row.groups() == ("120-127", "ground_truth", "1568"), settings
        assert os.path.exists(os.path.join(out, "real_settings.tex"))
        if os.path.exists(os.path.join(out, "figures", "fig5_1_fluid_desk.png")):
            assert os.path.exists(os.path.join(out, "figures", "real_fig5_1_fluid_desk.png")), "real figure missing"

    # a binary that fails: the plan carries on, then exits 1 naming the steps
    bad = os.path.join(work, "false_seamless")
    with open(bad, "w") as f:
        f.write("#!/bin/bash\nexit 3\n")
    os.chmod(bad, 0o755)
    r = run(["bash", plan, "recon_hash"], cwd=src,
            env=dict(env, SEAMLESS=bad, RUNS=os.path.join(work, "runs_bad")))
    assert r.returncode == 1, r.returncode
    assert "failed: recon_hash_64 recon_hash_100" in r.stderr, r.stderr
    print("split reproduce: plan, bare bash run, resume and --from-runs all right")
    return 0


if __name__ == "__main__":
    sys.exit(main())
