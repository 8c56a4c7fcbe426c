"""Schema of ``planner=vgn``: the Volumetric Grasping Network (Breyer, Chung, Ott, Siegwart, Nieto, CoRL
2020, arXiv:2101.01132) run from its published checkpoint on the camera's depth views
(graspexp/planning/learned/vgn.py). The defaults are the values of the authors' detection code
(ethz-asl/vgn ``src/vgn/detection.py``, the version of the paper's experiments).

It needs the optional extra ``learned`` (torch, Open3D) and the checkpoint; :func:`unavailable` says
which is missing, as one line naming the command, when a config selects the planner. ``planner.checkpoint``
chooses the weights (:data:`VGN_CHECKPOINTS`): VGN's own, or VGN as GIGA's authors retrained it on single
side views; ``force_threshold`` and ``wall_margin_m`` are GIGA's additions to the detection (off by default).
"""

from dataclasses import dataclass
from importlib.util import find_spec

from graspexp.config.constraints import Interval, Options
from graspexp.config.planner.base import BASE_CONSTRAINTS, PlannerConfig
from graspexp.config.plugins import Learned, PlannerPlugin
from graspexp.core.checkpoints import VGN, VGN_PACKED, VGN_PILE, Checkpoint, missing_reason

EXTRA_MODULES = ("torch", "open3d")
"""What the ``learned`` extra installs and this planner imports."""
INSTALL = "pip install -e '.[learned]'"
"""The command that installs the extra (from a checkout; ``pip install 'graspexp[learned]'`` from a wheel)."""
VGN_CHECKPOINTS: dict[str, Checkpoint] = {"vgn_conv": VGN, "vgn_pile": VGN_PILE, "vgn_packed": VGN_PACKED}
"""The weights ``planner.checkpoint`` names (each pinned by SHA-256, :mod:`graspexp.core.checkpoints`)."""


@dataclass
class VgnConfig(PlannerConfig):
    quality_threshold: float = 0.9
    """A voxel is a grasp candidate when its smoothed predicted quality reaches this (VGN's detection
    threshold, 0.90)."""
    quality_sigma_voxels: float = 1.0
    """Standard deviation of the Gaussian that smooths the quality volume before thresholding, voxels
    (VGN: 1.0; 0: no smoothing)."""
    surface_band_voxels: int = 2
    """Candidates lie in the observed free space in front of a surface (the TSDF's truncation band) or
    up to this many voxels beyond it, never behind a surface (VGN: 2 dilations of the free-space voxels,
    masked by the voxels behind a surface)."""
    nms_size_voxels: int = 4
    """Edge of the cube of the non-maximum suppression: a candidate is kept only where its quality is
    the largest in this cube, voxels (VGN: 4)."""
    min_width_m: float = 0.01
    """Candidates whose predicted width is below this are dropped, m (VGN: 1.33 voxels = 1 cm)."""
    max_width_m: float = 0.07
    """Candidates whose predicted width is above this are dropped, m (VGN: 9.33 voxels = 7 cm)."""
    min_target_points: int = 5
    """A candidate must hold at least this many observed points of the target object between its pads
    (within the finger width, the planned opening and the finger length): VGN detects grasps on every
    surface in its volume (the support's edge too), and the trial grasps one object."""
    selection: str = "random"
    """Which candidate is executed: ``random``, a uniformly drawn one, seeded by the trial (VGN's clutter
    removal shuffles the detections and executes the first); ``best``, the highest quality."""
    opening: str = "max"
    """Planned opening: ``max``, the gripper's stroke (VGN's simulated Panda opens fully before every
    grasp); ``predicted``, the network's width plus twice ``width_clearance_m`` (at most the stroke)."""
    width_clearance_m: float = 0.005
    """With ``opening=predicted``: clearance added on each side of the predicted width, m."""
    threads: int = 1
    """torch threads of the forward pass (1: one core, as the runner gives each job). The outputs repeat bit
    for bit for one count; another count may move their last digits (torch splits the convolutions' sums by
    thread; measured on an Intel Xeon with AVX-512), so the count is part of what decides a result."""
    checkpoint: str = "vgn_conv"
    """The weights the network loads (:data:`VGN_CHECKPOINTS`): ``vgn_conv``, VGN's own model (ethz-asl/vgn
    ``assets/models/vgn_conv.pth``, trained on noise-free six-view TSDFs); ``vgn_pile`` or ``vgn_packed``, VGN
    retrained by GIGA's authors on single noisy side views of pile or packed scenes (GIGA, RSS 2021, Sec. VI-B:
    the VGN rows of its Table I). Each is pinned by SHA-256 and fetched by ``python -m graspexp
    download_checkpoint NAME`` (``vgn_conv``'s download name is ``vgn``)."""
    force_threshold: float | None = None
    """When no candidate reaches ``quality_threshold``, keep the single best candidate whose smoothed quality
    reaches this instead (in [0, 1]); None: off (VGN's detection). GIGA's ``--force`` (UT-Austin-RPL/GIGA
    ``src/vgn/detection_implicit.py``, ``select``: ``LOW_TH = 0.5``), used for its Table I runs of VGN and GIGA
    so that a scene whose detections are all below 0.9 still gets a grasp. It applies to the whole volume: in
    a clutter scene the one kept candidate is planned for the object it holds."""
    wall_margin_m: float = 0.0
    """Candidates in the first and last ``int(wall_margin_m / voxel length)`` voxel layers along the
    workspace's x and y are dropped, m (0: off, VGN's detection). GIGA's detection drops grasps within 2 cm
    of the x/y walls (``bound`` in UT-Austin-RPL/GIGA ``src/vgn/detection_implicit.py``, "avoid grasp out of
    bound"; 0.02 m of 7.5 mm voxels is 2 layers on each side). Its z limit (5.5 cm above the volume's floor,
    at the support) is not a key: graspexp assigns candidates to the objects they hold."""


CONSTRAINTS = {
    **BASE_CONSTRAINTS,
    "quality_threshold": [Interval(0, 1, "right")],
    "quality_sigma_voxels": [Interval(0, 10)],
    "surface_band_voxels": [Interval(0, 40, integer=True)],
    "nms_size_voxels": [Interval(1, 40, integer=True)],
    "min_width_m": [Interval(0, 0.3, unit="m")],
    "max_width_m": [Interval(0, 0.3, "right", "m")],
    "min_target_points": [Interval(0, 1_000_000, integer=True)],
    "selection": [Options(("random", "best"))],
    "opening": [Options(("max", "predicted"))],
    "width_clearance_m": [Interval(0, 0.05, unit="m")],
    "threads": [Interval(1, 256, integer=True)],
    "checkpoint": [Options(tuple(VGN_CHECKPOINTS))],
    "force_threshold": [None, Interval(0, 1)],
    "wall_margin_m": [Interval(0, 0.15, unit="m")],
}
"""Allowed values of every key of :class:`VgnConfig` (see :mod:`graspexp.config.constraints`)."""


def learned_unavailable(checkpoint: Checkpoint) -> str:
    """'' when a learned planner of the optional extra ``learned`` can run here with ``checkpoint``, else one line
    naming what is missing and the command that brings it (the extra's modules, then the checkpoint). It does
    not see the config: with another ``planner.checkpoint`` whose file is missing, each trial ends in an error
    of one line naming the download command (:class:`graspexp.core.checkpoints.CheckpointError`; the trial is
    listed as not run). Nothing is imported."""
    absent = [m for m in EXTRA_MODULES if find_spec(m) is None]
    if absent:
        return f"it needs {' and '.join(absent)}, the optional extra 'learned': {INSTALL}"
    return missing_reason(checkpoint)


def unavailable() -> str:
    """:func:`learned_unavailable` of ``planner=vgn``'s default checkpoint."""
    return learned_unavailable(VGN)


PLUGIN = PlannerPlugin(
    plan="graspexp.planning.learned.vgn:plan_vgn",
    plan_scene="graspexp.planning.learned.vgn:plan_vgn_scene",
    config=VgnConfig,
    constraints=CONSTRAINTS,
    unavailable=unavailable,
    needs_observation=True,
    learned=Learned(gripper="panda", checkpoints=tuple(VGN_CHECKPOINTS.values()), extra="learned"),
)
"""Entry point of ``planner=vgn`` (graspexp's ``pyproject.toml``)."""
