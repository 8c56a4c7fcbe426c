"""The benchmark of an installed planner (``python -m graspexp benchmark``): its jobs (the standard suite
for it and the planners it is ranked beside), their sweeps (one Hydra multirun per planner, resumable),
and the result folder ``OUT/<planner>/`` (:mod:`graspexp.report.benchmark`'s tables, ``summary.md`` and
``reproduce.json``: the command, every job's composed config, package and planner versions)."""

from __future__ import annotations

import dataclasses
import json
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from graspexp.config.plugins import LoadedPlanner, get_plugin, load_planners
from graspexp.core.rounds import RoundResult
from graspexp.core.run_layout import ROUNDS_CSV, SUMMARY_MD, results_csv
from graspexp.report.benchmark import clutter_lines, summary_lines
from graspexp.report.collect import collect
from graspexp.report.contact_area import finger_contacts_in_area
from graspexp.report.paper import PAPER_TABLES, SETTINGS, TRIALS_PER_SETTING
from graspexp.report.round_tables import find_rounds
from graspexp.run.job_config import clutter_modes
from graspexp.run.multirun import multirun_command
from graspexp.run.provenance import package_versions
from graspexp.run.suites import NOISE_LEVELS, Job, benchmark_suite


@dataclass
class Benchmark:
    """What one ``python -m graspexp benchmark`` command runs (its options: :mod:`graspexp.tools.benchmark`)."""

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
            done = Path(job.run_dir) / ROUNDS_CSV if job.mode in clutter_modes() else results_csv(job.run_dir)
            if not done.is_file():
                errors.append(f"{job.run_dir}: no results (the sweep of {job.planner} exited {rc})")
    return errors


def clutter_rounds(all_jobs: list[Job]) -> dict[tuple[float, float], list[RoundResult]]:
    """The rounds of the clutter jobs, per pose-noise level (mm, degrees), zero first."""
    levels: dict[tuple[float, float], list[RoundResult]] = {}
    for job in all_jobs:
        if job.mode in clutter_modes() and Path(job.run_dir).is_dir():
            levels.setdefault((job.trans_mm, job.rot_deg), []).extend(find_rounds(job.run_dir))
    return dict(sorted(levels.items(), key=lambda kv: kv[0] != (0.0, 0.0)))


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


def reproduce_record(bench: Benchmark, all_jobs: list[Job], configs: list[dict], argv: list[str]) -> dict:
    """Everything needed to re-run the suite: command, benchmark keys, each job's composed config
    (``configs``, in job order), package versions, and each planner's package, entry point and version."""
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
    rounds = clutter_rounds(all_jobs)
    lines = [f"# Benchmark: planner `{bench.planner}`", ""]
    if df.empty and not any(rounds.values()):
        lines.append("No readable trial logs.")
    if not df.empty:
        planners = [bench.planner, *compared(bench)]
        lines += summary_lines(df, bench.planner, planners, bench.datasets, bench.settings, out)
    lines += clutter_lines(rounds, out)
    if errors:
        lines += ["## Jobs that did not finish", "", *(f"- {e}" for e in errors), ""]
    text = "\n".join(lines) + "\n"
    (out / SUMMARY_MD).write_text(text)
    (out / "reproduce.json").write_text(
        json.dumps(reproduce_record(bench, all_jobs, configs, argv), indent=1)
    )
    return text
