"""Schema of ``planner=giga``: GIGA (Jiang, Zhu, Wang, Zhu, Chen, Zhou, Bohg, Zhu, "Synergies Between
Affordance and Geometry: 6-DoF Grasp Detection via Implicit Representations", RSS 2021, arXiv:2104.01542; MIT)
run from its published checkpoints on the camera's depth views (graspexp/planning/learned/giga.py).

GIGA reads the same 40^3 TSDF as VGN and queries its implicit grasp decoders at every voxel; its detection
(UT-Austin-RPL/GIGA ``src/vgn/detection_implicit.py``) is VGN's chain (Gaussian smoothing, the free-space band,
the width range, the 0.9 threshold, 4^3 non-maximum suppression) plus its wall margin, so this schema is VGN's
(:class:`graspexp.config.planner.vgn.VgnConfig`) with GIGA's checkpoints and the values of GIGA's detection
code where they differ: the width range (0.033 to 0.233 of the 30 cm workspace) and the 2 cm wall margin
(``bound``, always applied there). ``--force`` and ``--best`` are options of GIGA's experiment script, off by
default there as here (``planner.force_threshold=0.5``, ``planner.selection=best``).

It needs the optional extra ``learned`` (torch, Open3D) and the checkpoint; :func:`unavailable` says which is
missing, as one line naming the command, when a config selects the planner.
"""

from dataclasses import dataclass

from graspexp.config.constraints import Interval, Options
from graspexp.config.planner.vgn import CONSTRAINTS as VGN_CONSTRAINTS
from graspexp.config.planner.vgn import VgnConfig, learned_unavailable
from graspexp.config.plugins import Learned, PlannerPlugin
from graspexp.core.checkpoints import GIGA_LICENCE, GIGA_MODELS_URL, Checkpoint


def _giga(scene: str, sha256: str) -> Checkpoint:
    """GIGA trained on ``scene`` scenes (single noisy side views), from its authors' release."""
    return Checkpoint(
        name=f"giga_{scene}",
        filename=f"giga_{scene}.pt",
        url=f"{GIGA_MODELS_URL}giga_{scene}.pt",
        sha256=sha256,
        size_bytes=2_390_067,
        licence=GIGA_LICENCE,
        source=(
            f"Jiang et al., GIGA, RSS 2021 (arXiv:2104.01542), trained on {scene} scenes; supersglzc/GIGA "
            f"data/models/giga_{scene}.pt at commit 30efe594 (the files of UT-Austin-RPL/GIGA's data.zip)"
        ),
    )


GIGA_PILE = _giga("pile", "dbca164667336de89f85f08335008fd6d7099af18dc14714d0989ec4bc054fdb")
GIGA_PACKED = _giga("packed", "e0f86e3b01dbbde682aa56b3ae605991e58d6d0e0e78380aded6b6c13b3fbc67")
GIGA_CHECKPOINTS: dict[str, Checkpoint] = {"giga_pile": GIGA_PILE, "giga_packed": GIGA_PACKED}
"""The weights ``planner.checkpoint`` names (each pinned by SHA-256; ``python -m graspexp download_checkpoint
NAME`` fetches it)."""


@dataclass
class GigaConfig(VgnConfig):
    checkpoint: str = "giga_pile"
    """The weights the network loads (:data:`GIGA_CHECKPOINTS`): ``giga_pile`` or ``giga_packed``, GIGA trained
    on single noisy side views of pile or packed scenes (its Table I uses each on its own scene type)."""
    min_width_m: float = 0.0099
    """Candidates whose predicted width is below this are dropped, m (GIGA: 0.033 of the 30 cm workspace,
    9.9 mm; ``process`` in ``detection_implicit.py``)."""
    max_width_m: float = 0.0699
    """Candidates whose predicted width is above this are dropped, m (GIGA: 0.233 of the 30 cm workspace,
    69.9 mm)."""
    wall_margin_m: float = 0.02
    """Candidates in the first and last ``int(wall_margin_m / voxel length)`` voxel layers along the
    workspace's x and y are dropped, m (0: off). GIGA's detection always does this with 2 cm (``bound`` in
    ``detection_implicit.py``, "avoid grasp out of bound": 2 layers of 7.5 mm on each side)."""


CONSTRAINTS = {
    **VGN_CONSTRAINTS,
    "checkpoint": [Options(tuple(GIGA_CHECKPOINTS))],
    "min_width_m": [Interval(0, 0.3, unit="m")],
    "max_width_m": [Interval(0, 0.3, "right", "m")],
    "wall_margin_m": [Interval(0, 0.15, unit="m")],
}
"""Allowed values of every key of :class:`GigaConfig` (see :mod:`graspexp.config.constraints`)."""


def unavailable() -> str:
    """:func:`graspexp.config.planner.vgn.learned_unavailable` of ``planner=giga``'s default checkpoint."""
    return learned_unavailable(GIGA_CHECKPOINTS[GigaConfig.checkpoint])


PLUGIN = PlannerPlugin(
    plan="graspexp.planning.learned.giga:plan_giga",
    plan_scene="graspexp.planning.learned.giga:plan_giga_scene",
    config=GigaConfig,
    constraints=CONSTRAINTS,
    unavailable=unavailable,
    needs_observation=True,
    learned=Learned(gripper="panda", checkpoints=tuple(GIGA_CHECKPOINTS.values()), extra="learned"),
)
"""Entry point of ``planner=giga`` (graspexp's ``pyproject.toml``)."""
