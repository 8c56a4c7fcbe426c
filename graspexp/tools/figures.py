"""Figures of the planner's stages, in the manner of the paper's Figs. 3-9, 12 and 14.

Usage::

    python -m graspexp figures objects=[025_mug] [--out DIR] dataset=ycb [mode=bin]
    python -m graspexp figures --all [--out DIR] dataset=ycb

``key=value`` arguments are Hydra overrides, as for :mod:`graspexp.tools.plan` (the object is placed upright on
the support the same way, :mod:`graspexp.run.upright`). Per object, in ``--out`` (default
``outputs/figures/<dataset>/<object>/``):

- ``fig03_cloud.png``: the complete point cloud;
- ``fig04_area.png``: grasping area (red) and the rest (blue);
- ``fig05_clusters.png``: the K clusters in colours, centres as black-ringed dots;
- ``fig06_paths.png``: grasping paths of every cluster (one in ``PATH_STRIDE`` of the M drawn);
- ``fig07_main_axis.png``: the area's PCA main axis (red line);
- ``fig08_removed_paths.png``: the support plane (blue), kept paths (green), removed ones (grey, dashed);
- ``fig09_grasp_pose.png``: the chosen pose (X red, Y green, Z blue), its path and the finger opening.

``--all`` draws those for every available object of the dataset into ``<out>/<object>/`` (default
``outputs/figures/<dataset>/``) and an overview grid of the areas, ``areas_overview.png`` (Figs. 12, 14).
"""

import sys
from collections.abc import Sequence
from pathlib import Path

from graspexp.datasets import DatasetError, available_objects, job_object
from graspexp.planning import NoFeasibleGrasp, UnknownPlanner
from graspexp.report.figures import draw_object, draw_overview
from graspexp.run.upright import plan_upright
from graspexp.tools.cli import compose_checked, fail, tool_parser


def main(argv: Sequence[str] | None = None) -> int:
    """CLI entry; returns the exit status."""
    prog = "graspexp figures"
    parser = tool_parser(prog, __doc__.splitlines()[0], overrides=True)
    parser.add_argument(
        "--all",
        action="store_true",
        help="every available object (instead of objects=[...]) and the areas overview",
    )
    parser.add_argument(
        "--out", type=Path, help="output folder (default outputs/figures/<dataset>[/<object>])"
    )
    args = parser.parse_intermixed_args(argv)
    cfg = compose_checked(args.overrides, prog)
    base = args.out or Path("outputs") / "figures" / str(cfg.dataset.name)
    if bool(cfg.objects) == args.all:
        fail("name the objects to draw, objects=[NAME,...] (e.g. objects=[025_mug]), or --all", prog)
    if cfg.objects:
        for name in cfg.objects:
            try:
                planned = plan_upright(cfg, job_object(cfg, name))
            except (DatasetError, NoFeasibleGrasp, UnknownPlanner) as err:
                fail(f"{name}: {err}", prog)
            out = args.out if args.out and len(cfg.objects) == 1 else base / name
            for p in draw_object(name, planned.result, planned.request.gripper, out):
                print(p)
        return 0
    names = available_objects(cfg.dataset)
    if not names:
        fail(f"no object of dataset {cfg.dataset.name!r} is available under the data root", prog)
    done = []
    for name in names:
        try:
            item = plan_upright(cfg, job_object(cfg, name))
        except (DatasetError, NoFeasibleGrasp, UnknownPlanner) as err:
            print(f"warning: skipped {name}: {err}", file=sys.stderr)
            continue
        done.append((name, item.result))
        for p in draw_object(name, item.result, item.request.gripper, base / name):
            print(p)
    if done:
        print(draw_overview(done, base / "areas_overview.png", f"Grasping areas (red): {cfg.dataset.name}"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
