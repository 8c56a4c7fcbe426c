"""Schema of the ``dataset`` config group."""

from dataclasses import dataclass, field

from omegaconf import MISSING

from graspexp.config.constraints import TEXT, Interval, Names, Options


@dataclass
class DatasetConfig:
    """Which object set to load and from where."""

    name: str = MISSING
    """Loader key: ``ycb``, ``linemod`` or ``primitives``."""
    root: str | None = None
    """Data root folder. None: env ``GRASPEXP_DATA``, else ``datasets/`` in the working directory."""
    objects: list[str] = field(default_factory=list)
    """The objects of a run; empty (the shipped options): the dataset's default list, paper Table 1 / Table 2
    order (:data:`graspexp.datasets.catalog.DATASETS`, the one place it is written); ``objects=[...]`` at
    top level subsets it."""
    density_kg_m3: float = 700.0
    """Density used for the mass when the dataset publishes none (LINEMOD, primitives), kg/m^3."""
    regions: str = MISSING
    """Grasping-area spec file name under ``graspexp/datasets/regions/``."""


CONSTRAINTS = {
    "name": [Options(("ycb", "linemod", "primitives"))],
    "root": [None, *TEXT],
    "objects": [Names()],
    "density_kg_m3": [Interval(0, 25_000, "right", "kg/m^3")],
    "regions": TEXT,
}
"""Allowed values of every key (see :mod:`graspexp.config.constraints`)."""
