"""The rounds of a clutter-removal job (``mode=pile``/``packed``): each drawn from the pool, run (or read
back when its log is finished) and logged into one MCAP file per round; ``rounds.csv``, ``attempts.csv`` and
``summary.md`` (GSR and DR with their intervals) beside them."""

import logging
import time
import traceback
from pathlib import Path

import numpy as np
from omegaconf import DictConfig
from tqdm import tqdm

from graspexp.core.files import write_atomic
from graspexp.core.rounds import RoundEnd, RoundResult
from graspexp.core.run_layout import (
    ATTEMPTS_CSV,
    ROUNDS_CSV,
    LinkedRunPathError,
    check_not_linked,
    real_folder,
    round_log_path,
    summary_md,
)
from graspexp.core.seeding import rng_for, round_seed
from graspexp.record import read_round, trial_recorder
from graspexp.record.scene import round_bodies, round_scene
from graspexp.record.writer import is_write_error
from graspexp.report.round_tables import (
    attempts_frame,
    clutter_markdown,
    read_rounds,
    rounds_frame,
)
from graspexp.run.locks import RunError
from graspexp.run.objects import LoadedObject, round_context
from graspexp.run.provenance import job_metadata, pool_metadata
from graspexp.run.resume import finished_log
from graspexp.run.run_record import table_rounds
from graspexp.run.trial_loop import write_failure
from graspexp.sim.rounds import run_round
from graspexp.sim.trial import plain_config

log = logging.getLogger(__name__)


def draw_objects(pool: list[str], n: int, seed: int) -> list[str]:
    """The ``n`` objects of the round of ``seed`` from ``pool``: without replacement when the pool holds
    ``n``, else with (VGN draws with replacement from its object set)."""
    idx = rng_for(seed, "draw").choice(len(pool), size=n, replace=len(pool) < n)
    return [pool[int(i)] for i in idx]


def run_rounds(
    cfg: DictConfig, run_dir: Path, objects: list[str], models: dict[str, LoadedObject], bar: tqdm | None
) -> list[RoundResult]:
    """Every round of the job (``trials`` of them); finished rounds found in ``run_dir`` are read back. The pool
    is ``objects`` less the unusable ones; an exception inside a round is that round's ``error`` end."""
    plain = plain_config(cfg)
    pool = clutter_pool(objects, models)
    job_meta = job_metadata(cfg)
    pool_meta = pool_metadata([models[n] for n in pool])
    results = []
    for r in range(cfg.trials):
        seed = round_seed(plain, r)
        drawn = draw_objects(pool, int(cfg.mode.objects_per_round), seed)
        path = round_log_path(run_dir, cfg.mode.name, r)
        try:
            real_folder(run_dir, path.parent)
        except LinkedRunPathError as exc:
            raise RunError(str(exc)) from None
        result = finished_round(path, run_dir, r)
        if result is None:
            meta = {**job_meta, "object": cfg.mode.name, "trial": str(r), "trial_seed": str(seed),
                    "round_objects": " ".join(drawn), "round_pool": pool_meta}  # fmt: skip
            result = _run_one(cfg, plain, meta, path, r, seed, [models[n] for n in drawn])
        results.append(result)
        if bar is not None:
            bar.set_postfix_str(f"round {r}: {result.end}, {result.n_removed}/{result.n_placed}")
            bar.update()
    return results


def clutter_pool(objects: list[str], models: dict[str, LoadedObject]) -> list[str]:
    """The pool the rounds draw from: ``objects`` less the unusable ones (not in ``models``), in their order;
    RunError when none is left."""
    pool = [name for name in objects if name in models]
    if not pool:
        raise RunError(f"no object of the pool {objects} can be used (summary.md says why): nothing to place")
    return pool


def _run_one(
    cfg, plain, meta: dict[str, str], path: Path, r: int, seed: int, loaded: list[LoadedObject]
) -> RoundResult:
    """Round ``r`` run and logged with metadata ``meta``: the job's, the round's index and seed, the objects it
    drew (``round_objects``) and the pool with its meshes (``round_pool``: what resume and ``replay --resim``
    compare)."""
    bodies = round_bodies(len(loaded))
    try:
        with trial_recorder(path if cfg.record else None, meta, plain, bodies) as rec:
            scene = round_scene(plain, [o.hulls for o in loaded]) if cfg.record else None
            ctx = round_context(plain, loaded, r, seed, rec, scene)
            try:
                result = run_round(ctx)
            except Exception as exc:  # one round's error is recorded; the job goes on
                if is_write_error(exc):
                    raise
                log.error("round %d failed with an error: %s", r, exc)
                result = error_round(cfg, r, seed, [o.model.name for o in loaded], exc)
            rec.round_result(result.sim_time_s, result.to_dict())
    except Exception as exc:
        if not is_write_error(exc):
            raise
        raise RunError(write_failure(path, exc, "round")) from None
    return result


def error_round(cfg: DictConfig, r: int, seed: int, drawn: list[str], exc: BaseException) -> RoundResult:
    """The ``error`` result of a round that raised ``exc`` (its one-line description recorded)."""
    return RoundResult(
        dataset=cfg.dataset.name, mode=cfg.mode.name, planner=cfg.planner.name, round=r, seed=seed, drawn=drawn,
        placed=[], removed=[], end=RoundEnd.ERROR.value,
        error="".join(traceback.format_exception_only(type(exc), exc)).strip(),
    )  # fmt: skip


def finished_round(path: Path, run_dir: Path, r: int) -> RoundResult | None:
    """The result of round ``r``'s complete log at ``path``; None if absent. A log whose /round is unreadable or
    of another round, and a round that ended in ``error``, are moved aside and the round is redone."""

    def redo(result: RoundResult) -> str:
        if result.round != r:
            return f"its result is of round {result.round}"
        if result.end == RoundEnd.ERROR.value:
            return f"it ended in an error ({result.error})"
        return ""

    return finished_log(path, run_dir, "round", lambda p: RoundResult.from_dict(read_round(p)), redo)


def write_round_summary(run_dir: Path, results: list[RoundResult]) -> tuple[list[RoundResult], str]:
    """Write ``rounds.csv``, ``attempts.csv`` and ``summary.md`` for ``results`` and every other round the
    directory holds: its finished round logs (:func:`graspexp.report.round_tables.read_rounds`), then the rows
    of its tables no log holds (:func:`graspexp.run.run_record.table_rounds`: those of ``record=false`` runs of
    the same config, resume refuses another); (every round, by index; the summary's text)."""
    held = {r.round: r for r in read_rounds(run_dir)}
    held = {**table_rounds(run_dir), **held, **{r.round: r for r in results}}
    every = [held[k] for k in sorted(held)]
    text = clutter_markdown(every)
    files = (
        (Path(run_dir) / ROUNDS_CSV, rounds_frame(every).to_csv(index=False).encode()),
        (Path(run_dir) / ATTEMPTS_CSV, attempts_frame(every).to_csv(index=False).encode()),
        (summary_md(run_dir), (text + "\n").encode()),
    )
    for path, data in files:
        try:
            write_atomic(check_not_linked(path), lambda fh, data=data: fh.write(data))
        except OSError as exc:
            raise RunError(f"cannot write {path}: {exc.strerror or exc}") from None
    return every, text


def round_objective(results: list[RoundResult]) -> float:
    """A clutter job's objective: its GSR as a fraction (successful / executed attempts over the rounds); 0
    when the planner found no grasp in any round (no object was removed: a result, not an error)."""
    executed = [a.success for r in results for a in r.attempts if a.executed]
    return float(np.mean(executed)) if executed else 0.0


def timed_rounds(cfg: DictConfig, run_dir: Path, objects, models, wall0: float, cpu0: float) -> float:
    """Run the rounds, write the tables, print the summary; the job's objective (over every round the
    directory holds, as a single-object job's is over every trial)."""
    with tqdm(total=cfg.trials, desc=f"{cfg.mode.name}/{cfg.dataset.name}", disable=not cfg.progress) as bar:
        results = run_rounds(cfg, run_dir, objects, models, bar)
    every, text = write_round_summary(run_dir, results)
    print(
        f"\n{cfg.mode.name} / {cfg.dataset.name} / planner {cfg.planner.name}: {run_dir} ({len(every)} rounds, "
        f"{time.perf_counter() - wall0:.1f} s wall, {time.process_time() - cpu0:.1f} s CPU)"
    )
    print(text)
    if results and all(r.end == RoundEnd.ERROR.value for r in results):  # as a job none of whose trials ran
        first = results[0].error.splitlines()[0] if results[0].error else "no message"
        raise RunError(
            f"no round ran: every one of the {len(results)} rounds ended in an error (first: {first})"
        )
    return round_objective(every)
