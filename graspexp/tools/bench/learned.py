"""Inference time per plan of the learned planners on Table 1's YCB objects, CPU only.

Usage::

    GRASPEXP_DATA=... GRASPEXP_CHECKPOINTS=... python -m graspexp bench.learned [--runs 10]
        [planner=vgn] [gripper=panda] [mode=bin] [objects=[...]] [key=value ...]

Without ``planner=``, every installed learned planner in turn (a plugin declaring
:attr:`graspexp.config.plugins.PlannerPlugin.learned`, e.g. ``vgn``), one block each; each runs with the
gripper it was trained for (:attr:`graspexp.config.plugins.Learned.gripper`) unless ``gripper=`` is given.

Each object stands upright on the support (:mod:`graspexp.run.upright`) and the simulated depth camera
renders it once (``perception.camera.*``, the trial's own rendering and noise,
:mod:`graspexp.perception.scene_view`, through :func:`graspexp.run.upright.upright_request`); then ``--runs`` plans on that observation are timed, on the wall clock and as CPU time of this process
(torch's threads included; ``planner.threads`` sets how many). One row per object: p50 and p95 of the whole
plan, and the p50 of its two steps as the planner logs them (``fuse``: the depth views into the TSDF;
``infer``: the network's forward pass). The first plan of the process (torch's import, the checkpoint's
hash check and load) is reported apart. Extra ``key=value`` arguments are Hydra overrides.
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import sys  # noqa: E402
import time  # noqa: E402
from collections.abc import Sequence  # noqa: E402

import numpy as np  # noqa: E402

from graspexp.config.plugins import learned_planners  # noqa: E402
from graspexp.datasets import DatasetError, job_object, select_objects  # noqa: E402
from graspexp.planning import NoFeasibleGrasp, PlanRequest, plan  # noqa: E402
from graspexp.run.upright import upright_request  # noqa: E402
from graspexp.tools.cli import compose_checked, fail, tool_parser  # noqa: E402

PROG = "graspexp bench.learned"
DEFAULTS = ("dataset=ycb", "mode=bin")
"""The bench's job unless overridden: Table 1's objects, bin picking."""


def bench_jobs(overrides: Sequence[str]) -> list[list[str]]:
    """The overrides of each planner benched: the ``planner=`` of ``overrides``, else every learned planner
    (:func:`graspexp.config.plugins.learned_planners`, in name order); a learned planner with the gripper it
    was trained for, each on :data:`DEFAULTS`, unless ``overrides`` set them (they come last)."""
    given = {o.split("=")[0] for o in overrides}
    learned = learned_planners()
    named = [o.split("=", 1)[1] for o in overrides if o.split("=")[0] == "planner"]
    jobs = []
    for name in named[-1:] or list(learned):
        gripper = (f"gripper={learned[name].gripper}",) if name in learned else ()
        defaults = (f"planner={name}", *gripper, *DEFAULTS)
        jobs.append([d for d in defaults if d.split("=")[0] not in given] + list(overrides))
    return jobs


def time_plans(req: PlanRequest, runs: int) -> dict[str, np.ndarray]:
    """Per run (``runs``,) seconds: ``wall`` and ``cpu`` (process time) of the whole plan, and the
    planner's own ``fuse_cpu_s`` and ``infer_cpu_s``; NaN rows where it found no grasp."""
    out = {k: np.full(runs, np.nan) for k in ("wall", "cpu", "fuse_cpu_s", "infer_cpu_s")}
    for i in range(runs):
        w0, c0 = time.perf_counter(), time.process_time()
        try:
            extras = plan(req).grasp.extras
        except NoFeasibleGrasp:
            extras = {}
        out["cpu"][i], out["wall"][i] = time.process_time() - c0, time.perf_counter() - w0
        out["fuse_cpu_s"][i] = extras.get("fuse_cpu_s", np.nan)
        out["infer_cpu_s"][i] = extras.get("infer_cpu_s", np.nan)
    return out


def _percentiles_ms(seconds: np.ndarray) -> np.ndarray:
    """(p50, p95) of ``seconds`` in ms, NaN when every value is NaN (no grasp: the steps are not logged)."""
    finite = seconds[np.isfinite(seconds)]
    return np.percentile(finite, [50, 95]) * 1e3 if len(finite) else np.full(2, np.nan)


def main(argv: Sequence[str] | None = None) -> int:
    parser = tool_parser(PROG, __doc__.split("\n")[0], overrides=True)
    parser.add_argument("--runs", type=int, default=10, help="timed plans per object")
    args = parser.parse_intermixed_args(argv)
    jobs = bench_jobs(args.overrides)
    if not jobs:
        fail("no learned planner is installed (a plugin declaring learned); name one with planner=NAME", PROG)
    for i, overrides in enumerate(jobs):
        if i:
            print()
        bench(overrides, args.runs, first=i == 0)
    return 0


def bench(overrides: list[str], runs: int, first: bool = True) -> None:
    """Time ``runs`` plans per object of the job ``overrides`` and print the table; ``first``: the first
    planner of this process (its first plan pays torch's import)."""
    cfg = compose_checked(overrides, PROG)
    names = select_objects(cfg.dataset, cfg.objects)
    try:
        requests = [(name, upright_request(cfg, job_object(cfg, name))) for name in names]
    except DatasetError as err:
        fail(str(err), PROG)
    w0, c0 = time.perf_counter(), time.process_time()
    try:
        plan(requests[0][1])
    except NoFeasibleGrasp:
        pass
    first_wall, first_cpu = time.perf_counter() - w0, time.process_time() - c0
    views = len(requests[0][1].observation.views)
    what = (
        "first plan of this process (imports, checkpoint hash and load)"
        if first
        else "first plan of this planner (its imports, checkpoint hash and load)"
    )
    print(
        f"{PROG}: planner={cfg.planner.name}, gripper={cfg.gripper.name}, mode={cfg.mode.name}, camera "
        f"{cfg.perception.camera.name} ({views} view(s), {cfg.perception.camera.width_px} x "
        f"{cfg.perception.camera.height_px} px), planner.threads={cfg.planner.threads}, {runs} plans per "
        f"object\n{what}: {first_wall:.2f} s wall, {first_cpu:.2f} s CPU"
    )
    print(
        f"{'object':<26}{'wall p50':>9}{'wall p95':>9}{'CPU p50':>9}{'CPU p95':>9}{'fuse':>7}{'infer':>7}  ms"
    )
    p50s = []
    for name, req in requests:
        t = time_plans(req, runs)
        ms = {k: _percentiles_ms(v) for k, v in t.items()}
        p50s.append([ms["wall"][0], ms["cpu"][0], ms["infer_cpu_s"][0]])
        steps = "   (no grasp: steps not logged)" if np.isnan(ms["infer_cpu_s"][0]) else ""
        print(
            f"{name:<26}{ms['wall'][0]:>9.0f}{ms['wall'][1]:>9.0f}{ms['cpu'][0]:>9.0f}{ms['cpu'][1]:>9.0f}"
            f"{ms['fuse_cpu_s'][0]:>7.0f}{ms['infer_cpu_s'][0]:>7.0f}{steps}"
        )
    wall, cpu, infer = np.nanmedian(np.asarray(p50s), axis=0)
    print(
        f"median over objects of the p50: wall {wall:.0f} ms, CPU {cpu:.0f} ms (forward pass {infer:.0f} ms CPU)"
    )


if __name__ == "__main__":
    sys.exit(main())
