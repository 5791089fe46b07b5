# Snakemake (7.x) workflow behind scripts/compare_trackers: one job per (sequence, tracker row) cell,
# each running `seamless track` and `seamless eval` (through `compare_trackers --cell`, which turns
# "not available in this build" into a table entry instead of a failed job), then one local job
# that writes trackers.md, trackers.tex, results.json and the plots.
#
# Do not call it by hand: scripts/compare_trackers asks the binary for its tracker kinds, writes
# the grid (OUT/grid.json: sequences, rows, binary, config) and runs
#   snakemake -s scripts/sweep/compare_trackers.smk --configfile OUT/grid.json --directory OUT --cores N
# or, on a Slurm cluster, the same with --slurm --jobs N --default-resources ... (docs/REPRODUCE.md).
import json
import os

GRID = config["grid"]
OUT = config["out"]
PYTHON = config["python"]
COMPARE = config["compare"]
SEQS = list(config["sequences"])
ROWS = config["rows"]  # row id (the row's name, spaces as _) -> kind, mode, --set overrides, status
PLOTS = bool(config.get("plots", True))

wildcard_constraints:
    seq="[^/]+", row="[^/]+"

localrules: all, aggregate


rule all:
    input:
        f"{OUT}/trackers.md",


rule cell:
    input:
        # written by compare_trackers only when the cell's settings change, so --resume reruns
        # exactly the cells whose settings differ from the last run
        f"{OUT}/{{seq}}/{{row}}/spec.json",
    output:
        f"{OUT}/{{seq}}/{{row}}/cell.json",
    log:
        f"{OUT}/logs/{{seq}}__{{row}}.log",
    threads: int(config.get("threads", 1))
    resources:
        runtime=int(config.get("runtime_min", 60)),
        mem_mb=int(config.get("mem_mb", 8000)),
        slurm_extra=config.get("slurm_extra", ""),
    shell:
        "{PYTHON} {COMPARE} --cell {input} > {log} 2>&1"


rule aggregate:
    input:
        expand(f"{OUT}/{{seq}}/{{row}}/cell.json", seq=SEQS, row=list(ROWS)),
    output:
        md=f"{OUT}/trackers.md",
        tex=f"{OUT}/trackers.tex",
        json=f"{OUT}/results.json",
    log:
        f"{OUT}/logs/aggregate.log",
    shell:
        "{PYTHON} {COMPARE} --aggregate {GRID} > {log} 2>&1"
