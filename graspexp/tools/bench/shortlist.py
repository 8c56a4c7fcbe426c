"""Shortlist study: every grasp ``optimal_plus`` shortlists, simulated one at a time on the same drop,
beside what the planner measured of it.

    python -m graspexp bench.shortlist [--out shortlist.csv] [--n-jobs 2] [trials=5] [mode=collab,bin]
        [rot=z,xyz] [dataset=ycb,linemod] [objects=[a,b]] [key=value ...]

For each dataset, setting, object and trial the planner runs once; each of its S shortlisted paths
(``details.shortlist``, graspexp/planning/optimal_plus.py) is then executed in a fresh trial on the
same drop by a planner that returns that grasp. One CSV row per simulated grasp: held or not, the failure
reason, the edge excess (how far the object reaches past a pad's contact plane by the finger edges, the
measure ``choose_by=edge_clearance`` minimises), the pad depth, whether it passed the noise check, and
which grasp each ``choose_by`` rule picks. Prints the share held per band of edge excess and how often each
rule's pick is held. ``key=value`` arguments are job overrides (``planner.*``, ``sim.*``, ...); ``dataset=``,
``mode=`` and ``rot=`` take several values (every combination runs; default the paper's), ``trials=`` is
the drops per object and setting (default 5), ``objects=[...]`` a subset (default every staged one).
"""

from __future__ import annotations

import dataclasses
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd
from threadpoolctl import threadpool_limits

from graspexp.config.compose import compose_config
from graspexp.datasets import available_objects
from graspexp.planning import plan
from graspexp.planning.optimal_plus import pick_shortlisted
from graspexp.planning.request import PlanResult
from graspexp.run.objects import load_object, trial_context
from graspexp.run.suites import PAPER_DATASETS, PAPER_MODES, PAPER_ROTS
from graspexp.sim.trial import plain_config, run_trial
from graspexp.tools.cli import compose_checked, fail, positive_int, take_sweep, tool_parser

PROG = "graspexp bench.shortlist"
RULES = ("edge_clearance", "cost")
"""The ``planner.choose_by`` rules whose picks are scored from the simulated shortlist."""
EXCESS_BANDS_MM = (-np.inf, 0.0, 0.5, 1.0, 2.0, 4.0, np.inf)
"""Bands of edge excess (mm) the printed table splits the grasps into."""


def _forced(j: int, seen: dict):
    """A planner that returns ``optimal_plus``'s ``j``-th shortlisted grasp. The drop, so the request, is
    the same in every trial of one drop: the plan is made in the first and kept in ``seen["plan"]``."""

    def planner(req):
        res = seen.get("plan") or seen.setdefault("plan", plan(req))
        short = res.details.shortlist
        grasp = dataclasses.replace(res.grasp, pose=short.poses[j], width_m=float(short.widths[j]))
        return PlanResult(grasp=grasp, details=res.details)

    return planner


def _job(args: tuple[list[str], str, int]) -> list[dict]:
    """Every shortlisted grasp of ``trials`` drops of one object in one job config (a worker's task)."""
    overrides, name, trials = args
    threadpool_limits(limits=1)
    cfg = compose_config(overrides)
    plain = plain_config(cfg)
    loaded = load_object(cfg, name, plain)
    rows = []
    for i in range(trials):
        seen: dict = {}
        j, n = 0, 1
        while j < n:
            res = run_trial(trial_context(plain, loaded, i, plan=_forced(j, seen)))
            if "plan" not in seen:  # no grasp planned for this drop: nothing to compare
                break
            short = seen["plan"].details.shortlist
            n = len(short.costs)
            rows.append(
                {
                    "object": name,
                    "trial": i,
                    "candidate": j,
                    "held": res.success,
                    "reason": res.reason or "",
                    "edge_excess_mm": 1000 * float(short.edge_excess_m[j]),
                    "pad_depth_mm": 1000 * float(short.pad_depth_m[j]),
                    "robust": bool(short.robust[j]),
                    "cost": float(short.costs[j]),
                    **{
                        f"pick_{rule}": j
                        == pick_shortlisted(rule, short.costs, short.robust, short.edge_excess_m)
                        for rule in RULES
                    },
                }
            )
            j += 1
    return rows


def study(
    overrides: list[str],
    datasets: list[str],
    settings: list[str],
    trials: int,
    workers: int,
) -> pd.DataFrame:
    """One row per simulated shortlisted grasp (module doc), every dataset x ``mode/rot`` setting x object
    (``objects=[...]`` among ``overrides``, else every staged one)."""
    jobs = []
    for dataset in datasets:
        for setting in settings:
            mode, rot = setting.split("/")
            job = [f"dataset={dataset}", f"mode={mode}", f"rot={rot}", "planner=optimal_plus", *overrides]
            cfg = compose_checked(job, PROG)
            names = list(cfg.objects) if cfg.objects else available_objects(cfg.dataset)
            jobs += [((job, n, trials), dataset, setting) for n in names]
    frames = []
    with ProcessPoolExecutor(workers) as pool:
        for (_, dataset, setting), rows in zip(jobs, pool.map(_job, [j for j, _, _ in jobs]), strict=True):
            print(f"{dataset} {setting} {rows[0]['object'] if rows else ''}: {len(rows)} grasps", flush=True)
            frames.append(pd.DataFrame(rows).assign(dataset=dataset, setting=setting))
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()


def summary(df: pd.DataFrame) -> str:
    """Held % (grasps) per band of edge excess and per rule's pick, per dataset, as Markdown."""
    edges = EXCESS_BANDS_MM
    labels = (
        [f"<= {edges[1]:g}"]
        + [f"{a:g} - {b:g}" for a, b in zip(edges[1:-2], edges[2:-1], strict=True)]
        + [f"> {edges[-2]:g}"]
    )
    band = pd.cut(df["edge_excess_mm"], edges, labels=labels)
    held = df.groupby([band, "dataset"], observed=True)["held"]
    table = (100 * held.mean()).round(1).astype(str) + " % (" + held.size().astype(str) + ")"
    picks = {
        rule: df[df[f"pick_{rule}"]].groupby("dataset")["held"].agg(lambda h: f"{int(h.sum())} / {len(h)}")
        for rule in RULES
    }
    return (
        "Shortlisted grasps held, % (grasps), by edge excess (mm):\n\n"
        + table.unstack("dataset").fillna("").to_markdown()
        + "\n\nDrops whose pick is held, per planner.choose_by rule:\n\n"
        + pd.DataFrame(picks).to_markdown()
    )


def main(argv: list[str] | None = None) -> int:
    ap = tool_parser(PROG, __doc__, overrides=True)
    ap.add_argument(
        "--out", type=Path, default=Path("shortlist.csv"), help="CSV written (default shortlist.csv)"
    )
    ap.add_argument("--n-jobs", type=positive_int, default=2, help="processes (default 2)")
    args = ap.parse_intermixed_args(argv)
    if args.n_jobs < 1:
        fail(f"--n-jobs {args.n_jobs} is invalid: expected 1 or more processes", PROG)
    datasets, rest = take_sweep(args.overrides, "dataset", PAPER_DATASETS)
    modes, rest = take_sweep(rest, "mode", PAPER_MODES)
    rots, rest = take_sweep(rest, "rot", PAPER_ROTS)
    trials, rest = take_sweep(rest, "trials", ["5"])
    if len(trials) != 1 or not trials[0].isdigit() or int(trials[0]) < 1:
        fail(f"trials={','.join(trials)} is invalid: expected one positive integer", PROG)
    settings = [f"{m}/{r}" for m in modes for r in rots]
    df = study(rest, datasets, settings, int(trials[0]), args.n_jobs)
    if df.empty:
        fail("no grasp was planned: nothing to simulate", PROG)
    df.to_csv(args.out, index=False)
    print(summary(df))
    print(f"{PROG}: {len(df)} grasps in {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
