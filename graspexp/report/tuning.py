"""The tuning report (``docs/results/tuning.md``): what an Optuna study searched and found on its training
objects, and the study's best parameters beside the baseline (the config's own values: the paper's
constants) on held-out objects, with Wilson 95 % intervals and a paired test.

Both sets run the same trials (the drop pose of a trial derives from (seed, dataset, object, trial index),
never from the cost constants), so the comparison is paired: McNemar's exact test on the trials where
exactly one of the two succeeded.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import pandas as pd
from scipy.stats import binomtest

from graspexp.config.job import JobConfig
from graspexp.report.collect import ran
from graspexp.report.stats import success_pct
from graspexp.report.study import SweepStudy, is_log_scale

if TYPE_CHECKING:
    import optuna


@dataclass(frozen=True)
class ScoredSet:
    """One parameter set run on the scoring objects."""

    label: str
    params: dict[str, object]
    """Searched key (``cost.angle_weight``) -> value."""
    results: pd.DataFrame
    """One row per trial (the job's ``results.csv``): ``object``, ``trial``, ``success``, ..."""
    run_dir: Path
    wall_s: float
    trial: int | None = None
    """The study trial these parameters come from; None for the baseline (the config's values)."""


OBJECTIVE_WORDS = {
    "success": "the mean over objects of each object's success rate",
    "worst_object": "the lowest object's success rate",
}
"""Each ``objective`` (:data:`graspexp.config.job.OBJECTIVES`) in words, for the report."""


def _rate(df: pd.DataFrame) -> str:
    """Success of the trials that ran (:func:`graspexp.report.collect.ran`; "not run" when none did)."""
    df = ran(df)
    if df.empty:
        return "not run"
    k, n = int(df["success"].sum()), len(df)
    pct, lo, hi = success_pct(k, n)
    return f"{pct:.1f} % [{lo:.1f}, {hi:.1f}] ({k}/{n})"


def _reasons(df: pd.DataFrame) -> str:
    """Failure reasons with their counts, the most frequent first (``none`` when every trial held)."""
    counts = df.loc[~df["success"].astype(bool), "reason"].value_counts()
    return ", ".join(f"{reason} {n}" for reason, n in counts.items()) or "none"


def paired_test(a: pd.DataFrame, b: pd.DataFrame) -> tuple[int, int, float]:
    """(trials only ``a`` won, trials only ``b`` won, McNemar's exact two-sided p-value), matching trials
    by (object, trial); p is 1 when no trial differs."""
    keys = ["object", "trial"]
    a, b = ran(a), ran(b)  # a trial not run in either set is no win for the other
    m = a[keys + ["success"]].merge(b[keys + ["success"]], on=keys, suffixes=("_a", "_b"))
    only_a = int((m["success_a"] & ~m["success_b"]).sum())
    only_b = int((~m["success_a"] & m["success_b"]).sum())
    p = binomtest(only_a, only_a + only_b, 0.5).pvalue if only_a + only_b else 1.0
    return only_a, only_b, float(p)


def _max_factor(base: dict[str, object], other: dict[str, object]) -> float:
    """The largest ratio (>= 1) between two sets' positive numeric values of the same key; 1 when none."""
    ratios = [
        max(float(v) / float(base[k]), float(base[k]) / float(v))
        for k, v in other.items()
        if isinstance(v, int | float)
        and isinstance(base.get(k), int | float)
        and float(v) > 0 < float(base[k])
    ]
    return max(ratios, default=1.0)


def _search_lines(sweep: SweepStudy, scored: list[ScoredSet]) -> list[str]:
    dists = sweep.study.best_trial.distributions
    base, cand = scored[0], scored[-1]
    lines = [f"| parameter | searched | {base.label} | {cand.label} |", "|---|---|---|---|"]
    for key in sweep.searched:
        d = dists.get(key)
        low, high = getattr(d, "low", None), getattr(d, "high", None)
        scale = " log" if is_log_scale(d) else ""
        rng = f"[{low:g}, {high:g}]{scale}" if low is not None else str(getattr(d, "choices", ""))
        lines.append(
            f"| `{key}` | {rng} | {base.params.get(key)} | {cand.params.get(key, float('nan')):.4g} |"
        )
    return lines


def tuning_markdown(sweep: SweepStudy, scored: list[ScoredSet], command: str, pngs: list[str]) -> str:
    """The report as Markdown: the study (trials, search space, train objective of the baseline, trial
    0, and of the best trial), the scoring table per object and overall, the paired test, and the plots."""
    study = sweep.study
    trials = study.get_trials(deepcopy=False)
    done = [t for t in trials if t.state.name == "COMPLETE"]
    best = study.best_trial
    ties = sum(t.value == best.value for t in done)
    baseline, tuned = scored[0], scored[-1]
    fixed = [o for o in sweep.task_overrides if o.split("=", 1)[0] not in sweep.searched]
    objective = next((o.split("=", 1)[1] for o in fixed if o.startswith("objective=")), JobConfig.objective)
    trial0 = trials[0].value if trials and trials[0].state.name == "COMPLETE" else float("nan")
    out = [
        "# Tuning the paper's constants: study and held-out score",
        "",
        f"Generated by `{command}`; do not edit by hand.",
        "",
        "## Study (training objects)",
        "",
        f"- Storage `{sweep.storage}`, study `{study.study_name}`: {len(trials)} trials, {len(done)} complete, "
        f"{sum(t.state.name == 'FAIL' for t in trials)} failed; direction {study.direction.name.lower()}.",
        f"- Fixed overrides: `{' '.join(fixed)}`; objective `{objective}` ({OBJECTIVE_WORDS[objective]}).",
        f"- Objective on the training objects: baseline (trial 0, the config's values) {trial0:.4f}; best "
        f"{best.value:.4f} (trial {best.number}; {ties} complete trial(s) reach that value, the first is "
        "the best)." + ("" if best.number else " No trial beat the baseline on the training objects."),
        f"- Scored below as `{tuned.label}`: trial {tuned.trial}, objective on the training objects "
        f"{study.trials[tuned.trial].value:.4f}; its values differ from the {baseline.label}'s by up to a "
        f"factor {_max_factor(baseline.params, tuned.params):.3g}.",
        "- Objective of the complete trials (value: count): "
        + ", ".join(f"{v:.4f}: {n}" for v, n in sorted(Counter(t.value for t in done).items(), reverse=True))
        + f"; the study's jobs took {sum(t.duration.total_seconds() for t in done) / 60:.1f} min of wall time.",
        "",
        *_search_lines(sweep, scored),
        "",
        "## Held-out objects",
        "",
        f"Each set runs the same {len(baseline.results)} trials (same objects, trial indices and seeds); "
        "success rate with its Wilson 95 % interval.",
        "",
        f"| object | {' | '.join(s.label for s in scored)} |",
        f"|---|{'---|' * len(scored)}",
    ]
    for obj in baseline.results["object"].drop_duplicates():
        cells = [_rate(s.results[s.results["object"] == obj]) for s in scored]
        out.append(f"| {obj} | {' | '.join(cells)} |")
    out.append(f"| **all objects** | {' | '.join(f'**{_rate(s.results)}**' for s in scored)} |")
    only_base, only_tuned, p = paired_test(baseline.results, tuned.results)
    gain = 100.0 * (ran(tuned.results)["success"].mean() - ran(baseline.results)["success"].mean())
    out += [
        "",
        f"- {tuned.label} minus {baseline.label}: {gain:+.1f} percentage points; trials only {baseline.label} "
        f"won: {only_base}, only {tuned.label} won: {only_tuned}; McNemar exact p = {p:.3g}.",
        *(f"- Failures of {s.label}: {_reasons(s.results)}." for s in scored),
        f"- Wall time: {', '.join(f'{s.label} {s.wall_s:.0f} s' for s in scored)}; runs in "
        f"{', '.join(f'`{s.run_dir}`' for s in scored)}.",
        "",
        *[f"![{Path(png).stem}]({png})" for png in pngs],
        "",
    ]
    return "\n".join(out)


def scored_trial(study: optuna.Study) -> int | None:
    """The trial to score beside the baseline: None (the best trial) when a trial beat trial 0 (the
    config's own values) on the training objects; else, of the complete trials tied with trial 0, the one
    whose values lie farthest from trial 0's (:func:`_max_factor`): the most different set that trains
    as well, a fair test of whether the constants matter on held-out objects."""
    trials = [t for t in study.get_trials(deepcopy=False) if t.state.name == "COMPLETE"]
    first = study.trials[0]
    if study.best_trial.number != first.number or first.state.name != "COMPLETE":
        return None
    ties = [t for t in trials if t.value == first.value and t.number != first.number]
    if not ties:
        return None
    return max(ties, key=lambda t: (_max_factor(first.params, t.params), -t.number)).number
