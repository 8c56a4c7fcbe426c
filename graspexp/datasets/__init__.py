"""Object catalogues and loaders: YCB (google_16k / YCB-Video layouts), BOP sets (LINEMOD and any other),
folders of your own meshes and URDFs, and procedural primitives.

Public API (the simulator and planner import these names)::

    load_object(cfg, name, n_points, seed) -> ObjectModel
    job_object(job_cfg, name) -> ObjectModel (the job's cloud size and cloud seed)
    resolve_root(cfg) -> pathlib.Path
    dataset_objects(cfg) -> list[str]
    available_objects(cfg) -> list[str]
    catalogue(cfg) -> tuple[str, ...] (every object name the dataset accepts)
    import_meshlab_area(ply_path, object_points, *, scale=1.0, tolerance_m=None) -> (N,) bool
    DatasetError (a ValueError); ObjectError (a DatasetError: one object is unusable, the others run)

``cfg`` is a :class:`graspexp.config.DatasetConfig` or its composed DictConfig (``dataset``).
"""

from graspexp.datasets import primitives
from graspexp.datasets.catalog import available_objects, catalogue, dataset_objects, resolve_root
from graspexp.datasets.errors import DatasetError, ObjectError
from graspexp.datasets.loader import job_object, load_object, select_objects
from graspexp.datasets.model import ObjectModel
from graspexp.datasets.regions import import_meshlab_area

__all__ = [
    "DatasetError",
    "ObjectError",
    "ObjectModel",
    "available_objects",
    "catalogue",
    "dataset_objects",
    "import_meshlab_area",
    "job_object",
    "load_object",
    "primitives",
    "resolve_root",
    "select_objects",
]
