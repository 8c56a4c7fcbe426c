"""Pictures of what goes wrong, drawn from the trial logs alone (no simulator, no meshes).

For each setting (dataset, planner, mode, rot) and failure reason, a few example trials (distinct objects
first) are drawn at two instants: when the fingers have closed (or when the trial failed, if earlier) and
at the end of the log. Each picture shows the object's collision shapes, the gripper boxes and the support
top as logged on /scene and moved by /tf, and the planned grasp frame (X red, Y green, Z blue; Fig. 9).
Files are named ``<dataset>_<planner>_<mode>_<rot>_<reason>_<object>_<trial>.png`` so a reader can open
the same log (listed in ``gallery.md``) in Foxglove.
"""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

from graspexp.core.geometry import make_pose, quat_wxyz_to_matrix  # noqa: E402
from graspexp.record import CorruptLogError, TrialLog, read_trial  # noqa: E402
from graspexp.report.collect import SETTING_KEYS  # noqa: E402
from graspexp.report.render import markdown  # noqa: E402

VIEW_HALF_M = 0.13
"""Half the side of the cube drawn around the planned grasp point, m."""
AXIS_LEN_M = 0.04
"""Length of the drawn grasp-frame axes, m."""
CUBE_FACES = np.array([[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]])
"""Corner indices of the six faces of a box whose corners are ordered by the bits (x, y, z)."""


def pose_at(log: TrialLog, frame: str, t_s: float) -> np.ndarray | None:
    """(4, 4) world pose of ``frame`` at the last /tf sample at or before ``t_s``; identity for world."""
    if frame == "world":
        return np.eye(4)
    if frame not in log.transforms:
        return None
    times, pos, quat = log.transforms[frame]
    i = int(np.searchsorted(times, t_s, side="right")) - 1
    if i < 0:
        return None
    return make_pose(quat_wxyz_to_matrix(quat[i]), pos[i])


def _local_pose(p: dict) -> np.ndarray:
    q = p["orientation"]
    rot = quat_wxyz_to_matrix(np.array([q["w"], q["x"], q["y"], q["z"]], dtype=float))
    return make_pose(rot, np.array([p["position"][k] for k in "xyz"], dtype=float))


def _entities_at(log: TrialLog, t_s: float) -> dict[str, dict]:
    """The scene entities present at ``t_s``: the latest of each id added at or before, not yet deleted."""
    live: dict[str, tuple[float, dict]] = {}
    for t, ents in log.scenes:
        if t <= t_s:
            for e in ents:
                live[e["id"]] = (t, e)
    for t, ent_id in log.scene_deletions:
        if t <= t_s and ent_id in live and live[ent_id][0] <= t:
            del live[ent_id]
    return {k: e for k, (_, e) in live.items()}


def _polygons(
    log: TrialLog, t_s: float, centre: np.ndarray, half_m: float = VIEW_HALF_M
) -> list[tuple[np.ndarray, tuple]]:
    """(polygon (P, 3) world m, rgba) of every shape at ``t_s``; boxes larger than the view (the cube of
    half side ``half_m`` around ``centre``: the support) are reduced to their top face cropped to it."""
    polys = []
    for ent in _entities_at(log, t_s).values():
        frame = pose_at(log, ent["frame_id"], t_s)
        if frame is None:
            continue
        for cube in ent.get("cubes", []):
            size = np.array([cube["size"][k] for k in "xyz"], dtype=float)
            pose = frame @ _local_pose(cube["pose"])
            rgba = tuple(cube["color"][k] for k in "rgba")
            if size.max() > 2 * half_m:  # the support: its top face, cropped to the view
                top = pose[2, 3] + size[2] / 2
                lo = np.maximum(pose[:2, 3] - size[:2] / 2, centre[:2] - half_m)
                hi = np.minimum(pose[:2, 3] + size[:2] / 2, centre[:2] + half_m)
                if (lo < hi).all():
                    quad = [
                        [lo[0], lo[1], top],
                        [hi[0], lo[1], top],
                        [hi[0], hi[1], top],
                        [lo[0], hi[1], top],
                    ]
                    polys.append((np.array(quad), (*rgba[:3], 0.35)))
                continue
            bits = np.array([[(i >> 2) & 1, (i >> 1) & 1, i & 1] for i in range(8)], dtype=float) - 0.5
            corners = (bits * size) @ pose[:3, :3].T + pose[:3, 3]
            polys += [(corners[f], rgba) for f in CUBE_FACES]
        for tri in ent.get("triangles", []):
            pts = np.array([[p["x"], p["y"], p["z"]] for p in tri["points"]], dtype=float)
            pose = frame @ _local_pose(tri["pose"])
            world = pts @ pose[:3, :3].T + pose[:3, 3]
            idx = np.asarray(tri["indices"], dtype=int).reshape(-1, 3)
            rgba = tuple(tri["color"][k] for k in "rgba")
            polys += [(world[f], rgba) for f in idx]
    return polys


def key_times(log: TrialLog) -> dict[str, float]:
    """``close``: when the fingers have closed (the start of the phase after ``close``), or the failure
    time when the trial failed before; ``end``: the last /tf sample. Simulation seconds."""
    end = max((float(times[-1]) for times, _, _ in log.transforms.values()), default=0.0)
    names = [name for _, name, _ in log.phases]
    close = end
    if "close" in names:
        i = names.index("close")
        close = log.phases[i + 1][0] if i + 1 < len(log.phases) else end
    elif "failed" in names:
        close = log.phases[names.index("failed")][0]
    return {"close": close, "end": end}


def draw_trial(log: TrialLog, path: Path, title: str) -> Path:
    """Draw one trial at :func:`key_times` side by side into ``path`` (PNG), centred on the planned grasp
    point (where failures happen), else on the object's origin."""
    times = key_times(log)
    grasp = log.grasp["pose"] if log.grasp is not None else None
    obj = pose_at(log, "object", times["close"])
    centre = grasp[:3, 3] if grasp is not None else obj[:3, 3] if obj is not None else np.zeros(3)
    return draw_instants(log, times, grasp, centre, path, title)


def draw_instants(
    log: TrialLog,
    times: dict[str, float],
    grasp: np.ndarray | None,
    centre: np.ndarray,
    path: Path,
    title: str,
    half_m: float = VIEW_HALF_M,
) -> Path:
    """Draw the logged scene at each of ``times`` (label -> simulation s), side by side, into ``path``
    (PNG): the cube of half side ``half_m`` around ``centre`` (3,) world m, and the grasp frame ``grasp``
    (4, 4) world when given (the view looks along its X)."""
    fig = plt.figure(figsize=(5 * len(times), 5))
    for j, (label, t_s) in enumerate(times.items()):
        ax = fig.add_subplot(1, len(times), j + 1, projection="3d")
        polys = _polygons(log, t_s, centre, half_m)
        if polys:
            coll = Poly3DCollection([p for p, _ in polys], facecolors=[c for _, c in polys], linewidths=0.1)
            coll.set_edgecolor((0, 0, 0, 0.15))
            ax.add_collection3d(coll)
        if grasp is not None:
            for k, colour in enumerate(("r", "g", "b")):
                tip = grasp[:3, 3] + AXIS_LEN_M * grasp[:3, k]
                ax.plot(*np.stack([grasp[:3, 3], tip]).T, color=colour, linewidth=2)
            x = grasp[:3, 0]
            ax.view_init(elev=20, azim=float(np.degrees(np.arctan2(x[1], x[0]))))
        for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, strict=True):
            setter(c - half_m, c + half_m)
        ax.set_box_aspect((1, 1, 1))
        ax.set_title(f"{label}, t = {t_s:.2f} s", fontsize=9)
        ax.tick_params(labelsize=6)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


def pick_examples(df: pd.DataFrame, per_reason: int) -> pd.DataFrame:
    """Up to ``per_reason`` failed trials per (setting, reason): distinct objects first, then by trial."""
    failed = df[~df["success"]].copy()
    if failed.empty:
        return failed
    failed["reason"] = failed["reason"].fillna("(none)")
    failed = failed.sort_values([*SETTING_KEYS, "reason", "trial", "object"], kind="stable")
    failed["repeat"] = failed.groupby([*SETTING_KEYS, "reason", "object"]).cumcount()
    failed = failed.sort_values([*SETTING_KEYS, "reason", "repeat", "trial", "object"], kind="stable")
    return failed.groupby([*SETTING_KEYS, "reason"], sort=False).head(per_reason).drop(columns="repeat")


def write_gallery(df: pd.DataFrame, out_dir: Path | str, per_reason: int = 2) -> str:
    """Draw the examples of :func:`pick_examples` into ``out_dir/gallery/`` and return the Markdown index
    (also written to ``out_dir/gallery.md``). Logs that cannot be read are listed, not drawn."""
    out = Path(out_dir)
    rows, skipped = [], []
    for _, r in pick_examples(df, per_reason).iterrows():
        name = f"{r['dataset']}_{r['planner']}_{r['mode']}_{r['rot']}_{r['reason']}_{r['object']}_{int(r['trial']):03d}"
        try:
            log = read_trial(r["path"])
        except (CorruptLogError, OSError) as exc:
            skipped.append(f"- `{r['path']}`: {exc}")
            continue
        title = f"{r['object']} · {r['mode']} {r['rot']} · {r['planner']} · trial {int(r['trial'])}: {r['reason']}"
        draw_trial(log, out / "gallery" / f"{name}.png", title)
        rows.append(
            {
                "setting": f"{r['dataset']} {r['mode']} {r['rot']} {r['planner']}",
                "reason": r["reason"],
                "object": r["object"],
                "trial": int(r["trial"]),
                "picture": f"![{name}](gallery/{name}.png)",
                "log (open in Foxglove)": f"`{r['path']}`",
            }
        )
    md = ["# Failure gallery", ""]
    md.append(
        "Each picture: left, when the fingers have closed (or when the trial failed, if earlier); right, the "
        "end of the log. Blue: the object's collision shapes; grey: gripper boxes; brown: the support top; "
        "red / green / blue lines: the planned grasp frame's X (main axis), Y (closing) and Z (approach)."
    )
    md.append("")
    md.append(markdown(pd.DataFrame(rows), index=False) if rows else "No failed trials.")
    if skipped:
        md += ["", "Logs that could not be read:", "", *skipped]
    text = "\n".join(md) + "\n"
    out.mkdir(parents=True, exist_ok=True)
    (out / "gallery.md").write_text(text)
    return text
