"""Shortlist study, measured: every grasp ``optimal_plus`` shortlists, simulated one at a time on the same
drop, beside what the planner measured of it (``python -m graspexp bench.shortlist`` parses and prints)."""

from __future__ import annotations

import dataclasses
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pandas as pd
from threadpoolctl import threadpool_limits

from graspexp.config.compose import compose_config
from graspexp.datasets import available_objects
from graspexp.planning import plan
from graspexp.planning.optimal_plus import pick_shortlisted
from graspexp.planning.request import PlanResult
from graspexp.run.job_config import compose_job
from graspexp.run.objects import load_sim_object, trial_context
from graspexp.sim.trial import plain_config, run_trial

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
    loaded = load_sim_object(cfg, name, plain)
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
    (``objects=[...]`` among ``overrides``, else every staged one). Raises
    :class:`graspexp.config.ConfigError` for a bad override."""
    jobs = []
    for dataset in datasets:
        for setting in settings:
            mode, rot = setting.split("/")
            job = [f"dataset={dataset}", f"mode={mode}", f"rot={rot}", "planner=optimal_plus", *overrides]
            cfg = compose_job(job)
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
