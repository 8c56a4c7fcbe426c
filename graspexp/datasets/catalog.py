"""What exists: object names, file layouts, published masses and where the data root is.

Nothing here reads a mesh; :mod:`graspexp.datasets.loader` does that.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from graspexp.datasets.errors import DatasetError

DATA_ENV = "GRASPEXP_DATA"
"""Environment variable naming the data root when ``dataset.root`` is not set."""
DEFAULT_ROOT = "datasets"
"""Data root (relative to the working directory) when neither ``dataset.root`` nor the env var is set."""

# Published YCB masses in kg: Calli et al., "Benchmarking in Manipulation Research: The YCB Object and
# Model Set and Benchmarking Protocols", IEEE RAM 2015, Table 1 (also the object list on
# ycbbenchmarks.com). The keys are the catalogue of YCB objects this package knows; it covers the 21
# YCB-Video objects and both screwdrivers (paper Table 1 uses 043_phillips_screwdriver).
YCB_MASS_KG: dict[str, float] = {
    "002_master_chef_can": 0.414,
    "003_cracker_box": 0.411,
    "004_sugar_box": 0.514,
    "005_tomato_soup_can": 0.349,
    "006_mustard_bottle": 0.603,
    "007_tuna_fish_can": 0.171,
    "008_pudding_box": 0.187,
    "009_gelatin_box": 0.097,
    "010_potted_meat_can": 0.370,
    "011_banana": 0.066,
    "019_pitcher_base": 0.178,
    "021_bleach_cleanser": 1.131,
    "024_bowl": 0.147,
    "025_mug": 0.118,
    "035_power_drill": 0.895,
    "036_wood_block": 0.729,
    "037_scissors": 0.082,
    "040_large_marker": 0.0158,
    "043_phillips_screwdriver": 0.097,
    "044_flat_screwdriver": 0.0984,
    "051_large_clamp": 0.125,
    "052_extra_large_clamp": 0.202,
    "061_foam_brick": 0.028,
}

# LINEMOD / BOP ``lm`` object ids (Hinterstoisser et al., ACCV 2012; paper Table 2 order).
LINEMOD_IDS: dict[str, int] = {
    "ape": 1,
    "benchvise": 2,
    "cam": 4,
    "can": 5,
    "cat": 6,
    "driller": 8,
    "duck": 9,
    "eggbox": 10,
    "glue": 11,
    "holepuncher": 12,
    "iron": 13,
    "lamp": 14,
    "phone": 15,
}

LINEMOD_MM_TO_M = 1e-3
"""BOP LINEMOD models are in millimetres."""

PRIMITIVE_NAMES: tuple[str, ...] = ("can", "box", "bottle", "mug", "banana", "block")


@dataclass(frozen=True)
class DatasetSpec:
    """Static facts about one dataset (the registry value; the config's ``dataset.name`` is the key)."""

    name: str
    catalogue: tuple[str, ...]
    """Every object name the loader accepts."""
    default_objects: tuple[str, ...]
    """Object list used when ``dataset.objects`` is empty (paper Table 1 / Table 2 order)."""
    subfolder: str | None
    """``<root>/<subfolder>`` is the dataset folder when it exists, else ``<root>`` itself."""
    downloadable: bool


DATASETS: dict[str, DatasetSpec] = {
    "ycb": DatasetSpec(
        name="ycb",
        catalogue=tuple(YCB_MASS_KG),
        default_objects=(
            "021_bleach_cleanser",
            "025_mug",
            "010_potted_meat_can",
            "005_tomato_soup_can",
            "011_banana",
            "035_power_drill",
            "006_mustard_bottle",
            "036_wood_block",
            "043_phillips_screwdriver",
        ),
        subfolder="ycb",
        downloadable=True,
    ),
    "linemod": DatasetSpec(
        name="linemod",
        catalogue=tuple(LINEMOD_IDS),
        default_objects=tuple(LINEMOD_IDS),
        subfolder="linemod",
        downloadable=True,
    ),
    "primitives": DatasetSpec(
        name="primitives",
        catalogue=PRIMITIVE_NAMES,
        default_objects=PRIMITIVE_NAMES,
        subfolder=None,
        downloadable=False,
    ),
}


def dataset_spec(name: str) -> DatasetSpec:
    """The registry entry for ``name``; an unknown name lists the valid ones."""
    try:
        return DATASETS[name]
    except KeyError:
        raise DatasetError(
            f"unknown dataset {name!r} (dataset.name); valid names: {', '.join(sorted(DATASETS))}"
        ) from None


def download_command(name: str, root: Path | str) -> str:
    """The shell command that fetches dataset ``name`` into ``root``."""
    return f"python -m graspexp download dataset={name} dataset.root={root}"


def resolve_root(cfg: Any) -> Path:
    """The data root: ``cfg.root`` if set, else env ``GRASPEXP_DATA``, else ``./datasets``.

    ``~`` is expanded; a relative path stays relative to the working directory.
    """
    root = getattr(cfg, "root", None)
    if root in (None, ""):
        root = os.environ.get(DATA_ENV) or DEFAULT_ROOT
    return Path(str(root)).expanduser()


def dataset_dir(cfg: Any) -> Path:
    """The dataset folder: ``<root>/<subfolder>`` if that exists, else the root itself.

    So ``dataset.root`` may name either the common data root (holding ``ycb/`` and ``linemod/``) or the
    dataset's own folder (a folder of ``<id>/google_16k/`` or a BOP folder holding ``models/``).
    """
    spec = dataset_spec(cfg.name)
    root = resolve_root(cfg)
    if spec.subfolder is not None and (root / spec.subfolder).is_dir():
        return root / spec.subfolder
    return root


def check_object_name(dataset: str, name: str) -> None:
    """Raise :class:`DatasetError` listing the valid names if ``name`` is not in the catalogue."""
    spec = dataset_spec(dataset)
    if name not in spec.catalogue:
        raise DatasetError(
            f"unknown object {name!r} in dataset {dataset!r}; valid names: {', '.join(spec.catalogue)}"
        )


def candidate_paths(cfg: Any, name: str) -> list[Path]:
    """The mesh files that may hold object ``name``, in the order they are tried (empty for primitives)."""
    check_object_name(cfg.name, name)
    folder = dataset_dir(cfg)
    if cfg.name == "ycb":
        return [
            folder / name / "google_16k" / "textured.obj",  # official google_16k archives
            folder / "models" / name / "textured.obj",  # YCB-Video layout
        ]
    if cfg.name == "linemod":
        return [folder / "models" / f"obj_{LINEMOD_IDS[name]:06d}.ply"]  # BOP layout, millimetres
    return []


def mesh_path(cfg: Any, name: str) -> Path:
    """The existing mesh file of ``name``; a clear :class:`DatasetError` when the folder or file is missing."""
    paths = candidate_paths(cfg, name)
    for path in paths:
        if path.is_file():
            return path
    root = resolve_root(cfg)
    folder = dataset_dir(cfg)
    fix = f"download it with: {download_command(cfg.name, root)}"
    if not folder.is_dir():
        raise DatasetError(
            f"{cfg.name} dataset folder {folder.resolve()} does not exist (dataset.root / ${DATA_ENV}); {fix}"
        )
    tried = " or ".join(str(p.resolve()) for p in paths)
    raise DatasetError(f"mesh file for {cfg.name} object {name!r} not found: {tried}; {fix}")


def dataset_objects(cfg: Any) -> list[str]:
    """The configured object names (``cfg.objects``), or the dataset's default list when that is empty.

    Every name is checked against the catalogue (an unknown name lists the valid ones).
    """
    spec = dataset_spec(cfg.name)
    names = [str(n) for n in (getattr(cfg, "objects", None) or spec.default_objects)]
    for name in names:
        check_object_name(cfg.name, name)
    return names


def available_objects(cfg: Any) -> list[str]:
    """The names of :func:`dataset_objects` whose mesh files exist under the data root."""
    if cfg.name == "primitives":
        return dataset_objects(cfg)
    return [n for n in dataset_objects(cfg) if any(p.is_file() for p in candidate_paths(cfg, n))]
