"""Show an object's grasping area: a four-view figure, its share and extents, and a sidecar template.

Usage::

    python -m graspexp.area dataset=ycb --object 025_mug [--out DIR] [--write-sidecar PATH [--force]]
    python -m graspexp area dataset=primitives --object mug [planner=optimal_plus] [seed=3]
    python -m graspexp.area dataset=folder dataset.root=DIR --object NAME --write-sidecar DIR/NAME.yaml

``key=value`` arguments are Hydra overrides of ``conf/config.yaml``; the object is loaded as every trial of
that job sees it (:func:`graspexp.datasets.job_object`: ``planner.n_points`` surface samples, the job's
cloud seed, the area of ``dataset.regions``).

- Writes ``<out>/area_<dataset>_<object>.png`` (``--out``, default ``outputs/area``): the mesh from the
  front (-y, x-z plane), the side (+x, y-z plane), the top (+z, x-y plane) and an iso view, shaded grey,
  with the faces whose nearest surface sample (on the same side) is in the grasping area in red; axes in
  mm, object frame.
- Prints one fact a line: the samples in the area, the area's share of the samples
  (``area_mask.mean()``) and of the surface area, the axis-aligned extents of the object (mesh bounds)
  and of the area (its samples), object frame, mm, and the mass.
- ``--write-sidecar PATH`` writes a commented YAML template of a folder-dataset sidecar (``units``,
  ``mass_kg``, ``area``, ``friction``) filled in with the object's values, to edit; an existing file is
  kept unless ``--force``.

A bad override, an unknown object or missing data prints one ``graspexp area: error:`` line on stderr and
exits with status 2. ``python -m graspexp.area`` is an alias of ``python -m graspexp area``.
"""

import sys
import time
from collections.abc import Sequence
from pathlib import Path

from graspexp.datasets import DatasetError, job_object
from graspexp.report.area_view import draw_area, render_mesh, sidecar_template, summary
from graspexp.tools.cli import compose_checked, fail, tool_parser

PROG = "graspexp area"


def main(argv: Sequence[str] | None = None) -> int:
    """CLI entry; returns the exit status."""
    parser = tool_parser(PROG, __doc__, overrides=True)
    parser.add_argument("--object", required=True, metavar="NAME", help="the object, e.g. 025_mug")
    parser.add_argument(
        "--out", default="outputs/area", metavar="DIR", help="folder of the PNG (default: %(default)s)"
    )
    parser.add_argument("--write-sidecar", metavar="PATH", help="write a sidecar YAML template there")
    parser.add_argument("--force", action="store_true", help="overwrite an existing --write-sidecar file")
    args = parser.parse_intermixed_args(argv)
    sidecar = Path(args.write_sidecar) if args.write_sidecar else None
    if sidecar and sidecar.exists() and not args.force:
        fail(f"{sidecar} exists; add --force to overwrite it", PROG)
    cfg = compose_checked(args.overrides, PROG)
    try:
        model = job_object(cfg, args.object)
        template = sidecar_template(model, cfg) if sidecar else ""
    except DatasetError as err:
        fail(str(err), PROG)
    start = time.perf_counter()
    mesh, in_area = render_mesh(model)
    try:
        png = draw_area(model, mesh, in_area, Path(args.out) / f"area_{model.dataset}_{model.name}.png")
        if sidecar:
            sidecar.parent.mkdir(parents=True, exist_ok=True)
            sidecar.write_text(template)
    except OSError as err:
        fail(f"{err.strerror or err}: {err.filename}" if err.filename else str(err), PROG)
    print("\n".join(summary(model, mesh, in_area)))
    print(f"figure: {png} (rendered in {time.perf_counter() - start:.1f} s)")
    if sidecar:
        print(f"sidecar: {sidecar}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
