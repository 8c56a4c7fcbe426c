"""Pose registration from the simulated depth camera, per paper Table 1 and Table 2 object: accuracy from a
prior 10 mm / 10 deg off (as a learned estimator's output) and the cost of depth frame + registration per
plan.

Usage::

    GRASPEXP_DATA=/path/to/datasets python -m graspexp bench.registration [--poses 10] [--prior-mm 10]
        [--prior-deg 10] [dataset=ycb,linemod] [key=value ...]

Each object at ``--poses`` seeded random orientations on the support, seen by ``perception.camera``
(default the d435 preset) with its noise model; ICP from a prior drawn as ``perception.noise`` draws
(Gaussian std ``--prior-mm`` / ``--prior-deg``), or global registration with
``perception.registration.prior=none``. Per object: median ADD-S, the share of registrations under 1 cm
ADD-S (the usual YCB-Video threshold), median translation and rotation errors and fitness. Then over every
registration: p50 and p95 of the depth frame (ray cast, noise, cloud, the target's normals), of the
registration and of both, CPU time of the process (all threads) beside wall time, ms, against the target
of p50 <= 40 ms CPU.
BLAS/OpenMP run on one thread (``OMP_NUM_THREADS=1`` set before numpy loads, and threadpoolctl).
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

from collections.abc import Sequence  # noqa: E402

from omegaconf import OmegaConf  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

from graspexp.datasets import available_objects, job_object  # noqa: E402
from graspexp.report.paper import PAPER_TABLES  # noqa: E402
from graspexp.run.bench.registration import registration_report  # noqa: E402
from graspexp.tools.cli import compose_checked, positive_int, take_sweep, tool_parser  # noqa: E402

PROG = "graspexp bench.registration"


def main(argv: Sequence[str] | None = None) -> int:
    parser = tool_parser(PROG, __doc__.split("\n")[0], overrides=True)
    parser.add_argument("--poses", type=positive_int, default=10, help="registrations per object (10)")
    parser.add_argument("--prior-mm", type=float, default=10.0, help="prior translation std, mm (10)")
    parser.add_argument("--prior-deg", type=float, default=10.0, help="prior rotation std, deg (10)")
    args = parser.parse_intermixed_args(argv)
    datasets, rest = take_sweep(args.overrides, "dataset", ["ycb", "linemod"])
    models, perception, seed = {}, None, 0
    for dataset in datasets:
        cfg = compose_checked([f"dataset={dataset}", "perception.source=depth", *rest], PROG)
        table = PAPER_TABLES.get(dataset)
        names = list(cfg.objects) if cfg.objects else available_objects(cfg.dataset)
        if table is not None and not cfg.objects:
            names = [n for n in table.labels if n in names]
        models[dataset] = [job_object(cfg, name) for name in names]
        perception, seed = OmegaConf.to_object(cfg).perception, int(cfg.seed)
    with threadpool_limits(limits=1):
        print(registration_report(perception, models, args.poses, seed, args.prior_mm, args.prior_deg))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
