"""BOP datasets (the BOP challenge's common layout): ``models/obj_NNNNNN.ply`` in millimetres and
``models/models_info.json`` (per model id: ``diameter``, ``min_x/y/z``, ``size_x/y/z`` in mm and optional
``symmetries_discrete`` / ``symmetries_continuous``). LINEMOD, LM-O, YCB-Video, T-LESS, HomebrewedDB,
IC-BIN, TUD-L, HOPE, ITODD all ship it (Hodan et al., "BOP: Benchmark for 6D Object Pose Estimation",
ECCV 2018, and the BOP toolkit's ``dataset_params.py``).

Objects are named by the set's human names where it defines them (:data:`BOP_NAMES`), else
``obj_NNNNNN``. Masses are volume x ``dataset.density_kg_m3`` (BOP publishes none).
"""

from __future__ import annotations

import functools
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from graspexp.config.constraints import is_real
from graspexp.datasets.errors import DatasetError

MM_TO_M = 1e-3
"""BOP models are in millimetres."""
INFO_FILE = "models_info.json"

LM_NAMES = {
    1: "ape", 2: "benchvise", 3: "bowl", 4: "cam", 5: "can", 6: "cat", 7: "cup", 8: "driller", 9: "duck",
    10: "eggbox", 11: "glue", 12: "holepuncher", 13: "iron", 14: "lamp", 15: "phone",
}  # fmt: skip
"""LINEMOD (Hinterstoisser et al., ACCV 2012) model ids -> names; LM-O uses the same models."""
LM_SIZES_MM: dict[int, tuple[float, float, float]] = {
    1: (75.8686, 77.5992, 91.769), 2: (215.67, 121.8557, 219.41), 4: (136.6594, 143.0302, 100.497),
    5: (100.7916, 181.7958, 193.734), 6: (67.0107, 127.633, 117.4566), 8: (229.476, 75.4714, 208.002),
    9: (104.4292, 77.4076, 85.697), 10: (150.1846, 107.075, 69.2414), 11: (36.7211, 77.866, 172.8158),
    12: (100.8878, 108.497, 90.8), 13: (258.226, 118.4821, 141.1324), 14: (203.146, 117.7525, 213.116),
    15: (93.9181, 147.4334, 184.7474),
}  # fmt: skip
"""The published size (``size_x/y/z``, mm) of the 13 LINEMOD models of paper Table 2, as the BOP ``lm``
set's ``models_info.json`` gives it: the check a model without an entry there (LM-O ships the file with
8 of 15) still gets. Bowl (3) and cup (7) are left out: Table 2 does not use them."""
YCBV_NAMES = {
    1: "002_master_chef_can", 2: "003_cracker_box", 3: "004_sugar_box", 4: "005_tomato_soup_can",
    5: "006_mustard_bottle", 6: "007_tuna_fish_can", 7: "008_pudding_box", 8: "009_gelatin_box",
    9: "010_potted_meat_can", 10: "011_banana", 11: "019_pitcher_base", 12: "021_bleach_cleanser",
    13: "024_bowl", 14: "025_mug", 15: "035_power_drill", 16: "036_wood_block", 17: "037_scissors",
    18: "040_large_marker", 19: "051_large_clamp", 20: "052_extra_large_clamp", 21: "061_foam_brick",
}  # fmt: skip
"""YCB-Video (Xiang et al., RSS 2018) model ids -> YCB object ids."""
PUBLISHED_SIZES_MM: dict[str, dict[int, tuple[float, float, float]]] = {
    "lm": LM_SIZES_MM,
    "lmo": LM_SIZES_MM,
    "linemod": LM_SIZES_MM,
}
"""Model sizes the library carries per BOP set, used where ``models_info.json`` has no entry."""
BOP_NAMES: dict[str, dict[int, str]] = {
    "lm": LM_NAMES,
    "lmo": LM_NAMES,
    "linemod": LM_NAMES,
    "ycbv": YCBV_NAMES,
}
"""Human object names of the BOP sets that define them; every other set uses ``obj_NNNNNN``."""

_SIZE_KEYS = ("size_x", "size_y", "size_z")
_NUMBER_KEYS = ("diameter", "min_x", "min_y", "min_z", *_SIZE_KEYS)


@dataclass(frozen=True)
class ModelInfo:
    """One model's entry of ``models_info.json``, validated; lengths in mm."""

    model_id: int
    size_mm: tuple[float, float, float]
    diameter_mm: float
    n_discrete_symmetries: int
    continuous_axes: tuple[tuple[float, float, float], ...]

    def symmetry_note(self) -> str:
        """The symmetries in words ("" if none)."""
        parts = []
        if self.continuous_axes:
            axes = "; ".join(", ".join(f"{a:g}" for a in axis) for axis in self.continuous_axes)
            parts.append(f"continuous about ({axes})")
        if self.n_discrete_symmetries:
            parts.append(f"{self.n_discrete_symmetries} discrete")
        return "symmetries (models_info.json): " + ", ".join(parts) if parts else ""


def model_file(models_dir: Path, model_id: int) -> Path:
    """The model file of ``model_id`` in a BOP ``models`` folder."""
    return models_dir / f"obj_{model_id:06d}.ply"


def models_dir(folder: Path) -> Path:
    """``folder/models`` if it exists, else ``folder`` (a root may name the set or its models folder)."""
    return folder / "models" if (folder / "models").is_dir() else folder


def model_ids(models: Path) -> list[int]:
    """The ids of a BOP models folder: those of ``models_info.json`` and of the ``obj_NNNNNN.ply`` files
    present (a set may ship the file without every entry, as LM-O does). Raises DatasetError if none."""
    ids = {int(p.stem[4:]) for p in models.glob("obj_*.ply") if p.stem[4:].isdigit()}
    if (models / INFO_FILE).is_file():
        ids |= set(read_models_info(models))
    if not ids:
        raise DatasetError(
            f"BOP models folder {models.resolve()} holds no obj_NNNNNN.ply model and no {INFO_FILE}; "
            "point dataset.root at a BOP set's folder (the one holding models/)"
        )
    return sorted(ids)


def object_names(ids: list[int], bop_set: str) -> dict[str, int]:
    """name -> model id for every id, human names where set ``bop_set`` defines them."""
    names = BOP_NAMES.get(bop_set.lower(), {})
    return {names.get(i, f"obj_{i:06d}"): i for i in ids}


def read_models_info(models: Path) -> dict[int, ModelInfo]:
    """Every entry of ``models/models_info.json``, checked as strictly as a config: ids are integers, sizes
    positive finite numbers, symmetries well-formed. Raises :class:`DatasetError` naming the file, the id and
    the key."""
    path = models / INFO_FILE
    try:
        return _read_cached(path.resolve(), path.stat().st_mtime_ns)
    except FileNotFoundError:
        raise DatasetError(
            f"BOP models folder {models.resolve()} has no {INFO_FILE}; a BOP set ships it beside the models "
            "(it gives each model's size and symmetries)"
        ) from None


@functools.lru_cache(maxsize=16)
def _read_cached(path: Path, _mtime_ns: int) -> dict[int, ModelInfo]:
    try:
        data = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
        raise DatasetError(f"cannot read {path}: {err}") from None
    if not isinstance(data, dict) or not data:
        raise DatasetError(f"{path} must map model ids to their info, got {type(data).__name__}")
    return {_model_id(path, key): _model_info(path, key, entry) for key, entry in data.items()}


def _model_id(path: Path, key: str) -> int:
    if not key.isdigit() or int(key) < 1:
        raise DatasetError(f"{path}: model id {key!r} is not a positive integer")
    return int(key)


def _model_info(path: Path, key: str, entry: Any) -> ModelInfo:
    where = f"{path}: model {key}"
    if not isinstance(entry, dict):
        raise DatasetError(f"{where}: expected a mapping of {', '.join(_NUMBER_KEYS)}, got {entry!r}")
    for name in _NUMBER_KEYS:
        value = entry.get(name)
        if name not in _SIZE_KEYS and value is None:
            continue  # optional: only the sizes are needed here
        if not is_real(value) or (name in _SIZE_KEYS + ("diameter",) and value <= 0):
            raise DatasetError(
                f"{where}: {name} must be a {'positive ' if 'min' not in name else ''}number (mm), got {value!r}"
            )
    discrete = entry.get("symmetries_discrete", [])
    if not isinstance(discrete, list) or not all(
        isinstance(m, list) and len(m) == 16 and all(is_real(x) for x in m) for m in discrete
    ):
        raise DatasetError(f"{where}: symmetries_discrete must be a list of 16-number row-major 4x4 matrices")
    continuous = entry.get("symmetries_continuous", [])
    axes = []
    for sym in continuous if isinstance(continuous, list) else [None]:
        axis = sym.get("axis") if isinstance(sym, dict) else None
        if not (isinstance(axis, list) and len(axis) == 3 and all(is_real(a) for a in axis)):
            raise DatasetError(
                f"{where}: symmetries_continuous must be a list of {{axis: [x, y, z], offset: [...]}}"
            )
        axes.append(tuple(float(a) for a in axis))
    return ModelInfo(
        model_id=int(key),
        size_mm=tuple(float(entry[k]) for k in _SIZE_KEYS),
        diameter_mm=float(entry.get("diameter", math.nan)),
        n_discrete_symmetries=len(discrete),
        continuous_axes=tuple(axes),
    )
