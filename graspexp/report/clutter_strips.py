"""A picture strip of every failed attempt of the clutter rounds below a directory, drawn from the round
logs alone (no simulator, no meshes): the scene when the attempt was planned and when it ended, with the
planned grasp frame (X red, Y green, Z blue). An attempt that found no grasp (the round's last) is drawn
once, as the planner saw it, and one that ended before anything was planned (``not_at_rest``) once, when it
ended. Files are named
``<dataset>_<planner>_<mode>_r<round>_a<attempt>_<reason>.png``; ``clutter_failures.md`` lists them
beside the round log each came from, to open in Foxglove.
"""

from pathlib import Path

import numpy as np
import pandas as pd

from graspexp.record import CorruptLogError, TrialLog, read_trial
from graspexp.report.gallery import draw_instants, pose_at
from graspexp.report.render import markdown
from graspexp.report.round_tables import round_log_dirs

SCENE_HALF_M = 0.2
"""Half the side of the cube drawn around the attempt's grasp point (or its target), m: the 0.3 m
workspace and the neighbours around it."""


def round_logs(root: Path | str) -> list[Path]:
    """The finished round logs below ``root`` (``trials/<mode.name>/*.mcap`` of every clutter run directory,
    :func:`graspexp.report.round_tables.round_log_dirs`), sorted by path."""
    found = [p for d in round_log_dirs(root) for p in d.glob("*.mcap")]
    return sorted(p for p in found if p.is_file())  # an unfinished log is NNN.mcap.partial


def attempt_times(log: TrialLog) -> dict[int, tuple[float, float]]:
    """Attempt index -> (planned at, ended at), simulation s, from the round log's ``plan`` and
    ``attempt_end`` phases; an attempt that found no grasp ends where it was planned."""
    times: dict[int, list[float]] = {}
    for t_s, name, info in log.phases:
        attempt = (info or {}).get("attempt")
        if name == "plan" and attempt is not None:
            times[int(attempt)] = [t_s, t_s]
        elif name == "attempt_end" and attempt is not None and int(attempt) in times:
            times[int(attempt)][1] = t_s
    return {a: (t0, t1) for a, (t0, t1) in times.items()}


def _finite(value: object) -> bool:
    return isinstance(value, int | float) and bool(np.isfinite(value))


def _grasp_between(log: TrialLog, t0: float, t1: float) -> np.ndarray | None:
    """(4, 4) world pose of the last grasp logged in [t0, t1], None when none was."""
    poses = [g["pose"] for g in log.grasps if t0 <= g["t_s"] <= t1]
    return poses[-1] if poses else None


def _centre(log: TrialLog, grasp: np.ndarray | None, slot: int, t_s: float) -> np.ndarray:
    """The grasp point, else the target's origin at ``t_s``, else the world origin (3,) m."""
    if grasp is not None:
        return grasp[:3, 3]
    target = pose_at(log, f"object_{slot}", t_s)
    return target[:3, 3] if target is not None else np.zeros(3)


def draw_round_failures(log: TrialLog, out: Path) -> list[dict]:
    """Draw every failed attempt of one round log into ``out/`` (PNG); one index row per picture."""
    rr = log.round_result or {}
    times = attempt_times(log)
    rows = []
    for a in rr.get("attempts", []):
        planned = int(a["attempt"]) in times
        if a.get("success") or not (planned or _finite(a.get("sim_time_s"))):
            continue
        t0, t1 = times[int(a["attempt"])] if planned else (float(a["sim_time_s"]),) * 2
        grasp = _grasp_between(log, t0, t1) if planned else None
        reason = a.get("reason") or "(none)"
        name = f"{rr['dataset']}_{rr['planner']}_{rr['mode']}_r{int(rr['round']):03d}_a{int(a['attempt'])}_{reason}"
        if not planned:  # ended before anything was planned (a heap not at rest): the scene then
            instants = {"not planned": t0}
        else:
            instants = {"planned": t0, "ended": t1} if a.get("executed") else {"no grasp found": t0}
        title = (
            f"{rr['mode']} · {rr['planner']} · round {int(rr['round'])}, attempt {int(a['attempt'])}: "
            f"{a['target']} · {reason}"
        )
        draw_instants(
            log,
            instants,
            grasp,
            _centre(log, grasp, int(a["slot"]), t0),
            out / f"{name}.png",
            title,
            SCENE_HALF_M,
        )
        rows.append(
            {
                "round": int(rr["round"]),
                "attempt": int(a["attempt"]),
                "scene": f"{rr['dataset']} {rr['mode']} {rr['planner']}",
                "target": a["target"],
                "reason": reason,
                "picture": f"![{name}]({out.name}/{name}.png)",
                "log (open in Foxglove)": f"`{log.path}`",
            }
        )
    return rows


def write_clutter_strips(root: Path | str, out_dir: Path | str) -> str:
    """Draw the failed attempts of every round log below ``root`` into ``out_dir/clutter_failures/`` and
    return the Markdown index (also written to ``out_dir/clutter_failures.md``); a log that cannot be read
    is listed, not drawn. '' when no round log is below ``root`` (a ``record=false`` run)."""
    logs = round_logs(root)
    if not logs:
        return ""
    out = Path(out_dir)
    rows, skipped = [], []
    for path in logs:
        try:
            log = read_trial(path, require_result=False)
        except (CorruptLogError, OSError) as exc:
            skipped.append(f"- `{path}`: {exc}")
            continue
        rows += draw_round_failures(log, out / "clutter_failures")
    md = [
        "# Failed attempts in clutter",
        "",
        "Each strip: left, the scene when the attempt was planned; right, when it ended (an attempt that found "
        "no grasp, the round's last, is drawn once, and one that ended before anything was planned, when it ended). Blue: the objects' collision shapes; grey: gripper "
        "boxes; brown: the support top; red / green / blue lines: the planned grasp frame's X, Y (closing) "
        "and Z (approach).",
        "",
        markdown(pd.DataFrame(rows), index=False) if rows else "No failed attempts.",
    ]
    if skipped:
        md += ["", "Logs that could not be read:", "", *skipped]
    text = "\n".join(md) + "\n"
    out.mkdir(parents=True, exist_ok=True)
    (out / "clutter_failures.md").write_text(text)
    return text
