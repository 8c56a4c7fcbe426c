"""Results pages made from runs of the current code: ``python -m graspexp results`` regenerates them,
``python -m graspexp results --check`` tells which ones the code no longer reproduces.

A :class:`Page` (registered in :func:`graspexp.run.result_pages.pages`) declares

- its sweeps (:class:`graspexp.run.suites.Sweep`: a reading and extra overrides, defined in
  :mod:`graspexp.run.suites` with every other job matrix), each a Hydra
  multirun over the paper's four settings (:func:`graspexp.run.suites.reading_sweep`, the joblib
  launcher unless the overrides name another, e.g. ``hydra/launcher=submitit_slurm``);
- how its generated block is rendered from those runs (``render``, from :mod:`graspexp.report`);
- its fingerprint jobs: a few trials of the page's own planners and settings (``record=false``), whose
  outcomes are hashed (:func:`graspexp.report.pages.outcome_fingerprint`) and stamped into the page.

:func:`regenerate` runs every sweep not yet done into ``OUT/runs/<sweep>`` (a sweep two pages share runs
once; an interrupted regeneration continues: each sweep resumes its own trials, and a finished sweep is
marked and skipped), then the fingerprint jobs, then writes each page's block. :func:`check` re-runs the
fingerprint jobs into a temporary folder and compares each page's stamp. A page whose sweeps name a planner
that cannot run here (a learned planner such as ``planner=vgn`` without the optional extra ``learned`` or its
checkpoint: :func:`unavailable`) is skipped by both, with one line saying why; :func:`learned_pages` are the
pages that run a learned planner (``nox -s learned`` checks them).
"""

from __future__ import annotations

import contextlib
import dataclasses
import datetime
import hashlib
import io
import json
import os
import platform
import resource
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from graspexp.core.run_layout import ATTEMPTS_CSV, results_csv
from graspexp.report.pages import (
    PageError,
    Provenance,
    Stamp,
    add_stamp,
    duration,
    outcome_fingerprint,
    page_stamps,
    provenance,
    replace_block,
    stamp_for,
)
from graspexp.run.multirun import multirun_command
from graspexp.run.provenance import cpu_class, cpu_flags, machine_fingerprint
from graspexp.run.suites import FINGERPRINT_SETTINGS, FINGERPRINT_SUBSET, Sweep, reading_sweep

DONE_NAME = ".graspexp-results-done.json"
"""Marker a finished sweep leaves in its directory: command, exit status, wall and CPU seconds."""


@dataclass(frozen=True)
class PageInput:
    """What a page's ``render`` gets: each sweep's directory, a folder for the page's figures (beside the
    page, ``<page>_files/``, linked as such; emptied before each render, which makes it when it draws)
    and a work folder for its CSV files (under OUT)."""

    runs: Mapping[Sweep, Path]
    assets: Path
    work: Path


@dataclass(frozen=True)
class Page:
    """A results page: the file it lives in (relative to the repository root), its sweeps, how its
    generated block is rendered, and the jobs of its fingerprint."""

    name: str
    path: str
    sweeps: tuple[Sweep, ...]
    render: Callable[[PageInput], str]
    fingerprint: tuple[Sweep, ...]
    """Sweeps whose outcomes this page's numbers depend on; each runs on ``fingerprint_settings`` with
    ``fingerprint_subset``."""
    fingerprint_subset: tuple[str, ...] = FINGERPRINT_SUBSET
    fingerprint_settings: tuple[tuple[str, str], ...] = FINGERPRINT_SETTINGS
    """(mode, rot) of each fingerprint job."""
    admonition: bool = True
    """Whether the provenance is a Markdown admonition (the site) or plain paragraphs (the README)."""


@dataclass
class SweepTime:
    """A finished sweep: its command, exit status, wall and CPU seconds (CPU None: jobs ran elsewhere)."""

    command: str
    rc: int
    wall_s: float
    cpu_s: float | None
    commit: str = ""
    """The commit the sweep ran at."""
    skipped: bool = field(default=False)


def merged(*groups: Sequence[str]) -> tuple[str, ...]:
    """The overrides of ``groups`` in order, a later value of a key replacing an earlier one (in place)."""
    out: dict[str, str] = {}
    for group in groups:
        for o in group:
            out[o.split("=", 1)[0].lstrip("+~")] = o
    return tuple(out.values())


def fingerprint_jobs(page: Page, overrides: Sequence[str] = ()) -> list[tuple[str, ...]]:
    """The override lists of ``page``'s fingerprint jobs (``record=false``, no progress bars); the job
    overrides among ``overrides`` (those given to every sweep; not ``hydra.*``) go to them too, under
    the page's fingerprint subset."""
    shared = [o for o in overrides if not o.lstrip("+~").startswith("hydra")]
    return [
        merged(
            s.reading.overrides,
            s.extra,
            shared,
            page.fingerprint_subset,
            (f"mode={mode}", f"rot={rot}", "record=false", "progress=false"),
        )
        for s in page.fingerprint
        for mode, rot in page.fingerprint_settings
    ]


def page_planners(page: Page) -> list[str]:
    """Every planner that ``page``'s sweeps and fingerprint jobs name (``planner=a,b``), in order, once."""
    names: dict[str, None] = {}
    for sweep in (*page.sweeps, *page.fingerprint):
        for override in (*sweep.reading.overrides, *sweep.extra):
            key, _, value = override.partition("=")
            if key.lstrip("+~") == "planner":
                names |= dict.fromkeys(value.split(","))
    return list(names)


def unavailable(page: Page) -> str:
    """'' when every planner that ``page``'s sweeps and fingerprint jobs name can run here; else one line:
    the first that cannot and why (its plugin's ``unavailable``, e.g. the optional extra to install)."""
    from graspexp.config.plugins import get_plugin

    for name in page_planners(page):
        plugin = get_plugin(name).plugin
        why = plugin.unavailable() if plugin.unavailable is not None else ""
        if why:
            return f"page {page.name} ({page.path}) skipped: planner={name} cannot run here: {why}"
    return ""


def learned_pages(pages: Sequence[Page]) -> list[Page]:
    """The pages of ``pages`` that run a learned planner (a plugin declaring
    :attr:`graspexp.config.plugins.PlannerPlugin.learned`)."""
    from graspexp.config.plugins import learned_planners

    learned = learned_planners()
    return [page for page in pages if any(name in learned for name in page_planners(page))]


def available(pages: Sequence[Page]) -> list[Page]:
    """The pages of ``pages`` whose planners can run here; one line on stderr for each that cannot."""
    out = []
    for page in pages:
        why = unavailable(page)
        if why:
            print(f"graspexp results: {why}", file=sys.stderr)
        else:
            out.append(page)
    return out


def _job_key(overrides: Sequence[str]) -> str:
    return hashlib.sha256("\n".join(sorted(overrides)).encode()).hexdigest()[:16]


class ResultsError(RuntimeError):
    """A fingerprint job that cannot run (bad override, missing data): one line naming the job."""


def _run_fingerprint_job(overrides: tuple[str, ...], run_dir: str) -> str:
    """Run one fingerprint job into ``run_dir`` (its printout swallowed); returns the path of its table of
    outcomes: results.csv, or attempts.csv for a clutter job."""
    from graspexp.config import ConfigError
    from graspexp.config.compose import compose_validated
    from graspexp.datasets import DatasetError
    from graspexp.run.locks import RunError
    from graspexp.run.runner import run_in_dir

    try:
        cfg = compose_validated(list(overrides))  # run_in_dir makes it ready
        with contextlib.redirect_stdout(io.StringIO()):
            run_in_dir(cfg, Path(run_dir))
    except (ConfigError, DatasetError, RunError) as exc:
        raise ResultsError(f"the fingerprint job {shlex.join(overrides)} cannot run: {exc}") from None
    trials = results_csv(run_dir)
    return str(trials if trials.is_file() else Path(run_dir) / ATTEMPTS_CSV)


def run_fingerprints(
    pages: Sequence[Page], out: Path, n_jobs: int, overrides: Sequence[str] = ()
) -> dict[str, str]:
    """Run every fingerprint job of ``pages`` (:func:`fingerprint_jobs` with ``overrides``) once (jobs two
    pages share run once) into ``out`` (emptied first: a fingerprint never reuses a trial) with ``n_jobs``
    processes; returns each page's fingerprint."""
    from joblib import Parallel, delayed

    jobs = {_job_key(j): j for page in pages for j in fingerprint_jobs(page, overrides)}
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    start = time.perf_counter()
    print(f"graspexp results: fingerprints: {len(jobs)} jobs ...", file=sys.stderr, flush=True)
    paths = Parallel(n_jobs=n_jobs)(delayed(_run_fingerprint_job)(j, str(out / k)) for k, j in jobs.items())
    tables = {k: pd.read_csv(p, dtype=str, keep_default_na=False) for k, p in zip(jobs, paths, strict=True)}
    print(f"graspexp results: fingerprints: {time.perf_counter() - start:.0f} s", file=sys.stderr)
    return {
        page.name: outcome_fingerprint(tables[_job_key(j)] for j in fingerprint_jobs(page, overrides))
        for page in pages
    }


def _git(root: Path, *args: str) -> str:
    return subprocess.run(["git", *args], cwd=root, capture_output=True, text=True, check=True).stdout.strip()


NOT_CODE = (":(exclude)docs", ":(exclude,glob)**/*.md")
"""git pathspecs of the files that are documentation, not code: changes there do not mark a commit changed."""


def commit_of(root: Path) -> tuple[str, str]:
    """(short commit, its date YYYY-MM-DD) of the checkout at ``root``; ``+changes`` is appended when
    tracked files other than the documentation differ from the commit (the pages a regeneration has written
    so far change no number of the next page)."""
    try:
        commit = _git(root, "rev-parse", "--short", "HEAD")
        date = _git(root, "show", "-s", "--format=%cs", "HEAD")
        changed = _git(root, "status", "--porcelain", "--untracked-files=no", "--", ".", *NOT_CODE)
    except (OSError, subprocess.CalledProcessError):
        return "unknown", datetime.date.today().isoformat()
    return commit + ("+changes" if changed else ""), date


def describe_machine() -> str:
    """What the machine is, in words: cores, architecture, VM or not, CPU model, the physics backend."""
    cpu = machine_fingerprint()["cpu"]
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    arch = {"x86_64": "x86-64", "aarch64": "arm64"}.get(platform.machine(), platform.machine())
    kind = "VM" if "hypervisor" in (cpu_flags() or ()) else "machine"
    return f"a {cores}-core {arch} {kind} ({cpu}, {cpu_class()}), CPU PhysX"


def _remote(overrides: Sequence[str]) -> bool:
    return any(o.startswith("hydra/launcher=submitit_slurm") for o in overrides)


def run_sweep(sweep: Sweep, out: Path, overrides: Sequence[str], label: str, commit: str = "") -> SweepTime:
    """Run (or resume) one sweep into ``out/<sweep.name>`` at ``commit``; a sweep marked done is skipped
    (with a warning when it was made at another commit: its trials are then not of this code)."""
    sweep_dir = out / sweep.name
    marker = sweep_dir / DONE_NAME
    given = [*sweep.extra, *overrides]
    if sweep.settings:
        command = reading_sweep(sweep.reading, out, given, sweep_dir=sweep_dir)
    else:
        launcher = {"launcher": ()} if any(o.startswith("hydra/launcher=") for o in given) else {}
        command = multirun_command(
            sweep_dir, ["progress=false", *sweep.reading.overrides, *given], **launcher
        )
    shown = shlex.join(["python", *command[1:]])
    if marker.is_file():
        done = SweepTime(**json.loads(marker.read_text()))
        print(f"{label} {sweep.name}: done before ({duration(done.wall_s)}), skipped", file=sys.stderr)
        if done.commit != commit:
            print(
                f"{label} {sweep.name}: warning: made at commit {done.commit or 'unknown'}, not {commit}; "
                "choose another --out to run it with this code",
                file=sys.stderr,
            )
        return dataclasses.replace(done, skipped=True)
    print(f"{label} {sweep.name}: {sweep.reading.what}\n  {shown}", file=sys.stderr, flush=True)
    before, start = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
    rc = subprocess.call(command)
    after, wall = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter() - start
    cpu = (
        None
        if _remote(overrides)
        else (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    )
    result = SweepTime(shown, rc, wall, cpu, commit)
    print(f"{label} {sweep.name}: {duration(wall)} wall, exit {rc}", file=sys.stderr, flush=True)
    if rc == 0:
        marker.write_text(json.dumps({k: v for k, v in vars(result).items() if k != "skipped"}))
    return result


def _writable(path: Path) -> bool:
    """Whether this process may create, replace and remove files in the folder ``path`` (or write the file
    ``path``): :func:`os.access` (False on a read-only file system, for root too)."""
    return os.access(path, os.W_OK)


def _nearest(path: Path) -> Path:
    """``path`` or its nearest folder above that exists."""
    path = path.absolute()
    while not path.exists() and path.parent != path:
        path = path.parent
    return path


def unwritable(pages: Sequence[Page], root: Path, out: Path) -> list[str]:
    """One line per reason :func:`regenerate` could not write its output: a page file under ``root`` that
    is missing, not a regular file, without its generated block or not writable; a page's folder where its
    figures folder cannot be made; ``out`` (the runs) not writable. [] when all can be written: checked
    before any sweep runs, so that nothing fails after hours of them."""
    problems = []
    for page in pages:
        path = root / page.path
        if not path.is_file():
            what = "is not a regular file" if path.exists() else "does not exist"
            problems.append(f"page {page.name}: {path} {what} (--root names the repository root)")
            continue
        try:
            replace_block(path.read_text(), "", str(path))
        except PageError as exc:
            problems.append(str(exc))
            continue
        except (OSError, UnicodeDecodeError) as exc:
            problems.append(
                f"page {page.name}: {path} cannot be read ({getattr(exc, 'strerror', None) or exc})"
            )
            continue
        for target in (path, path.parent):
            if not _writable(target):
                problems.append(f"page {page.name}: {target} is not writable (a read-only root?)")
                break
    base = _nearest(out)
    if not base.is_dir() or not _writable(base):
        problems.append(
            f"the run folder {out} cannot be made: {base} is not a writable folder (choose --out)"
        )
    return problems


def regenerate(
    pages: Sequence[Page], root: Path, out: Path, overrides: Sequence[str], command: str, n_jobs: int
) -> list[str]:
    """Run the sweeps of ``pages`` (each once, resumable) into ``out/runs``, their fingerprints, and write
    each page's generated block into its file under ``root``; returns one line per sweep that failed (its
    pages are then left as they were). A page whose planners cannot run here is skipped (:func:`available`).
    :class:`ResultsError` (one line), before any sweep runs, when a page file or ``out`` cannot be written
    (:func:`unwritable`)."""
    pages = available(pages)
    cannot = unwritable(pages, root, out)
    if cannot:
        raise ResultsError(f"nothing run: {'; '.join(cannot)}")
    commit, date = commit_of(root)
    machine = describe_machine()
    sweeps = list(dict.fromkeys(s for page in pages for s in page.sweeps))
    names = {s.name: s for s in sweeps}
    if len(names) != len(sweeps):
        raise ValueError("two different sweeps share a name; give their readings different names")
    times: dict[Sweep, SweepTime] = {}
    total = time.perf_counter()
    for i, sweep in enumerate(sweeps, 1):
        users = ", ".join(p.name for p in pages if sweep in p.sweeps)
        times[sweep] = run_sweep(sweep, out / "runs", overrides, f"[{i}/{len(sweeps)}] ({users})", commit)
    failed = {s for s, t in times.items() if t.rc != 0}
    fingerprints = run_fingerprints(pages, out / "fingerprint", n_jobs, overrides) if pages else {}
    problems = [f"sweep {s.name} exited {times[s].rc}: {times[s].command}" for s in failed]
    for page in pages:
        if failed & set(page.sweeps):
            problems.append(f"page {page.name} ({page.path}) not written: a sweep of it failed")
            continue
        path = root / page.path
        assets, work = path.parent / f"{path.stem}_files", out / "pages" / page.name
        own = [times[s] for s in page.sweeps]
        cpu = None if any(t.cpu_s is None for t in own) else sum(t.cpu_s or 0.0 for t in own)
        jobs = fingerprint_jobs(page, overrides)
        head = provenance(
            Provenance(
                page=page.name,
                command=command,
                commit=commit,
                date=date,
                machine=machine,
                sweeps=tuple(t.command for t in own),
                wall_s=sum(t.wall_s for t in own),
                cpu_s=cpu,
                fingerprint=fingerprints[page.name],
                fingerprint_trials=_fingerprint_trials(jobs),
                fingerprint_jobs=tuple(" ".join(j) for j in jobs),
                sweep_commits=tuple(t.commit or "unknown" for t in own),
                cpu=cpu_class(),
            ),
            page.admonition,
        )
        work.mkdir(parents=True, exist_ok=True)
        shutil.rmtree(assets, ignore_errors=True)  # every file in it is drawn again: none outlives its page
        body = page.render(PageInput({s: out / "runs" / s.name for s in page.sweeps}, assets, work))
        try:  # checked before the sweeps; changed since
            path.write_text(replace_block(path.read_text(), head + "\n" + body, str(path)))
        except (OSError, PageError) as exc:
            problems.append(f"page {page.name} ({path}) not written: {getattr(exc, 'strerror', None) or exc}")
            continue
        print(f"graspexp results: wrote {path}", file=sys.stderr)
    ran = [t for t in times.values() if not t.skipped]
    cpu_all = "n/a" if any(t.cpu_s is None for t in ran) else duration(sum(t.cpu_s or 0.0 for t in ran))
    print(
        f"graspexp results: {len(ran)} sweeps run now ({len(times) - len(ran)} done before), "
        f"{duration(time.perf_counter() - total)} wall in all; the sweeps run now {cpu_all} CPU",
        file=sys.stderr,
    )
    return problems


def _fingerprint_trials(jobs: Sequence[Sequence[str]]) -> int:
    """Trials of the fingerprint ``jobs``: objects x trials per job, summed."""
    from graspexp.datasets import select_objects
    from graspexp.run.job_config import compose_job

    n = 0
    for job in jobs:
        cfg = compose_job(list(job))
        n += len(select_objects(cfg.dataset, cfg.objects)) * int(cfg.trials)
    return n


def _page_stamps(page: Page, root: Path) -> tuple[list[Stamp], list[str]]:
    """The stamps of ``page`` in the generated block of its file under ``root`` and one line per problem
    of the file (:func:`graspexp.report.pages.page_stamps`; no file, no block: a problem)."""
    path = root / page.path
    try:
        text = path.read_text()
    except FileNotFoundError:
        return [], [f"{page.path}: no such file under {root}: {_regenerate(page)}"]
    except (OSError, UnicodeDecodeError) as exc:
        return [], [f"{page.path}: cannot be read ({getattr(exc, 'strerror', None) or exc})"]
    return page_stamps(text, page.name, page.path)


def _regenerate(page: Page) -> str:
    return f"run python -m graspexp results --pages {page.name}"


def _unstamped(page: Page) -> str:
    return f"{page.path}: no fingerprint of page {page.name!r} in its generated block: {_regenerate(page)}"


def check(pages: Sequence[Page], root: Path, n_jobs: int) -> list[str]:
    """One line per page of ``pages`` whose fingerprint for this machine's CPU class (:func:`.pages.stamp_for`)
    the current code does not reproduce (or that records none); [] when every page is current. Only the
    stamps inside a page's generated block count; a page without its block, or with a garbled stamp line, a
    stamp outside the block or two stamps for one class is a problem (one line each, naming the page and
    the line) and is not fingerprinted. A page whose planners cannot run here is skipped
    (:func:`available`), and so, with a line saying so, is a page that records fingerprints of other CPU
    classes only (its last digits are not this machine's to check)."""
    pages = available(pages)
    cpu = cpu_class()
    recorded = {}
    problems = []
    for page in pages:
        stamps, wrong = _page_stamps(page, root)
        mine = stamp_for(stamps, cpu)
        if wrong:  # a page whose stamps cannot be trusted is not checked: it is not current
            problems += wrong
        elif not stamps:
            problems.append(_unstamped(page))
        elif mine is None:
            classes = ", ".join(sorted({s.cpu for s in stamps}))
            print(
                f"graspexp results: {page.path}: fingerprints of {classes} only, not checkable on this "
                f"machine ({cpu}); `python -m graspexp results --stamp-cpu` adds this class's on one where "
                "the page is current",
                file=sys.stderr,
            )
        else:
            recorded[page.name] = mine
    with tempfile.TemporaryDirectory(prefix="graspexp-results-check-") as tmp:
        stamped = [p for p in pages if p.name in recorded]
        now = run_fingerprints(stamped, Path(tmp), n_jobs) if stamped else {}
    for page in pages:
        stamp = recorded.get(page.name)
        if stamp is None:
            continue
        if now[page.name] != stamp.fingerprint:
            problems.append(
                f"{page.path}: made at commit {stamp.commit} (fingerprint {stamp.fingerprint}"
                f"{', ' + stamp.cpu if stamp.cpu else ''}); the current code gives {now[page.name]}: "
                f"regenerate it with python -m graspexp results --pages {page.name}"
            )
        else:
            print(f"graspexp results: {page.path}: current ({stamp.fingerprint})", file=sys.stderr)
    return problems


def stamp_cpu(pages: Sequence[Page], root: Path, n_jobs: int) -> list[str]:
    """Record this machine's CPU class's fingerprint beside the stamps of each page of ``pages`` that has
    none of this class, from the current code; [] or one line per page left alone (never generated; made on
    this class: regenerate it; a problem of its stamps, as :func:`check` reports them; not writable). Run it at a commit whose pages are current on the class they were made on
    (``results --check`` there): the new stamp then says what the same code gives on this class."""
    pages = available(pages)
    cpu = cpu_class()
    problems, todo = [], []
    for page in pages:
        stamps, wrong = _page_stamps(page, root)
        if wrong:
            problems += wrong
        elif not stamps:
            problems.append(_unstamped(page))
        elif stamps[0].cpu == cpu:
            print(f"graspexp results: {page.path}: made on {cpu}, nothing to add", file=sys.stderr)
        elif not _writable(root / page.path):
            problems.append(f"{page.path}: not writable under {root}: no fingerprint taken for it")
        else:
            todo.append(page)
    commit = commit_of(root)[0]
    with tempfile.TemporaryDirectory(prefix="graspexp-results-stamp-") as tmp:
        now = run_fingerprints(todo, Path(tmp), n_jobs) if todo else {}
    for page in todo:
        path = root / page.path
        path.write_text(add_stamp(path.read_text(), Stamp(page.name, now[page.name], commit, cpu), str(path)))
        print(f"graspexp results: {page.path}: {cpu} fingerprint {now[page.name]} added", file=sys.stderr)
    return problems
