"""The synthetic clouds of :mod:`helpers.planning` lie on their surfaces."""

import numpy as np
from helpers.planning import box_cloud, cylinder_cloud


def test_synthetic_clouds_lie_on_their_surfaces():
    rng = np.random.default_rng(0)
    cyl = cylinder_cloud(rng, 200, radius_m=0.03, height_m=0.1)
    np.testing.assert_allclose(np.hypot(cyl[:, 0], cyl[:, 1]), 0.03, atol=1e-12)
    box = box_cloud(rng, 300, (0.02, 0.04, 0.06))
    on_face = np.isclose(np.abs(box[:, 0]), 0.01) | np.isclose(np.abs(box[:, 1]), 0.02)
    on_face |= np.isclose(box[:, 2], 0.0) | np.isclose(box[:, 2], 0.06)
    assert on_face.all()
