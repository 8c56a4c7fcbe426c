"""What exists: the layouts, their object names, file paths, published facts and where the data root is.

Four layouts (``dataset.layout``; None takes the catalogued set's own):

- ``ycb``: ``<id>/google_16k/textured.obj`` (official archives) or ``models/<id>/textured.obj`` (YCB-Video),
  metres, the published masses of :mod:`graspexp.datasets.ycb_objects`;
- ``bop``: any BOP set (:mod:`graspexp.datasets.bop`), millimetres; ``linemod`` is the catalogued instance;
- ``folder``: your own meshes and URDFs (:mod:`graspexp.datasets.folder`); ``vgn_pile`` and ``vgn_packed``
  are catalogued instances (VGN's and GIGA's clutter test objects, :mod:`graspexp.datasets.vgn_clutter`);
- ``primitives``: procedural shapes (:mod:`graspexp.datasets.primitives`).

Nothing here reads a mesh; :mod:`graspexp.datasets.loader` does that.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from graspexp.datasets import bop, folder, vgn_clutter
from graspexp.datasets.errors import DatasetError
from graspexp.datasets.source import MeshPart, ObjectSource
from graspexp.datasets.ycb_objects import GOOGLE_16K_EXTENTS_MM, GOOGLE_16K_FACES, YCB_MASS_KG

DATA_ENV = "GRASPEXP_DATA"
"""Environment variable naming the data root when ``dataset.root`` is not set."""
DEFAULT_ROOT = "datasets"
"""Data root (relative to the working directory) when neither ``dataset.root`` nor the env var is set."""

LINEMOD_IDS: dict[str, int] = {name: i for i, name in bop.LM_NAMES.items() if name not in ("bowl", "cup")}
"""The 13 LINEMOD objects of paper Table 2 (BOP ``lm`` ids; bowl and cup have no pose benchmark)."""
LINEMOD_MM_TO_M = bop.MM_TO_M

PRIMITIVE_NAMES: tuple[str, ...] = ("can", "box", "bottle", "mug", "banana", "block")

YCB_TABLE1: tuple[str, ...] = (
    "021_bleach_cleanser",
    "025_mug",
    "010_potted_meat_can",
    "005_tomato_soup_can",
    "011_banana",
    "035_power_drill",
    "006_mustard_bottle",
    "036_wood_block",
    "043_phillips_screwdriver",
)
"""The 9 YCB objects of paper Table 1, in its order: the default list and the ``train`` split."""
YCB_STAGED_EXTRAS: tuple[str, ...] = (
    "002_master_chef_can",
    "003_cracker_box",
    "004_sugar_box",
    "007_tuna_fish_can",
    "008_pudding_box",
    "009_gelatin_box",
    "019_pitcher_base",
    "024_bowl",
    "037_scissors",
    "040_large_marker",
    "044_flat_screwdriver",
    "051_large_clamp",
    "052_extra_large_clamp",
    "061_foam_brick",
)
"""The ``test`` split of ``ycb``: the 14 other objects staged in the shared data (none is in Table 1), so
constants tuned on Table 1 are scored on objects the study never saw. A fixed list: downloading more of
the catalogue does not change what a test score means."""


@dataclass(frozen=True)
class DatasetSpec:
    """Static facts about one catalogued dataset (the registry value; ``dataset.name`` is the key)."""

    name: str
    layout: str
    catalogue: tuple[str, ...]
    """Every object name the loader accepts."""
    default_objects: tuple[str, ...]
    """Object list used when ``dataset.objects`` is empty (paper Table 1 / Table 2 order)."""
    subfolder: str | None
    """``<root>/<subfolder>`` is the dataset folder when it exists, else ``<root>`` itself."""
    downloadable: bool
    splits: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    """Named object lists (``train``, ``test``) that ``dataset.split`` selects instead of the default list:
    tune on one, score on the other."""


DATASETS: dict[str, DatasetSpec] = {
    "ycb": DatasetSpec(
        name="ycb",
        layout="ycb",
        catalogue=tuple(YCB_MASS_KG),
        default_objects=YCB_TABLE1,
        subfolder="ycb",
        downloadable=True,
        splits={"train": YCB_TABLE1, "test": YCB_STAGED_EXTRAS},
    ),
    "linemod": DatasetSpec(
        name="linemod",
        layout="bop",
        catalogue=tuple(LINEMOD_IDS),
        default_objects=tuple(LINEMOD_IDS),
        subfolder="linemod",
        downloadable=True,
    ),
    **{
        f"vgn_{scene}": DatasetSpec(
            name=f"vgn_{scene}",
            layout="folder",
            catalogue=vgn_clutter.object_names(scene),
            default_objects=vgn_clutter.object_names(scene),
            subfolder=vgn_clutter.set_folder(scene),
            downloadable=True,
        )
        for scene in vgn_clutter.SCENES
    },
    "primitives": DatasetSpec(
        name="primitives",
        layout="primitives",
        catalogue=PRIMITIVE_NAMES,
        default_objects=PRIMITIVE_NAMES,
        subfolder=None,
        downloadable=False,
        splits={"train": PRIMITIVE_NAMES[:3], "test": PRIMITIVE_NAMES[3:]},
    ),
}
"""The catalogued datasets: their object names are known without reading the data root."""


def dataset_spec(name: str) -> DatasetSpec:
    """The registry entry for ``name``; an unknown name lists the valid ones."""
    try:
        return DATASETS[name]
    except KeyError:
        raise DatasetError(
            f"unknown dataset {name!r} (dataset.name); catalogued: {', '.join(sorted(DATASETS))}; "
            "for your own objects use dataset=folder or dataset=bop with dataset.root=DIR"
        ) from None


def catalogued(cfg: Any) -> DatasetSpec | None:
    """The registry entry of ``cfg`` if it is a catalogued set read in its own layout, else None. A
    catalogued name read in another layout is refused (its tables would pass for the paper's)."""
    spec = DATASETS.get(cfg.name)
    layout = getattr(cfg, "layout", None)
    if spec is None or layout in (None, spec.layout):
        return spec
    raise DatasetError(
        f"dataset.name={cfg.name!r} is the catalogued {spec.layout} set; a dataset read with "
        f"dataset.layout={layout} needs another name (dataset.name=...)"
    )


def layout_of(cfg: Any) -> str:
    """The layout ``cfg`` is read with (``dataset.layout``, or the catalogued set's)."""
    spec = catalogued(cfg)
    if spec is not None:
        return spec.layout
    layout = getattr(cfg, "layout", None)
    if layout is None:
        dataset_spec(cfg.name)  # raises, naming the catalogued sets and the layouts
    return str(layout)


def download_command(name: str, root: Path | str) -> str:
    """The shell command that fetches dataset ``name`` into ``root``."""
    return f"python -m graspexp download dataset={name} dataset.root={root}"


def resolve_root(cfg: Any) -> Path:
    """The data root: ``cfg.root`` if set, else env ``GRASPEXP_DATA``, else ``./datasets``.

    ``~`` is expanded; a relative path stays relative to the working directory.
    """
    root = getattr(cfg, "root", None)
    if root in (None, ""):
        if getattr(cfg, "layout", None) == "folder":
            raise DatasetError("dataset=folder needs the folder of your meshes: dataset.root=DIR")
        root = os.environ.get(DATA_ENV) or DEFAULT_ROOT
    return Path(str(root)).expanduser()


def dataset_dir(cfg: Any) -> Path:
    """The dataset folder: ``<root>/<subfolder>`` if that exists, else the root itself.

    So ``dataset.root`` may name either the common data root (holding ``ycb/``, ``linemod/`` or a BOP set's
    folder named by ``dataset.bop_set``) or the dataset's own folder.
    """
    root = resolve_root(cfg)
    spec = catalogued(cfg)
    sub = spec.subfolder if spec is not None else getattr(cfg, "bop_set", None)
    if sub and (root / sub).is_dir():
        return root / sub
    return root


def _bop_models(cfg: Any) -> tuple[Path, dict[str, int]]:
    """(models folder, name -> model id) of a BOP-layout dataset."""
    models = bop.models_dir(dataset_dir(cfg))
    spec = catalogued(cfg)
    if spec is not None:
        return models, LINEMOD_IDS
    if not models.is_dir():
        raise DatasetError(
            f"BOP dataset folder {models.resolve()} does not exist (dataset.root / ${DATA_ENV})"
        )
    return models, bop.object_names(bop.model_ids(models), _bop_set(cfg))


def _bop_set(cfg: Any) -> str:
    """The BOP set's short name (``linemod`` for the catalogued instance, else ``dataset.bop_set`` or the
    folder's name), lower case."""
    if catalogued(cfg) is not None:
        return str(cfg.name).lower()
    return str(getattr(cfg, "bop_set", None) or dataset_dir(cfg).name).lower()


def catalogue(cfg: Any) -> tuple[str, ...]:
    """Every object name dataset ``cfg`` accepts (a folder's and a BOP set's are read from disk)."""
    spec = catalogued(cfg)
    if spec is not None:
        return spec.catalogue
    layout = layout_of(cfg)
    if layout == "folder":
        return tuple(folder.scan(dataset_dir(cfg)))
    return tuple(_bop_models(cfg)[1])


def default_objects(cfg: Any) -> tuple[str, ...]:
    """The objects of a run when ``dataset.objects`` is empty: the split ``dataset.split`` names, else the
    paper's list, or every object; DatasetError for a split the dataset does not define."""
    spec = catalogued(cfg)
    split = getattr(cfg, "split", None)
    if split is not None:
        splits = spec.splits if spec is not None else {}
        if split not in splits:
            having = ", ".join(n for n, s in DATASETS.items() if split in s.splits)
            raise DatasetError(f"dataset {cfg.name!r} has no {split!r} split (dataset.split); {having} do")
        return splits[split]
    return spec.default_objects if spec is not None else catalogue(cfg)


def check_object_name(cfg: Any, name: str) -> None:
    """Raise :class:`DatasetError` listing the valid names if ``name`` is not in the catalogue."""
    names = catalogue(cfg)
    if name not in names:
        raise DatasetError(
            f"unknown object {name!r} in dataset {cfg.name!r}; valid names: {', '.join(names)}"
        )


def candidate_paths(cfg: Any, name: str) -> list[Path]:
    """The mesh files that may hold object ``name``, in the order they are tried (empty for primitives)."""
    check_object_name(cfg, name)
    layout = layout_of(cfg)
    if layout == "ycb":
        base = dataset_dir(cfg)
        return [
            base / name / "google_16k" / "textured.obj",  # official google_16k archives
            base / "models" / name / "textured.obj",  # YCB-Video layout
        ]
    if layout == "bop":
        models, ids = _bop_models(cfg)
        return [bop.model_file(models, ids[name])]
    if layout == "folder":
        if catalogued(cfg) is not None:  # a catalogued set of URDFs: its names are known, nothing is scanned
            return [dataset_dir(cfg) / f"{name}.urdf"]
        return [folder.scan(dataset_dir(cfg))[name].file]
    return []


def mesh_path(cfg: Any, name: str) -> Path:
    """The existing mesh file of ``name``; a clear :class:`DatasetError` when the folder or file is missing."""
    paths = candidate_paths(cfg, name)
    for path in paths:
        if path.is_file():
            return path
    root = resolve_root(cfg)
    base = dataset_dir(cfg)
    fix = f"download it with: {download_command(cfg.name, root)}" if catalogued(cfg) else "put it there"
    if not base.is_dir():
        raise DatasetError(
            f"{cfg.name} dataset folder {base.resolve()} does not exist (dataset.root / ${DATA_ENV}); {fix}"
        )
    tried = " or ".join(str(p.resolve()) for p in paths)
    raise DatasetError(f"mesh file for {cfg.name} object {name!r} not found: {tried}; {fix}")


def object_source(cfg: Any, name: str) -> ObjectSource:
    """What object ``name`` of dataset ``cfg`` is made of (files, units, published mass and size, sidecar)."""
    layout = layout_of(cfg)
    if layout == "primitives":
        check_object_name(cfg, name)
        return ObjectSource(name=name, parts=())
    if layout == "folder" and catalogued(cfg) is not None:
        urdf = mesh_path(cfg, name)  # the catalogued set's URDF, or the error naming the download command
        return folder.object_source(urdf.parent, folder.FolderEntry(name, urdf, True), str(cfg.units))
    if layout == "folder":
        base = dataset_dir(cfg)
        entries = folder.scan(base)
        if name not in entries:
            check_object_name(cfg, name)
        return folder.object_source(base, entries[name], str(cfg.units))
    path = mesh_path(cfg, name)
    if layout == "ycb":
        google_16k = path.parent.name == "google_16k"
        size = GOOGLE_16K_EXTENTS_MM.get(name) if google_16k else None
        return ObjectSource(
            name=name,
            parts=(MeshPart(path),),
            source=str(path.resolve()),
            mass_kg=YCB_MASS_KG[name],
            published_faces=GOOGLE_16K_FACES if google_16k else None,
            published_size=size,
            published_where="the google_16k model's extents (graspexp.datasets.ycb_objects.GOOGLE_16K_EXTENTS_MM)",
        )
    models, ids = _bop_models(cfg)
    info = bop.read_models_info(models).get(ids[name]) if (models / bop.INFO_FILE).is_file() else None
    carried = bop.PUBLISHED_SIZES_MM.get(_bop_set(cfg), {}).get(ids[name])
    where = str(models / bop.INFO_FILE)
    if info is not None:
        size, size_note = info.size_mm, info.symmetry_note()
    elif carried is not None:
        where = f"the {_bop_set(cfg)} set's models_info.json (carried by graspexp: {where} has no entry)"
        size, size_note = carried, f"size checked against {where}"
    else:
        size, size_note = None, f"size not checked: no entry in {where}"
    notes = ("units: mm (BOP)", "mass: volume x dataset.density_kg_m3", size_note)
    return ObjectSource(
        name=name,
        parts=(MeshPart(path, scale=bop.MM_TO_M),),
        source=str(path.resolve()),
        published_size=size,
        published_where=where,
        notes=tuple(n for n in notes if n),
    )


def dataset_objects(cfg: Any) -> list[str]:
    """The configured object names (``cfg.objects``), or the dataset's default list when that is empty.

    Every name is checked against the catalogue (an unknown name lists the valid ones).
    """
    names = [str(n) for n in (getattr(cfg, "objects", None) or default_objects(cfg))]
    for name in names:
        check_object_name(cfg, name)
    return names


def available_objects(cfg: Any) -> list[str]:
    """The names of :func:`dataset_objects` whose mesh files exist under the data root."""
    if layout_of(cfg) == "primitives" or (layout_of(cfg) == "folder" and catalogued(cfg) is None):
        return dataset_objects(cfg)
    return [n for n in dataset_objects(cfg) if any(p.is_file() for p in candidate_paths(cfg, n))]
