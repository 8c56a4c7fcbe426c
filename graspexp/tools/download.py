"""Fetch and verify the real object meshes (YCB google_16k, BOP LINEMOD) into the data root.

Usage::

    python -m graspexp download dataset=ycb [dataset.root=DIR] [objects=[025_mug,011_banana]] [--all]
    python -m graspexp download dataset=linemod [dataset.root=DIR] [--base-url URL] [--sha256 HEX]

``key=value`` arguments are Hydra overrides of ``conf/config.yaml`` (one of the downloadable datasets,
its root, the objects; default: the dataset's paper list); ``--all``: every object of its catalogue.
What is written where, and how each archive is verified: :mod:`graspexp.datasets.download`.
"""

import argparse
import sys
from collections.abc import Sequence

from graspexp.datasets.catalog import DATASETS, dataset_spec, resolve_root
from graspexp.datasets.download import LINEMOD_ARCHIVE, download_dataset
from graspexp.datasets.errors import DatasetError
from graspexp.tools.cli import compose_checked, tool_parser

PROG = "graspexp download"


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The command line: ``--`` options, and Hydra overrides composed into the job config
    (``dataset=``, ``dataset.root=``, ``objects=[...]``); ``root`` and ``objects`` are resolved."""
    parser = tool_parser(PROG, "Download and verify YCB (google_16k) or BOP LINEMOD object meshes.", True)
    parser.add_argument("--all", action="store_true", help="every object of the dataset's catalogue")
    parser.add_argument(
        "--base-url", default=None, help="base URL of the archives (default: env or official)"
    )
    parser.add_argument("--sha256", default=None, help="expected SHA-256 of lm_models.zip (mirrors)")
    args = parser.parse_intermixed_args(argv)
    cfg = compose_checked(args.overrides, PROG)
    args.dataset = str(cfg.dataset.name)
    if args.dataset not in DATASETS or not DATASETS[args.dataset].downloadable:
        valid = [n for n, spec in DATASETS.items() if spec.downloadable]
        parser.error(
            f"dataset={args.dataset} cannot be downloaded; give dataset= one of {', '.join(valid)} "
            "(a folder or BOP set of your own is read where it lies: dataset.root=DIR)"
        )
    args.root = resolve_root(cfg.dataset)
    args.progress = bool(cfg.progress)
    catalogue = dataset_spec(args.dataset).catalogue
    objects = list(catalogue) if args.all else list(cfg.objects or cfg.dataset.objects or [])
    args.objects_given = bool(objects)
    args.objects = objects or list(dataset_spec(args.dataset).default_objects)
    unknown = [n for n in args.objects if n not in catalogue]
    if unknown:
        parser.error(f"unknown {args.dataset} objects {unknown}; valid: {', '.join(catalogue)}")
    return args


def main(argv: Sequence[str] | None = None) -> int:
    """CLI entry point; returns the exit status (2 for a dataset error, with one message on stderr)."""
    args = parse_args(argv)
    try:
        paths, missing = download_dataset(
            args.dataset,
            args.root,
            args.objects,
            url=args.base_url,
            sha256=args.sha256,
            progress=args.progress,
        )
        if missing and args.objects_given:
            raise DatasetError(f"{LINEMOD_ARCHIVE} lacks the models of: {', '.join(missing)}")
        if missing:
            print(f"warning: {LINEMOD_ARCHIVE} lacks the models of: {', '.join(missing)}", file=sys.stderr)
    except DatasetError as err:
        print(f"{PROG}: error: {err}", file=sys.stderr)
        return 2
    print(f"{len(paths)} {args.dataset} model(s) ready under {args.root.resolve()}")
    print(f"use them with dataset={args.dataset} dataset.root={args.root} (or GRASPEXP_DATA={args.root})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
