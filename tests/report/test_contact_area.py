"""The in-area metric's reference cloud: dense enough that a contact on an area face counts, for every
planner alike (graspexp/report/contact_area.py)."""

import numpy as np
import pytest
from omegaconf import OmegaConf
from scipy.spatial import cKDTree

from graspexp.config import DatasetConfig
from graspexp.datasets import load_object
from graspexp.datasets.catalog import DATASETS, candidate_paths
from graspexp.report.contact_area import IN_AREA_TOLERANCE_M, _area_index, in_area


@pytest.mark.parametrize("dataset", ["ycb", "linemod"])
def test_every_point_of_an_area_face_is_within_the_tolerance_of_the_reference(data_root, dataset):
    cfg = DatasetConfig(name=dataset, root=str(data_root), regions=f"{dataset}.yaml")
    yaml = OmegaConf.to_yaml(OmegaConf.structured(cfg))
    names = [
        n for n in DATASETS[dataset].default_objects if any(p.is_file() for p in candidate_paths(cfg, n))
    ]
    assert names
    wide = 0
    for name in names:
        reference = _area_index(yaml, name, 7)
        surface = load_object(cfg, name, 100_000, 8)  # another, denser draw of the same surface
        on_area = surface.points[surface.area_mask]
        assert in_area(on_area, reference).all(), (name, cKDTree(reference.data).query(on_area)[0].max())
        # the planners' 2048-point cloud is no such reference: on most objects it leaves wider gaps
        sparse = load_object(cfg, name, 2048, 7)
        wide += cKDTree(sparse.points[sparse.area_mask]).query(on_area)[0].max() > IN_AREA_TOLERANCE_M
    assert wide >= len(names) / 2


def test_a_contact_beyond_the_area_border_is_outside():
    tree = cKDTree(np.array([[0.0, 0.0, 0.0], [0.001, 0.0, 0.0]]))
    np.testing.assert_array_equal(
        in_area(np.array([[0.0, 0.004, 0.0], [0.0, 0.006, 0.0], [0.0261, 0.0, 0.0]]), tree),
        [True, False, False],
    )
