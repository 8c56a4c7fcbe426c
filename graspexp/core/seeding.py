"""Seeds derived from (global seed, object, trial index, purpose): any trial can be re-run alone."""

import hashlib
from typing import Any

import numpy as np


def derive_seed(seed: int, *keys: object) -> int:
    """A 63-bit seed that depends only on ``seed`` and ``keys`` (stable across processes and runs)."""
    text = "/".join([str(int(seed)), *map(str, keys)])
    return int.from_bytes(hashlib.sha256(text.encode()).digest()[:8], "little") >> 1


def trial_seed(job: Any, object_name: str, trial: int) -> int:
    """Seed of one trial of job config ``job`` from (global seed, dataset, object, trial index)."""
    return derive_seed(job.seed, job.dataset.name, object_name, trial)


def round_seed(job: Any, round_index: int) -> int:
    """Seed of one clutter round (``mode=pile``/``packed``) of job config ``job``: from (global seed, dataset,
    mode, round index); it draws the round's objects, their places and every attempt's draws."""
    return derive_seed(job.seed, job.dataset.name, job.mode.name, "round", round_index)


def plan_seed(trial_seed: int) -> int:
    """The planner's seed in the trial of ``trial_seed`` (:attr:`PlanRequest.seed`)."""
    return derive_seed(trial_seed, "plan")


def cloud_seed(job: Any, object_name: str) -> int:
    """Seed of the object's sampled cloud: the same for every trial of the object in job config ``job``."""
    return derive_seed(job.seed, "cloud", object_name)


def rng_for(seed: int, *keys: object) -> np.random.Generator:
    """A numpy Generator seeded by :func:`derive_seed`."""
    return np.random.default_rng(derive_seed(seed, *keys))
