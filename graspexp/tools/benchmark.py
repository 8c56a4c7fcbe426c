"""``python -m graspexp benchmark [--option ...] planner=NAME [dataset=...] [key=value ...]``: the standard
suite for any installed planner, ranked beside the built-in planners and the paper's published numbers.

The standard suite: the paper's four settings (collab / bin x rotation z / xyz) on Table 1 (``ycb``) and
Table 2 (``linemod``), :data:`graspexp.report.paper.TRIALS_PER_SETTING` trials per object, at zero pose
noise and at each of :data:`NOISE_LEVELS`. Every planner runs the same drops (a drop depends only on the
seed, dataset, object and trial index).

``key=value`` arguments are job overrides, as for every tool: ``planner=NAME`` (required) is the planner
entered; ``dataset=`` one dataset or several (``dataset=ycb,linemod``, the default); ``trials=``;
``objects=[...]`` a subset; ``planner.*`` keys go to the entered planner only, the rest (``gripper=``,
``sim.*``, ...) to every planner. Options:

- ``mode=collab,bin`` / ``rot=z,xyz``: the settings, every combination of the values given (default the
  paper's four);
- ``--noise 10:0,0:10``: pose-noise levels ``trans_mm:rot_deg`` besides zero (``--noise ''``: none);
- ``--compare obb,random``: planners ranked beside it (default the built-in ones; they run too where
  their results are missing, once, and are reused by every later entrant);
- ``--out DIR`` (default ``outputs/benchmark``); ``--n-jobs N`` (default 2): jobs in parallel with Hydra's
  joblib launcher;
- ``--launcher submitit``: Hydra's submitit launcher, one SLURM array task per job (``--slurm-partition``,
  ``--timeout-min``; without a partition, local processes).

Jobs launch as every graspexp sweep does: one Hydra multirun per planner (``python -m graspexp -m ...``),
so a job that cannot run is named in that sweep's failure summary and the others run.

Output, one folder per planner, ``OUT/<planner>/``: ``runs/<dataset>/<mode>_<rot>_t<mm>_r<deg>/`` (the
runner's job directories: resumable, locked, one MCAP log per trial), ``summary.md`` (ranking and tables),
``ranking.csv``, ``trials.csv`` (per trial: outcome and in-area contact fraction), ``noise.csv``,
``failures.csv`` and ``reproduce.json`` (command, every job's composed
config, package versions, planner package and version). Re-running the same command resumes.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd
import yaml
from omegaconf import OmegaConf

from graspexp.config import ConfigError, PluginError
from graspexp.config.plugins import LoadedPlanner, get_plugin, load_planners
from graspexp.core.run_layout import results_csv
from graspexp.report.collect import collect
from graspexp.report.compare import FC_MU, check_same_drops, render_markdown
from graspexp.report.compare import success_by_noise as noise_success_table
from graspexp.report.contact_area import IN_AREA_TOLERANCE_M, finger_contacts_in_area
from graspexp.report.paper import PAPER_TABLES, SETTINGS, TRIALS_PER_SETTING
from graspexp.report.render import display_frame, footnotes, markdown
from graspexp.report.stats import percentiles, success_pct
from graspexp.report.tables import failure_breakdown, success_table
from graspexp.run.multirun import multirun_command
from graspexp.run.suites import NOISE_LEVELS, PAPER_MODES, PAPER_ROTS, Job, benchmark_suite
from graspexp.tools.cli import compose_checked, fail, positive_int, tool_parser

TRIAL_COLUMNS = (
    "planner",
    "dataset",
    "mode",
    "rot",
    "trans_mm",
    "rot_deg",
    "object",
    "trial",
    "success",
    "reason",
    "contacts",
    "contacts_in_area",
    "fc_min_mu",
    "plan_ms",
)
"""Columns of ``trials.csv``: one row per trial, with its in-area contact fraction beside its outcome."""
IN_AREA_NOTE = (
    "In-area contact %: share of the finger-object contacts at the end of closing that lie within "
    f"{IN_AREA_TOLERANCE_M * 1000:g} mm of a grasping-area point of the object's reference cloud "
    "(graspexp/report/contact_area.py; from each log's /contacts and /tf), over the trials whose fingers "
    "touch the object then. Trials all in area %: share of those trials whose every contact is in the area. "
    "Success in area: successful trials whose every contact is in the area (the hand-over task's success)."
)


@dataclass
class Benchmark:
    """What one ``python -m graspexp benchmark`` command runs (see the module doc)."""

    planner: str
    datasets: list[str] = field(default_factory=lambda: list(PAPER_TABLES))
    settings: list[str] = field(default_factory=lambda: [f"{m}/{r}" for m, r in SETTINGS])
    trials: int = TRIALS_PER_SETTING
    objects: list[str] | None = None
    noise: list[list[float]] = field(default_factory=lambda: [list(n) for n in NOISE_LEVELS])
    compare: list[str] | None = None
    out: str = "outputs/benchmark"
    n_jobs: int = 2
    launcher: str = "joblib"
    slurm_partition: str = ""
    timeout_min: int = 240
    overrides: list[str] = field(default_factory=list)


PROG = "graspexp benchmark"
SUITE_KEYS = ("planner", "dataset", "mode", "rot", "trials", "objects")
"""Job keys whose values choose the suite (the other overrides are passed on to every job)."""


def _names(text: str) -> list[str]:
    """``a,b`` or ``[a,b]`` -> ``["a", "b"]``."""
    return [t.strip() for t in text.strip().strip("[]").split(",") if t.strip()]


def _noise_levels(text: str) -> list[list[float]]:
    """``10:0,0:10`` -> ``[[10.0, 0.0], [0.0, 10.0]]``; ``''`` -> ``[]``."""
    try:
        return [[float(v) for v in level.split(":")] for level in _names(text)]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected trans_mm:rot_deg levels, e.g. 10:0,0:10"
        ) from None


def arg_parser() -> argparse.ArgumentParser:
    """The benchmark's command line (module doc)."""
    parser = tool_parser(PROG, __doc__, overrides=True)
    parser.add_argument("--noise", type=_noise_levels, help="trans_mm:rot_deg levels besides zero")
    parser.add_argument(
        "--compare", type=_names, help="planners ranked beside it (default: the built-in ones)"
    )
    parser.add_argument("--out", default=Benchmark.out, help=f"output folder (default {Benchmark.out})")
    parser.add_argument(
        "--n-jobs", type=positive_int, default=Benchmark.n_jobs, help="jobs in parallel (joblib)"
    )
    parser.add_argument("--launcher", choices=("joblib", "submitit"), default=Benchmark.launcher)
    parser.add_argument("--slurm-partition", default=Benchmark.slurm_partition, help="with submitit")
    parser.add_argument("--timeout-min", type=int, default=Benchmark.timeout_min, help="with submitit")
    return parser


def parse_args(argv: list[str]) -> Benchmark:
    """The command line (module doc) -> :class:`Benchmark`."""
    args = arg_parser().parse_intermixed_args(argv)
    values: dict = {"overrides": []}
    for tok in args.overrides:
        key, sep, raw = tok.partition("=")
        if key not in SUITE_KEYS or not sep:
            values["overrides"].append(tok)
        elif key == "dataset":
            values["datasets"] = _names(raw)
        elif key in ("mode", "rot"):
            values[key] = _names(raw)
        else:
            values[key] = yaml.safe_load(raw) if key != "planner" else raw
    if "planner" not in values:
        raise ConfigError("planner is missing: python -m graspexp benchmark planner=NAME [dataset=...]")
    modes, rots = values.pop("mode", None), values.pop("rot", None)
    if modes or rots:  # every combination of the given modes and rotations, in the paper's order
        values["settings"] = [f"{m}/{r}" for m in (modes or PAPER_MODES) for r in (rots or PAPER_ROTS)]
    options = ("noise", "compare", "out", "n_jobs", "launcher", "slurm_partition", "timeout_min")
    return Benchmark(**values, **{k: getattr(args, k) for k in options if getattr(args, k) is not None})


def compared(bench: Benchmark) -> list[str]:
    """The planners ranked beside the entered one: ``compare`` or every built-in planner."""
    if bench.compare is not None:
        return [p for p in bench.compare if p != bench.planner]
    builtin = [
        n
        for n, p in load_planners().items()
        if isinstance(p, LoadedPlanner) and p.package.startswith("graspexp ")
    ]
    return [n for n in builtin if n != bench.planner]


def jobs(bench: Benchmark) -> list[Job]:
    """Every (planner, dataset, setting, noise level) job of the suite, entered planner first
    (:func:`graspexp.run.suites.benchmark_suite`)."""
    return benchmark_suite(
        [bench.planner, *compared(bench)],
        bench.datasets,
        bench.settings,
        [(float(t), float(r)) for t, r in bench.noise],
        bench.trials,
        bench.objects,
        bench.overrides,
        Path(bench.out),
    )


RUN_SUBDIR = (
    "${dataset.name}/${mode.name}_${rot.name}"
    "_t${graspexp.g:${perception.noise.trans_mm}}_r${graspexp.g:${perception.noise.rot_deg}}"
)
"""Each job's directory below ``OUT/<planner>/runs`` (Hydra's ``hydra.sweep.subdir``), as :func:`jobs`
names it: ``<dataset>/<mode>_<rot>_t<mm>_r<deg>``."""
JOB_KEYS = ("planner", "dataset", "mode", "rot", "perception.noise.trans_mm", "perception.noise.rot_deg")
"""The overrides a job of :func:`jobs` sets itself; the sweep of one planner sweeps them."""


def sweep_command(bench: Benchmark, planner_jobs: list[Job]) -> list[str]:
    """One Hydra multirun that runs every job of one planner (the same planner and overrides; every
    combination of their datasets, settings and noise levels), each into its :attr:`Job.run_dir`, with
    the joblib launcher (``--n-jobs``) or submitit (SLURM with ``--slurm-partition``, else local)."""
    first = planner_jobs[0]
    rest = [o for o in first.overrides if o.split("=", 1)[0] not in JOB_KEYS]
    levels = dict.fromkeys((j.trans_mm, j.rot_deg) for j in planner_jobs)
    noise = ",".join(f"{{trans_mm:{t:g},rot_deg:{r:g}}}" for t, r in levels)
    if bench.launcher == "submitit":
        kind = "submitit_slurm" if bench.slurm_partition else "submitit_local"
        launcher = [f"hydra/launcher={kind}", f"hydra.launcher.timeout_min={bench.timeout_min}"]
        launcher += ["hydra.launcher.cpus_per_task=1"]
        launcher += [f"hydra.launcher.partition={bench.slurm_partition}"] if bench.slurm_partition else []
    else:
        launcher = ["hydra/launcher=joblib", f"hydra.launcher.n_jobs={bench.n_jobs}"]
    overrides = [
        f"planner={first.planner}",
        f"dataset={','.join(dict.fromkeys(j.dataset for j in planner_jobs))}",
        f"mode={','.join(dict.fromkeys(j.mode for j in planner_jobs))}",
        f"rot={','.join(dict.fromkeys(j.rot for j in planner_jobs))}",
        f"perception.noise={noise}",
        *rest,
        f"hydra.sweep.subdir='{RUN_SUBDIR}'",  # quoted: Hydra resolves it per job
        *launcher,  # last: the benchmark's launcher keys win over any in the job overrides
    ]
    return multirun_command(Path(bench.out) / first.planner / "runs", overrides, launcher=())


def run_all(bench: Benchmark, todo: list[Job]) -> list[str]:
    """Run (or resume) the jobs, one Hydra multirun per planner (a failed job is named in its sweep's
    failure summary on stderr; the others run); the error line of each job left without results."""
    errors = []
    by_planner: dict[str, list[Job]] = {}
    for job in todo:
        by_planner.setdefault(job.planner, []).append(job)
    for planner_jobs in by_planner.values():
        rc = subprocess.call(sweep_command(bench, planner_jobs))
        for job in planner_jobs:
            if not results_csv(job.run_dir).is_file():
                errors.append(f"{job.run_dir}: no results (the sweep of {job.planner} exited {rc})")
    return errors


def results(all_jobs: list[Job]) -> pd.DataFrame:
    """One row per readable trial log of every job: report.collect columns plus trans_mm, rot_deg and the
    finger-object contacts at the end of closing (``contacts``) and how many lie in the grasping area
    (``contacts_in_area``)."""
    frames = []
    for job in all_jobs:
        if Path(job.run_dir).is_dir():
            df = collect(job.run_dir).results
            if not df.empty:
                counts = [finger_contacts_in_area(p) for p in df["path"]]
                df = df.assign(
                    trans_mm=job.trans_mm,
                    rot_deg=job.rot_deg,
                    contacts_in_area=[c[0] for c in counts],
                    contacts=[c[1] for c in counts],
                )
                frames.append(df)
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()


def _success(g: pd.DataFrame) -> str:
    n = len(g)
    rate, lo, hi = success_pct(int(g["success"].sum()), n)
    return f"{rate:.0f} [{lo:.0f}, {hi:.0f}] ({n})" if n else "n/a"


def ranking(df: pd.DataFrame, dataset: str, settings: list[str]) -> pd.DataFrame:
    """Zero-noise trials of one dataset: one row per planner, best success first, then the paper's
    printed Average of its own method (where the paper reports this dataset)."""
    rows = []
    zero = df[(df["dataset"] == dataset) & (df["trans_mm"] == 0) & (df["rot_deg"] == 0)]
    for planner, g in zero.groupby("planner", sort=True):
        row = {"planner": planner, "success % [95% CI] (n)": _success(g), "_rate": g["success"].mean()}
        for s in settings:
            mode, rot = s.split("/")
            row[s] = _success(g[(g["mode"] == mode) & (g["rot"] == rot)])
        planned = g[g["reason"] != "no_feasible_grasp"]
        touched = int(g["contacts"].sum())
        row["in-area contact %"] = f"{100 * g['contacts_in_area'].sum() / touched:.0f}" if touched else "n/a"
        held = g[g["contacts"] > 0]
        all_in = (held["contacts_in_area"] == held["contacts"]).mean() if len(held) else math.nan
        row["trials all in area %"] = f"{100 * all_in:.0f}" if len(held) else "n/a"
        in_area_success = g["success"] & (g["contacts"] > 0) & (g["contacts_in_area"] == g["contacts"])
        row["success in area % [95% CI]"] = _success(g.assign(success=in_area_success))
        row[f"force-closure % (mu<={FC_MU:g})"] = (
            f"{100 * (planned['fc_min_mu'] <= FC_MU + 1e-9).mean():.0f}" if len(planned) else "n/a"
        )
        mu = planned["fc_min_mu"].median() if len(planned) else math.nan
        row["median min mu"] = f"{mu:.2f}"
        p50, p95 = percentiles(g["plan_ms"])
        row["plan ms p50 / p95"] = f"{p50:.0f} / {p95:.0f}"
        reasons = g.loc[~g["success"], "reason"].fillna("(none)").value_counts()
        row["failures"] = ", ".join(f"{r} {c}" for r, c in reasons.head(3).items()) or "none"
        rows.append(row)
    table = pd.DataFrame(rows)
    if not table.empty:
        table = table.sort_values(["_rate", "planner"], ascending=[False, True]).drop(columns="_rate")
    paper = PAPER_TABLES.get(dataset)
    if paper is not None:
        printed = dict(zip([f"{m}/{r}" for m, r in SETTINGS], paper.ours_average, strict=True))
        shown = [printed[s] for s in settings if s in printed]
        row = {"planner": "paper (printed Average, its own method)"}
        row["success % [95% CI] (n)"] = f"{sum(shown) / len(shown):.0f}" if shown else "n/a"
        row.update({s: f"{printed[s]:.0f}" if s in printed else "n/a" for s in settings})
        table = pd.concat([table, pd.DataFrame([row])], ignore_index=True).fillna("")
    return table


def reproduce_record(bench: Benchmark, all_jobs: list[Job], configs: list[dict], argv: list[str]) -> dict:
    """Everything needed to re-run the suite: command, benchmark keys, each job's composed config
    (``configs``, in job order), package versions, and each planner's package, entry point and version."""
    from graspexp.run.provenance import package_versions

    planners = {}
    for name in dict.fromkeys(j.planner for j in all_jobs):
        p = get_plugin(name)
        planners[name] = {"package": p.package, "entry_point": p.entry_point, "version": p.version}
    return {
        "command": "python -m graspexp benchmark " + " ".join(argv),
        "benchmark": dataclasses.asdict(bench),
        "packages": package_versions(),
        "planners": planners,
        "jobs": [
            {
                **{k: v for k, v in dataclasses.asdict(j).items() if k != "overrides"},
                "overrides": list(j.overrides),
                "config": c,
            }
            for j, c in zip(all_jobs, configs, strict=True)
        ],
    }


def write_summary(
    bench: Benchmark, all_jobs: list[Job], configs: list[dict], errors: list[str], argv: list[str]
) -> str:
    """Write the result folder ``OUT/<planner>/`` (module doc); returns the Markdown summary."""
    out = Path(bench.out) / bench.planner
    out.mkdir(parents=True, exist_ok=True)
    df = results(all_jobs)
    lines = [f"# Benchmark: planner `{bench.planner}`", ""]
    if df.empty:
        lines.append("No readable trial logs.")
    else:
        df = df[df["planner"].isin([bench.planner, *compared(bench)])]
        rankings = []
        for dataset in bench.datasets:
            table = ranking(df, dataset, bench.settings)
            rankings.append(table.assign(dataset=dataset))
            lines += [f"## Ranking on `{dataset}` (zero pose noise)", "", markdown(table, index=False), ""]
        lines += [
            "Success: successes / trials with the Wilson 95 % score interval; plan time: wall time of the "
            f"plan call (ms); force-closure: share of planned grasps force-closure at mu <= {FC_MU:g}, and "
            "the median smallest such mu (NaN: none); failures: the three most frequent reasons.",
            IN_AREA_NOTE,
            "",
        ]
        pd.concat(rankings).to_csv(out / "ranking.csv", index=False)
        per_trial = df[[*TRIAL_COLUMNS]].assign(
            in_area_fraction=(df["contacts_in_area"] / df["contacts"].where(df["contacts"] > 0))
        )
        per_trial.to_csv(out / "trials.csv", index=False)
        zero = df[(df["trans_mm"] == 0) & (df["rot_deg"] == 0)]
        for dataset in bench.datasets:
            if dataset in PAPER_TABLES and (zero["dataset"] == dataset).any():
                st = success_table(zero, dataset, bench.planner)
                lines += [f"## `{bench.planner}` beside the paper's Table {st.paper.number}", ""]
                lines += [markdown(display_frame(st)), "", *(f"- {n}" for n in footnotes(st)), ""]
        noise = noise_success_table(df)
        noise.to_csv(out / "noise.csv", index=False)
        lines += ["## Every setting and pose-noise level", ""]
        lines += render_markdown(noise, check_same_drops(df), []).splitlines()[2:]
        failures = failure_breakdown(zero)
        failures.to_csv(out / "failures.csv", index=False)
        lines += ["", "## Failure reasons (zero pose noise)", "", markdown(failures, index=False), ""]
    if errors:
        lines += ["## Jobs that did not finish", "", *(f"- {e}" for e in errors), ""]
    text = "\n".join(lines) + "\n"
    (out / "summary.md").write_text(text)
    (out / "reproduce.json").write_text(
        json.dumps(reproduce_record(bench, all_jobs, configs, argv), indent=1)
    )
    return text


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    try:
        bench = parse_args(argv)
        get_plugin(bench.planner)
    except (ConfigError, PluginError) as exc:
        fail(str(exc), PROG)
    all_jobs = jobs(bench)
    # every job's config is checked before the first trial runs
    configs = [OmegaConf.to_container(compose_checked(j.overrides, PROG), resolve=True) for j in all_jobs]
    errors = run_all(bench, all_jobs)
    print(write_summary(bench, all_jobs, configs, errors, argv), end="")
    print(f"graspexp benchmark: results in {Path(bench.out) / bench.planner}", file=sys.stderr)
    for e in errors:
        print(f"graspexp benchmark: job failed: {e}", file=sys.stderr)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
