"""Schema of the ``dataset`` config group."""

from dataclasses import dataclass, field

from omegaconf import MISSING

from graspexp.config.constraints import TEXT, Interval, Names, Options, Pattern

LAYOUTS = ("ycb", "bop", "folder", "primitives")
SPLITS = ("train", "test")
"""The object splits a catalogued dataset may name (``dataset.split``)."""
"""How a dataset's files are laid out and read (:mod:`graspexp.datasets.catalog`)."""


@dataclass
class DatasetConfig:
    """Which object set to load and from where."""

    name: str = MISSING
    """The dataset's name in logs, seeds and tables; ``ycb``, ``linemod`` and ``primitives`` are the
    catalogued sets (paper Tables 1 and 2, procedural shapes)."""
    layout: str | None = None
    """How the files are read: ``ycb`` (google_16k or YCB-Video folders), ``bop`` (``models/`` +
    ``models_info.json``, millimetres), ``folder`` (every mesh or single-link URDF in ``root``, with
    optional ``NAME.yaml`` sidecars) or ``primitives``. None: the layout of the catalogued set ``name``
    (``linemod`` is a BOP set)."""
    root: str | None = None
    """Data root folder. None: env ``GRASPEXP_DATA``, else ``datasets/`` in the working directory. The
    ``folder`` layout reads this folder itself and needs it set."""
    objects: list[str] = field(default_factory=list)
    """The objects of a run; empty (the shipped options): the dataset's default list, paper Table 1 / Table 2
    order (:data:`graspexp.datasets.catalog.DATASETS`, the one place it is written), or every object of a
    folder or BOP set; ``objects=[...]`` at top level subsets it."""
    split: str | None = None
    """``train`` or ``test``: the dataset's named object split instead of its default list (tuning on one,
    scoring on the other; ``ycb``: train = paper Table 1, test = the other staged objects). None: the
    default list. Refused together with ``objects=[...]`` (both would choose the objects)."""
    density_kg_m3: float = 700.0
    """Density used for the mass when the dataset publishes none (BOP sets, folders, primitives), kg/m^3."""
    regions: str | None = None
    """Grasping-area spec file (a path, or a name under ``graspexp/datasets/regions/``). None: no spec
    file; an object's area comes from its sidecar (``folder`` layout), else it is the whole surface."""
    units: str = "m"
    """``folder`` layout: the units of mesh files whose sidecar sets none: ``m``, ``cm``, ``mm`` or a
    number (the factor from file units to metres)."""
    max_faces: int = 500_000
    """Largest mesh an object may have, faces (triangles as read from its file; a URDF object's parts
    together). Building a collision shape takes minutes from about a million faces (a 2.6M-face scan: 179 s
    and 4.9 GB); a larger object fails alone with this key named: decimate it first (MeshLab's Quadric Edge
    Collapse) or raise the cap. Scanned objects need far fewer (google_16k: 16,384)."""
    bop_set: str | None = None
    """``bop`` layout: the BOP set (``lm``, ``lmo``, ``ycbv``, ``tless``, ...) whose human object names to
    use where it defines them; None: the name of the folder (BOP folders are named by set)."""


CONSTRAINTS = {
    "name": [Pattern(r"[A-Za-z0-9][A-Za-z0-9_.-]*", "a name of letters, digits, '_', '.' and '-'")],
    "layout": [None, Options(LAYOUTS)],
    "root": [None, *TEXT],
    "objects": [Names()],
    "split": [None, Options(SPLITS)],
    "density_kg_m3": [Interval(0, 25_000, "right", "kg/m^3")],
    "regions": [None, *TEXT],
    "units": [Pattern(r"m|cm|mm|[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?", "m, cm, mm or a positive number")],
    "max_faces": [Interval(1, None, integer=True)],
    "bop_set": [None, *TEXT],
}
"""Allowed values of every key (see :mod:`graspexp.config.constraints`)."""
