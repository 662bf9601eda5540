"""``workbench stress --out DIR``: the stiff and extreme cases of the catalogue, with verdicts."""
from __future__ import annotations


def add_parser(sub):
    p = sub.add_parser("stress", help="run the stiff/extreme case catalogue; table with expected, measured, verdict")
    p.add_argument("--out", required=True, help="output folder (stress.csv, stress.json, stress.md, stress.html)")
    p.add_argument("--only", metavar="PATTERN", help="case ids matching this (substring or shell pattern)")
    p.add_argument("--catalogue", help="catalogue file (default: stress/cases.toml of the repository)")
    p.add_argument("--jobs", type=int, default=1,
                   help="worker processes for the cases (default 1: in this process, one after the other; "
                        "with more, the rows' times share the cores)")
    p.add_argument("--cluster", metavar="ADDRESS",
                   help="run the cases on the workers of a Dask scheduler, e.g. tcp://HOST:8786 (needs "
                        "workbench[cluster] here and the same workbench version on every worker; not with "
                        "--jobs above 1; docs/guide/cluster.md)")
    p.set_defaults(run=run)


def run(args) -> int:
    import sys
    from pathlib import Path

    from ..compare.executors import check_options
    from ..compare.stress import CATALOGUE, stress
    from ..core.output_paths import check_output_dir
    check_options(args.jobs, args.cluster)
    check_output_dir(args.out, "--out")
    res = stress(args.out, only=args.only, catalogue=args.catalogue or CATALOGUE, progress=sys.stderr.isatty(),
                 command=" ".join(["workbench"] + sys.argv[1:]), jobs=args.jobs, cluster=args.cluster)
    for r in res["rows"]:
        print(f"  {r['case']:<32} {r['method']:<10} {r['verdict']}")
    print("summary: " + ", ".join(f"{k} {v}" for k, v in res["summary"].items()))
    print(f"table: {(Path(args.out) / 'stress.html').resolve()}")
    return 0
