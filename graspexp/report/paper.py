"""The numbers printed in the paper, as data: Tables 1 and 2 and the planner runtime of section IV-F.

Source: "Optimal grasping strategy for robots with a parallel gripper based on feature sensing of 3D
object model", section IV (/work/shared/paper/optimal-grasping-strategy.txt). Every value below is
copied from the paper as printed (success rates in %, 10 trials per object and setting); nothing here
is computed. The printed averages are kept as printed too, so a report can show both the paper's
average and the average over the subset of objects we ran.
"""

from dataclasses import dataclass

SETTINGS: tuple[tuple[str, str], ...] = (("collab", "z"), ("collab", "xyz"), ("bin", "z"), ("bin", "xyz"))
"""(mode, rot) in the paper's column order: Ours-Z / Ours-XYZ (Collaborative), Ours-Z / Ours-XYZ (Bin picking)."""

SETTING_LABELS: dict[tuple[str, str], str] = {
    ("collab", "z"): "Z Collaborative",
    ("collab", "xyz"): "XYZ Collaborative",
    ("bin", "z"): "Z Bin picking",
    ("bin", "xyz"): "XYZ Bin picking",
}

BASELINES: tuple[str, ...] = ("GPD [18]", "PointNetGPD 2-class [19]", "PointNetGPD 3-class [19]")
"""Table 1's baseline columns (other methods; copied from the paper, never re-run here)."""

PLANNER_RUNTIME_S = 0.1
"""Section IV-F: the grasping strategy (segment into clusters, create grasping paths, cost function)
runs in 0.1 s on an Intel i7-9700 @ 3.0 GHz (pose estimation, 0.04 s, not included)."""

TRIALS_PER_SETTING = 10
"""Section IV-D: "we tested ten rounds on each of the objects"."""


@dataclass(frozen=True)
class PaperTable:
    """One of the paper's success-rate tables."""

    number: int
    dataset: str
    """Our dataset name (config ``dataset.name``)."""
    title: str
    labels: dict[str, str]
    """Our object id -> the paper's row label, in the paper's row order."""
    ours: dict[str, tuple[float, float, float, float]]
    """Our object id -> the paper's own success rates (%), in :data:`SETTINGS` order."""
    ours_average: tuple[float, float, float, float]
    """The paper's Average row for its own method, as printed."""
    baselines: dict[str, tuple[float, ...]]
    """Our object id -> baseline success rates (%), in :data:`BASELINES` order (empty for Table 2)."""
    baselines_average: tuple[float, ...]


# TABLE 1. "Comparison between the proposed method and state-of-the-art approaches in the grasping
# success rate on the YCB-Video dataset." Columns: GPD [18], PointnetGPD 2-class [19],
# PointnetGPD 3-class [19], Ours-Z (Collaborative robots), Ours-XYZ (Collaborative robots),
# Ours-Z (Bin picking), Ours-XYZ (Bin picking).
_TABLE1_ROWS: tuple[tuple[str, str, tuple[float, ...]], ...] = (
    ("021_bleach_cleanser", "Cleanser B.", (100, 100, 90, 100, 90, 100, 100)),
    ("025_mug", "Mug", (30, 50, 70, 100, 100, 80, 60)),
    ("010_potted_meat_can", "Meat Can", (60, 80, 70, 90, 90, 100, 100)),
    ("005_tomato_soup_can", "Tomato Soup", (90, 100, 100, 100, 100, 70, 100)),
    ("011_banana", "Banana", (20, 90, 90, 100, 100, 100, 100)),
    ("035_power_drill", "Power Drill", (80, 70, 90, 100, 100, 100, 100)),
    ("006_mustard_bottle", "Mustard B.", (90, 100, 90, 90, 100, 100, 100)),
    ("036_wood_block", "Wood Block", (90, 90, 90, 50, 70, 100, 100)),
    ("043_phillips_screwdriver", "Screwdriver", (20, 70, 80, 100, 100, 100, 100)),
)
_TABLE1_AVERAGE = (64.44, 83.33, 85.56, 92.22, 94.44, 94.44, 95.56)

# TABLE 2. "Grasping success rate on LINEMOD dataset." Columns: Ours-Z (Collaborative mode),
# Ours-XYZ (Collaborative mode), Ours-Z (Bin picking), Ours-XYZ (Bin picking).
_TABLE2_ROWS: tuple[tuple[str, str, tuple[float, ...]], ...] = (
    ("ape", "Ape", (100, 100, 90, 80)),
    ("benchvise", "Bench vise", (100, 100, 90, 100)),
    ("cam", "Cam", (100, 100, 100, 100)),
    ("can", "Can", (100, 100, 100, 90)),
    ("cat", "Cat", (100, 100, 100, 100)),
    ("driller", "Driller", (100, 100, 100, 100)),
    ("duck", "Duck", (100, 100, 100, 90)),
    ("eggbox", "Egg box", (60, 60, 70, 90)),
    ("glue", "Glue", (100, 100, 90, 100)),
    ("holepuncher", "Hole p.", (80, 80, 100, 70)),
    ("iron", "Iron", (100, 90, 100, 80)),
    ("lamp", "Lamp", (100, 100, 90, 100)),
    ("phone", "Phone", (100, 100, 100, 100)),
)
_TABLE2_AVERAGE = (95.38, 94.62, 94.62, 92.31)

TABLE1 = PaperTable(
    number=1,
    dataset="ycb",
    title="Grasping success rate on YCB-Video (paper Table 1)",
    labels={k: label for k, label, _ in _TABLE1_ROWS},
    ours={k: tuple(float(v) for v in vals[3:]) for k, _, vals in _TABLE1_ROWS},  # type: ignore[misc]
    ours_average=tuple(float(v) for v in _TABLE1_AVERAGE[3:]),  # type: ignore[arg-type]
    baselines={k: tuple(float(v) for v in vals[:3]) for k, _, vals in _TABLE1_ROWS},
    baselines_average=tuple(float(v) for v in _TABLE1_AVERAGE[:3]),
)

TABLE2 = PaperTable(
    number=2,
    dataset="linemod",
    title="Grasping success rate on LINEMOD (paper Table 2)",
    labels={k: label for k, label, _ in _TABLE2_ROWS},
    ours={k: tuple(float(v) for v in vals) for k, _, vals in _TABLE2_ROWS},  # type: ignore[misc]
    ours_average=tuple(float(v) for v in _TABLE2_AVERAGE),  # type: ignore[arg-type]
    baselines={},
    baselines_average=(),
)

PAPER_TABLES: dict[str, PaperTable] = {t.dataset: t for t in (TABLE1, TABLE2)}
"""Our dataset name -> the paper table that reports it."""
