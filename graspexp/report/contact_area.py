"""Where the fingers touch: the share of finger contacts that lie inside the object's grasping area.

Read from a trial log: at the end of closing (the last ``/contacts`` message before the phase that
follows ``close``), each finger-object contact (the force-weighted mean point of the pair, world frame)
is moved into the object frame by the object's ``/tf`` pose at that time; it is *in the area* when a
grasping-area point of the object's reference cloud (:data:`AREA_REFERENCE_POINTS` surface points, the
run's cloud seed, the dataset's area rules) lies within :data:`IN_AREA_TOLERANCE_M` of it. The reference
is the same for every planner. (The planner's own cloud, the reference until December 2026, leaves random
gaps between area points of up to 9-13 mm with 2048 points and 5-9.5 mm with 4096 on the larger objects,
so contacts on an area face were counted outside, more often for the planners with the sparser cloud.)
Trials whose fingers do not touch the object then have no contacts to count.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pandas as pd
from omegaconf import OmegaConf
from scipy.spatial import cKDTree
from tqdm import tqdm

from graspexp.config import DatasetConfig
from graspexp.core.bodies import FINGER_NAMES, OBJECT_NAME
from graspexp.core.geometry import make_pose, quat_wxyz_to_matrix, transform_points
from graspexp.core.seeding import cloud_seed
from graspexp.datasets import DatasetError, load_object
from graspexp.record import CorruptLogError, read_trial
from graspexp.report.tables import IN_AREA_COLUMN

IN_AREA_TOLERANCE_M = 0.005
"""A contact within this of a grasping-area point is in the area, m: a contact on an area face counts
(the collision mesh lies within 0.3 mm of the scan), one a pad width (20 mm) beyond the area's border
does not."""
AREA_REFERENCE_POINTS = 20_000
"""Size of the reference cloud the contacts are measured against: on every Table 1/2 object 99 % of the
area's surface lies within 2.8 mm of a reference area point (the largest gap: 4.9 mm, on the iron), inside
the tolerance (measured against 200 000 surface points)."""


@functools.lru_cache(maxsize=64)
def _area_index(dataset_yaml: str, name: str, seed: int) -> cKDTree:
    dataset = OmegaConf.merge(OmegaConf.structured(DatasetConfig), OmegaConf.create(dataset_yaml))
    model = load_object(dataset, name, AREA_REFERENCE_POINTS, seed)
    return cKDTree(model.points[model.area_mask])


def _at(times: np.ndarray, t_s: float) -> int:
    return max(int(np.searchsorted(times, t_s + 1e-9, side="right")) - 1, 0)


def finger_contacts_in_area(path: Path | str) -> tuple[int, int]:
    """(finger-object contacts in the grasping area, all finger-object contacts) at the end of closing;
    (0, 0) for a trial that never closed or whose fingers do not touch the object then."""
    log = read_trial(path)
    names = [n for _, n, _ in log.phases]
    if "close" not in names or OBJECT_NAME not in log.transforms:
        return 0, 0
    i = names.index("close")
    end = log.phases[i + 1][0] if i + 1 < len(log.phases) else np.inf
    before = [c for t, c in log.contacts if t <= end + 1e-9]
    if not before:
        return 0, 0
    t_end = max(t for t, _ in log.contacts if t <= end + 1e-9)
    pairs = [
        c
        for c in before[-1]
        if {c["body0"], c["body1"]} & set(FINGER_NAMES) and OBJECT_NAME in (c["body0"], c["body1"])
    ]
    if not pairs:
        return 0, 0
    times, pos, quat = log.transforms[OBJECT_NAME]
    j = _at(times, t_end)
    world_from_object = make_pose(quat_wxyz_to_matrix(quat[j]), pos[j])
    local = transform_points(np.linalg.inv(world_from_object), np.array([c["position"] for c in pairs]))
    cfg = OmegaConf.create(log.metadata["config_yaml"])
    name = log.result["object"]
    tree = _area_index(OmegaConf.to_yaml(cfg.dataset), name, cloud_seed(cfg, name))
    return int(in_area(local, tree).sum()), len(pairs)


def in_area(points_m: np.ndarray, area: cKDTree, tolerance_m: float = IN_AREA_TOLERANCE_M) -> np.ndarray:
    """(P,) bool: which of the (P, 3) points (object frame, m) lie within ``tolerance_m`` of a point of
    the grasping area's tree (object frame); all False for an empty area."""
    if area.n == 0:
        return np.zeros(len(points_m), dtype=bool)
    distance, _ = area.query(points_m)
    return distance <= tolerance_m


def held_in_area(results: pd.DataFrame, progress: bool = True) -> pd.Series:
    """The report's second criterion for the collected ``results`` (columns ``success``, ``path``), one
    value per row: held (the paper's criterion) with every finger contact at the end of closing in the
    grasping area (:func:`finger_contacts_in_area`; a held trial without contacts then is not). Only held
    trials' logs are read. None where it cannot be told: a log whose contacts cannot be read, or an object
    whose mesh is not found (the reference cloud needs it: set ``GRASPEXP_DATA``)."""
    out = pd.Series(False, index=results.index, name=IN_AREA_COLUMN, dtype=object)
    held = results.index[results["success"].astype(bool)]
    for i in tqdm(held, desc="contacts in the grasping area", unit="log", disable=not progress):
        try:
            n_in, n_all = finger_contacts_in_area(results.at[i, "path"])
        except (CorruptLogError, OSError, DatasetError):
            out.at[i] = None
            continue
        out.at[i] = bool(n_all > 0 and n_in == n_all)
    return out
