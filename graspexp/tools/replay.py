"""Print a trial log as a readable timeline: ``python -m graspexp replay FILE.mcap [--resim]``.

Header (object, mode, rot, seed, planner), one line per phase with its sim time, the finger forces per
phase (min / median / max of the summed contact force magnitude between ``object`` and each finger per
contacts message), and the outcome. Exit status: 0 normally; 2 with one ``error: ...`` line on stderr for
a corrupt, truncated or unreadable file. ``--resim`` re-simulates the trial with
``graspexp.run.resim.resimulate`` and exits 0 if it agrees with the log, 1 otherwise.
"""

import json
import math
import sys
from collections.abc import Sequence

import numpy as np

from graspexp.config import ConfigError, PluginError
from graspexp.core.bodies import FINGER_NAMES, OBJECT_NAME
from graspexp.datasets import DatasetError
from graspexp.record.reader import CorruptLogError, TrialLog, read_trial
from graspexp.tools.cli import tool_parser

HEADER_KEYS = ("object", "mode", "rot", "seed", "planner", "trial", "dataset")
"""Header fields, taken from the metadata record, else from the result."""


def logged_finger_forces(log: TrialLog) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Per contacts message: times (T,) s and, per finger, the summed force magnitude (T,) N on the object."""
    times = np.array([t for t, _ in log.contacts], dtype=float)
    forces = {f: np.zeros(len(times)) for f in FINGER_NAMES}
    for i, (_, contacts) in enumerate(log.contacts):
        for c in contacts:
            pair = {c["body0"], c["body1"]}
            for finger in FINGER_NAMES:
                if pair == {OBJECT_NAME, finger}:
                    forces[finger][i] += float(np.linalg.norm(np.asarray(c["force_n"], dtype=float)))
    return times, forces


def _fmt_info(info: dict | None, limit: int = 90) -> str:
    if not info:
        return ""
    text = json.dumps(info, separators=(", ", "="), default=str)[1:-1].replace('"', "")
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _fmt_num(v: object, unit: str = "") -> str:
    if isinstance(v, float):
        return "nan" if math.isnan(v) else f"{v:.4g}{unit}"
    return f"{v}{unit}"


def format_timeline(log: TrialLog) -> str:
    """The timeline text printed by the CLI."""
    res = log.result or {}
    lines = [f"trial log {log.path}"]
    header = []
    for key in HEADER_KEYS:
        value = log.metadata.get(key, res.get(key))
        if value is not None:
            header.append(f"{key}={value}")
    lines.append("  " + "  ".join(header))
    lines.append(f"  {log.message_count} messages on {', '.join(sorted(log.topics))}")

    times, forces = logged_finger_forces(log)
    phases = log.phases
    lines.append("phases (sim time, s):")
    if not phases:
        lines.append("  (no phase messages)")
    for i, (t0, name, info) in enumerate(phases):
        t1 = phases[i + 1][0] if i + 1 < len(phases) else math.inf
        lines.append(f"  {t0:8.3f}  {name:<15s}{_fmt_info(info)}".rstrip())
        in_phase = (times >= t0) & (times < t1)
        if any(forces[finger][in_phase].any() for finger in FINGER_NAMES):
            parts = []
            for finger in FINGER_NAMES:
                f = forces[finger][in_phase]
                parts.append(f"{finger} {f.min():.3g}/{np.median(f):.3g}/{f.max():.3g}")
            lines.append(f"  {'':8s}  {'':15s}finger force N min/med/max: " + "; ".join(parts))

    if log.grasp is not None:
        g = log.grasp
        lines.append(
            f"grasp: planner={g.get('planner')} cost={_fmt_num(g.get('cost'))} "
            f"width={_fmt_num(g.get('width_m'), ' m')} cluster={g.get('cluster')} path={g.get('path')} "
            f"K={g.get('K')} M={g.get('M')} n_feasible={g.get('n_feasible')}"
        )
    if log.round_result is not None:
        rr = log.round_result
        lines.append(
            f"round: {rr['end']}, removed {len(rr['removed'])} of {len(rr['placed'])} placed "
            f"({' '.join(rr['drawn'])} drawn)"
        )
        for a in rr["attempts"]:
            status = "ok" if a["success"] else a["reason"]
            lines.append(f"  attempt {a['attempt']}: {a['target']} (object_{a['slot']}) {status}")
    elif log.result is None:
        lines.append("outcome: (no result)")
    else:
        status = "SUCCESS" if res.get("success") else f"FAILED ({res.get('reason')})"
        lines.append(f"outcome: {status}")
        details = [
            f"slip={_fmt_num(res.get('slip_m'), ' m')}",
            "finger_force_n=[" + ", ".join(_fmt_num(v) for v in res.get("finger_force_n", [])) + "]",
            f"redrops={res.get('redrops')}",
            f"sim_time={_fmt_num(res.get('sim_time_s'), ' s')}",
            f"steps={res.get('steps')}",
        ]
        lines.append("  " + "  ".join(details))
        if res.get("error"):
            lines.append(f"  error: {res['error']}")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = tool_parser("graspexp replay", __doc__.split("\n")[0])
    parser.add_argument("file", help="trial log (.mcap)")
    parser.add_argument(
        "--resim", action="store_true", help="re-simulate the trial and check it agrees with the log"
    )
    args = parser.parse_args(argv)
    try:
        log = read_trial(args.file)
    except (CorruptLogError, OSError) as exc:
        msg = str(exc) if isinstance(exc, CorruptLogError) else f"{args.file}: {exc.strerror or exc}"
        print(f"{parser.prog}: error: {msg}", file=sys.stderr)
        return 2
    print(format_timeline(log))
    if args.resim:
        try:
            from graspexp.run.resim import resimulate
        except ImportError as exc:
            print(f"{parser.prog}: error: --resim needs graspexp.run.resim ({exc})", file=sys.stderr)
            return 2
        try:
            agrees, explanation = resimulate(log)
        except (DatasetError, PluginError, ConfigError) as exc:  # the log's mesh, planner or config
            print(f"{parser.prog}: error: cannot re-simulate {args.file}: {exc}", file=sys.stderr)
            return 2
        print(f"resim: {'agrees' if agrees else 'DISAGREES'}: {explanation}")
        return 0 if agrees else 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
