"""Pose registration from the simulated depth camera, measured per object (:mod:`graspexp.perception.accuracy`):
accuracy from a prior (median ADD-S, share under 1 cm, median errors and fitness) and the cost of depth frame
+ registration per plan (p50 and p95, CPU time beside wall time). ``python -m graspexp bench.registration``
prints it; the camera results page embeds it."""

from collections.abc import Mapping, Sequence

import numpy as np

from graspexp.config.perception import PerceptionConfig
from graspexp.datasets.model import ObjectModel
from graspexp.perception.accuracy import Attempt, registration_attempts

TARGET_CPU_MS = 40.0
"""Depth frame + registration per plan, CPU p50, ms (the paper's pose step: 0.04 s on a GPU, IV-F)."""


def accuracy_rows(attempts: Mapping[str, Sequence[Attempt]]) -> list[str]:
    """One fixed-width line per object (``attempts``: object -> its registrations), under a header line."""
    lines = [
        f"{'object':<26} {'ADD-S p50 mm':>12} {'<1 cm':>6} {'trans mm':>9} {'rot deg':>8} {'fitness':>8}"
    ]
    for name, runs in attempts.items():
        adds = np.array([r.adds_mm for r in runs])
        lines.append(
            f"{name:<26} {np.median(adds):>12.2f} {np.mean(adds < 10.0):>6.0%} "
            f"{np.median([r.trans_mm for r in runs]):>9.2f} {np.median([r.rot_deg for r in runs]):>8.2f} "
            f"{np.median([r.fitness for r in runs]):>8.2f}"
        )
    return lines


def cost_rows(attempts: Sequence[Attempt]) -> list[str]:
    """p50 / p95 of the depth frame, the registration and both, CPU and wall, ms, over ``attempts``; and
    the target line (CPU p50 against :data:`TARGET_CPU_MS`)."""
    t = np.array(
        [(r.depth_cpu_s, r.depth_wall_s, r.registration_cpu_s, r.registration_wall_s) for r in attempts]
    )
    t *= 1e3
    rows = {"depth frame": t[:, :2], "registration": t[:, 2:], "both": t[:, [0, 1]] + t[:, [2, 3]]}
    lines = [
        f"per plan, {len(t)} registrations, ms: {'CPU p50':>8} {'CPU p95':>8} {'wall p50':>9} {'wall p95':>9}"
    ]
    for label, v in rows.items():
        cpu, wall = np.percentile(v[:, 0], [50, 95]), np.percentile(v[:, 1], [50, 95])
        lines.append(f"{label:<36} {cpu[0]:>8.1f} {cpu[1]:>8.1f} {wall[0]:>9.1f} {wall[1]:>9.1f}")
    both = float(np.median(rows["both"][:, 0]))
    met = "met" if both <= TARGET_CPU_MS else "NOT met"
    lines.append(f"target: CPU p50 <= {TARGET_CPU_MS:g} ms: {met} ({both:.1f} ms)")
    return lines


def registration_report(
    perception: PerceptionConfig,
    models: Mapping[str, Sequence[ObjectModel]],
    poses: int,
    seed: int,
    prior_mm: float,
    prior_deg: float,
) -> str:
    """The measurement as text: per dataset (``models``: dataset -> its objects) a table of
    :func:`accuracy_rows`, then :func:`cost_rows` over every registration."""
    lines: list[str] = []
    every: list[Attempt] = []
    for dataset, objects in models.items():
        found = {
            m.name: registration_attempts(perception, m, poses, seed, prior_mm=prior_mm, prior_deg=prior_deg)
            for m in objects
        }
        every += [a for runs in found.values() for a in runs]
        lines += [
            f"{dataset}: prior {prior_mm:g} mm / {prior_deg:g} deg, {poses} poses per object",
            *accuracy_rows(found),
            "",
        ]
    return "\n".join([*lines, *cost_rows(every)])
