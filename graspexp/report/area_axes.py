"""Per object: how clearly its grasping area has a main axis, and which axis ``pose_axis`` then takes.

Read from a run's logs: the recorded job config gives the dataset, the planner keys and the cloud seed, so
the clouds are the ones that run planned on (:func:`graspexp.datasets.load_object`, ``planner.n_points``
points). ``elongation`` is :func:`graspexp.planning.clusters.elongation` of the area cloud;
``cos_area_object`` is ``|a . o|`` of the area's and the object's main axes (1: the same line).
"""

import pandas as pd
from omegaconf import OmegaConf

from graspexp.config import DatasetConfig
from graspexp.core.seeding import cloud_seed
from graspexp.datasets import DatasetError, load_object
from graspexp.planning.clusters import elongation, main_axis
from graspexp.planning.optimal import pose_axis_source
from graspexp.record import CorruptLogError
from graspexp.record.reader import read_config_yaml


def area_axes_frame(results: pd.DataFrame) -> pd.DataFrame:
    """One row per (dataset, object) of the collected ``results`` (with ``path``): dataset, object,
    elongation, cos_area_object, pose_axis (the source ``planner.pose_axis`` takes for it). Objects whose
    log or mesh cannot be read are left out; empty for a planner without ``pose_axis``."""
    rows = []
    for (dataset, obj), sub in results.groupby(["dataset", "object"], sort=False):
        try:
            text = read_config_yaml(sub["path"].iloc[0])
        except (CorruptLogError, OSError):
            continue
        if text is None:
            continue
        cfg = OmegaConf.create(text)
        if "pose_axis" not in cfg.planner:
            return pd.DataFrame()
        ds = OmegaConf.merge(OmegaConf.structured(DatasetConfig), cfg.dataset)
        try:
            model = load_object(ds, obj, int(cfg.planner.n_points), cloud_seed(cfg, obj))
        except DatasetError:
            continue
        area = model.points[model.area_mask]
        rows.append(
            {
                "dataset": dataset,
                "object": obj,
                "elongation": elongation(area),
                "cos_area_object": abs(float(main_axis(area) @ main_axis(model.points))),
                "pose_axis": pose_axis_source(cfg.planner, area),
            }
        )
    return pd.DataFrame(rows)
