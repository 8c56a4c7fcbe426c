"""Warm the collision-shape cache: every object's shape built once, in parallel, with progress.

Usage::

    python -m graspexp prepare dataset=ycb                 # the objects a run of this config would use
    python -m graspexp prepare --all dataset=linemod       # every catalogue object with a mesh on disk
    python -m graspexp prepare dataset=ycb objects=[025_mug] sim.collision_method=coacd

``key=value`` arguments are Hydra overrides of the job config (:func:`graspexp.run.prepare.prepare_shapes`).
"""

import logging
import sys
import time
from collections.abc import Sequence

from omegaconf import OmegaConf

from graspexp.datasets import DatasetError, select_objects
from graspexp.run.prepare import prepare_shapes, staged_objects
from graspexp.tools.cli import compose_checked, fail, tool_parser


def main(argv: Sequence[str] | None = None) -> int:
    """Exit status 0, 1 when some objects could not be prepared (each named on stderr), 2 for bad input."""
    prog = "graspexp prepare"
    parser = tool_parser(prog, __doc__.splitlines()[0], overrides=True)
    parser.add_argument("--all", action="store_true", help="every catalogue object with a mesh on disk")
    args = parser.parse_intermixed_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    cfg = compose_checked(args.overrides, prog)
    try:
        names = staged_objects(cfg.dataset) if args.all else select_objects(cfg.dataset, cfg.objects)
        sim = OmegaConf.to_object(cfg.sim)
        t0 = time.perf_counter()
        failed = prepare_shapes(cfg.dataset, sim, names)
    except DatasetError as err:
        fail(str(err), prog)
    ready = len(names) - len(failed)
    print(f"{ready} collision shapes of {cfg.dataset.name} ready in {time.perf_counter() - t0:.1f} s")
    for name, why in failed.items():
        print(f"{prog}: {name}: NOT prepared: {why}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
