"""Every job matrix graspexp runs, built from the one statement of the paper's settings
(:mod:`graspexp.report.paper`): the paper suite (its four settings x Tables 1 and 2 x 10 trials), the
readings (each way to read the paper, the other planners, optimal_plus's ablations) and the benchmark's
standard suite (every planner x dataset x setting x pose-noise level), as Hydra multirun overrides or
job lists. The tools and ``nox`` sessions launch them with Hydra (``python -m graspexp -m ...``)."""

import sys
from dataclasses import dataclass
from pathlib import Path

from graspexp.report.paper import PAPER_TABLES, SETTINGS, TRIALS_PER_SETTING
from graspexp.run.multirun import multirun_command


def sweep_values(key: str, values: tuple[str, ...] | list[str]) -> str:
    """``key=a,b`` (one override sweeping ``values`` in order, duplicates dropped)."""
    return f"{key}={','.join(dict.fromkeys(values))}"


PAPER_MODES: tuple[str, ...] = tuple(dict.fromkeys(m for m, _ in SETTINGS))
"""The paper's modes in its column order: collab, bin."""
PAPER_ROTS: tuple[str, ...] = tuple(dict.fromkeys(r for _, r in SETTINGS))
"""The paper's drop rotations in its column order: z, xyz."""
SETTINGS_SWEEP: tuple[str, ...] = (
    sweep_values("mode", PAPER_MODES),
    sweep_values("rot", PAPER_ROTS),
)
"""The paper's four settings (IV-C, IV-D) as multirun overrides: ``mode=collab,bin rot=z,xyz``."""
PAPER_DATASETS: tuple[str, ...] = tuple(PAPER_TABLES)
"""The datasets of the paper's Tables 1 and 2, in table order."""
PAPER_PLANNERS: tuple[str, ...] = ("optimal", "optimal_in_area")
"""The paper's method as this project reads it, and beside it the same with the area rule on the pads."""


def paper_suite(trials: int = TRIALS_PER_SETTING, planners: tuple[str, ...] = PAPER_PLANNERS) -> list[str]:
    """Multirun overrides of the paper suite: its settings x Tables 1 and 2 x ``trials`` x ``planners``."""
    return [
        *SETTINGS_SWEEP,
        sweep_values("dataset", PAPER_DATASETS),
        sweep_values("planner", planners),
        f"trials={trials}",
    ]


@dataclass(frozen=True)
class Reading:
    """One way to read the paper (or another planner): a name, Hydra overrides and what it changes."""

    name: str
    overrides: tuple[str, ...]
    what: str


READINGS: tuple[Reading, ...] = (
    Reading(
        "default",
        ("planner=optimal",),
        "the paper's method as this project reads it (conf/planner/optimal.yaml)",
    ),
    Reading(
        "in_area",
        ("planner=optimal_in_area",),
        "optimal_in_area: every pad contact in the grasping area, object axis",
    ),
    Reading(
        "literal", ("planner=optimal_literal",), "the paper as printed (conf/planner/optimal_literal.yaml)"
    ),
    Reading(
        "k_half_stroke",
        ("planner=optimal", "planner.auto_k_stroke_fraction=0.5"),
        "K = ceil(L / (0.5 stroke)): clusters half a stroke long",
    ),
    Reading("k_1", ("planner=optimal", "planner.k=1"), "K = 1: one cluster, the whole area"),
    Reading("r_rms", ("planner=optimal", "planner.cluster_radius=rms"), "r_k = RMS distance from c_k"),
    Reading(
        "grasp_at_c_k", ("planner=optimal", "planner.grasp_point=centre"), "grasp point at c_k, no shift"
    ),
    Reading(
        "no_section_fit", ("planner=optimal", "planner.section_fit=false"), "least cost wins, no section test"
    ),
    Reading(
        "no_swept_check",
        ("planner=optimal", "planner.swept_check=false"),
        "no swept check: fingers and palm may meet the object or the table",
    ),
    Reading(
        "area_rule",
        ("planner=optimal", "planner.min_contacts_in_area=1"),
        "area rule: every pad contact point in the grasping area (not in the paper)",
    ),
    Reading(
        "bin_fallback",
        ("planner=optimal", "planner.min_contacts_in_area=1", "planner.fallback_contacts_in_area=0"),
        "area rule, and in bin the grasp touching the area most when none is inside it",
    ),
    Reading("no_margin", ("planner=optimal", "planner.width_margin=0"), "opening = 2 r_k exactly"),
    Reading(
        "pose_axis_object",
        ("planner=optimal", "planner.pose_axis=object"),
        "grasp X = the object's main axis, every object",
    ),
    Reading(
        "pose_axis_area",
        ("planner=optimal", "planner.pose_axis=area"),
        "grasp X = the area's main axis, every object (as printed)",
    ),
    Reading(
        "alpha_axis_area", ("planner=optimal", "planner.main_axis=area"), "alpha and K from the area's axis"
    ),
    Reading(
        "tcp_25mm",
        ("planner=optimal", "gripper.tcp_from_tip_m=0.025"),
        "grasp point 25 mm behind the fingertips",
    ),
)
"""The readings table's rows: the literal reading, the default, and each single change from the default."""

PLANNERS: tuple[Reading, ...] = (
    Reading("optimal_plus", ("planner=optimal_plus",), "the paper's candidates with collision checks"),
    Reading("antipodal", ("planner=antipodal",), "GPD-style antipodal sampling, whole object"),
    Reading(
        "antipodal_area",
        ("planner=antipodal_area",),
        "antipodal sampling inside the grasping area",
    ),
    Reading(
        "antipodal_area_pads",
        ("planner=antipodal_area_pads",),
        "antipodal sampling held to optimal_plus's area rule: every pad contact in the area",
    ),
    Reading("obb", ("planner=obb",), "top-down across the bounding box's short side"),
)
"""Other planners on the same drops: with the readings they give each object's best success (ceiling)."""

NOISE = ("perception.noise.trans_mm=3", "perception.noise.rot_deg=2")
"""The pose noise the robustness rows add: 3 mm / 2 degrees std-dev, what optimal_plus assumes."""
PLUS = ("planner=optimal_plus", "record=false")
ABLATIONS: tuple[Reading, ...] = (
    Reading("plus", PLUS, "optimal_plus as configured (the rows below change one thing)"),
    Reading(
        "plus_opening_cluster", (*PLUS, "planner.opening=cluster"), "optimal_plus, opening >= 2 r_k (1.2)"
    ),
    Reading(
        "plus_k_stroke", (*PLUS, "planner.cluster_length=stroke"), "optimal_plus, clusters one stroke long"
    ),
    Reading("plus_no_roll", (*PLUS, "planner.rolls_deg=[0.0]"), "optimal_plus, only the paper's roll"),
    Reading(
        "plus_no_depth_search",
        (*PLUS, "planner.depth_offsets_m=[0.0]"),
        "optimal_plus, grasp point at c_k depth",
    ),
    Reading(
        "plus_min_depth_10mm", (*PLUS, "planner.min_pad_depth_m=0.01"), "optimal_plus, pad depth >= 10 mm"
    ),
    Reading(
        "plus_no_min_depth",
        (*PLUS, "planner.min_pad_depth_m=-0.5"),
        "optimal_plus without the pad-depth test",
    ),
    Reading(
        "plus_no_cone", (*PLUS, "planner.friction_coef=10"), "optimal_plus without the friction-cone test"
    ),
    Reading(
        "plus_any_area",
        (*PLUS, "planner.min_contacts_in_area=0"),
        "optimal_plus, pads may touch outside the area",
    ),
    Reading(
        "plus_no_fallback",
        (*PLUS, "planner.fallback_contacts_in_area=1.0"),
        "optimal_plus, no area fallback (every contact in the area)",
    ),
    Reading(
        "plus_fallback_collab",
        (*PLUS, "planner.fallback_modes=[collab,bin]"),
        "optimal_plus, the area fallback in collab mode too",
    ),
    Reading(
        "plus_choose_cost",
        (*PLUS, "planner.choose_by=cost"),
        "optimal_plus, the paper's cost picks the grasp (no edge clearance)",
    ),
    Reading(
        "plus_no_arm_settle",
        (*PLUS, "sim.approach_settle_s=0"),
        "optimal_plus, fingers close as the approach ends (no arm settle)",
    ),
    Reading("plus_n2048", (*PLUS, "planner.n_points=2048"), "optimal_plus with a 2048-point cloud"),
    Reading("plus_no_com", (*PLUS, "planner.com_weight=0"), "optimal_plus without the gravity-arm factor"),
    Reading(
        "plus_no_noise_check", (*PLUS, "planner.noise_samples=0"), "optimal_plus without the pose-noise check"
    ),
    Reading("plus_noise", (*PLUS, *NOISE), "optimal_plus, perception noise 3 mm / 2 deg"),
    Reading(
        "plus_noise_no_check", (*PLUS, *NOISE, "planner.noise_samples=0"), "same noise, no pose-noise check"
    ),
    Reading(
        "default_noise", ("planner=optimal", "record=false", *NOISE), "optimal, perception noise 3 mm / 2 deg"
    ),
)
"""optimal_plus with each of its added terms switched off (or changed) on its own, and under pose noise."""

ALL: dict[str, Reading] = {r.name: r for r in (*READINGS, *PLANNERS, *ABLATIONS)}


def reading_sweep(
    reading: Reading,
    out: Path,
    overrides: tuple[str, ...] | list[str] = (),
    sweep_dir: Path | None = None,
) -> list[str]:
    """The multirun that runs one reading on the paper's four settings into ``out/<name>`` (or
    ``sweep_dir``): Tables 1 and 2 at the paper's trial count with the joblib launcher, unless the
    reading's overrides or ``overrides`` give ``dataset=``, ``trials=`` or ``hydra/launcher=`` (any other
    override goes to every job too; ``overrides`` come last and win)."""
    given = {o.split("=", 1)[0] for o in (*reading.overrides, *overrides)}
    defaults = [
        o
        for o in (sweep_values("dataset", PAPER_DATASETS), f"trials={TRIALS_PER_SETTING}")
        if o.split("=", 1)[0] not in given
    ]
    return multirun_command(
        sweep_dir if sweep_dir is not None else out / reading.name,
        [*SETTINGS_SWEEP, *defaults, "progress=false", *reading.overrides, *overrides],
        **({"launcher": ()} if "hydra/launcher" in given else {}),
    )


NOISE_LEVELS: tuple[tuple[float, float], ...] = ((10.0, 0.0), (20.0, 0.0), (0.0, 10.0))
"""Pose-noise levels (translation std mm, rotation std degrees) run besides zero, as in ``nox -s compare``."""


@dataclass(frozen=True)
class Job:
    """One job of the benchmark suite: its planner, dataset, setting and noise level, its overrides and
    the directory it runs into."""

    planner: str
    dataset: str
    mode: str
    rot: str
    trans_mm: float
    rot_deg: float
    overrides: tuple[str, ...]
    run_dir: str


def benchmark_suite(
    planners: list[str],
    datasets: list[str],
    settings: list[str],
    levels: list[tuple[float, float]],
    trials: int,
    objects: list[str] | None,
    overrides: list[str],
    out: Path,
) -> list[Job]:
    """The benchmark's job matrix: every planner (the first is the entered one) x dataset x ``mode/rot``
    setting x pose-noise level (mm, degrees; zero first, then ``levels``), each into
    ``out/<planner>/runs/<dataset>/<mode>_<rot>_t<mm>_r<deg>``. ``planner.*`` overrides go to the first
    planner only, the others to every job."""
    shared = [o for o in overrides if not o.lstrip("+~").startswith("planner.")]
    own = [o for o in overrides if o.lstrip("+~").startswith("planner.")]
    levels = [(0.0, 0.0)] + [(t, r) for t, r in levels if (t, r) != (0, 0)]
    subset = [f"objects=[{','.join(objects)}]"] if objects else []
    jobs = []
    for planner in planners:
        for dataset in datasets:
            for setting in settings:
                mode, rot = setting.split("/")
                for t, r in levels:
                    job_overrides = (
                        f"planner={planner}",
                        f"dataset={dataset}",
                        f"mode={mode}",
                        f"rot={rot}",
                        f"perception.noise.trans_mm={t}",
                        f"perception.noise.rot_deg={r}",
                        f"trials={trials}",
                        "progress=false",
                        *subset,
                        *shared,
                        *(own if planner == planners[0] else []),
                    )
                    run_dir = out / planner / "runs" / dataset / f"{mode}_{rot}_t{t:g}_r{r:g}"
                    jobs.append(Job(planner, dataset, mode, rot, t, r, job_overrides, str(run_dir)))
    return jobs


if __name__ == "__main__":  # the paper suite's overrides, for scripts: python -m graspexp.run.suites [TRIALS]
    print(" ".join(paper_suite(int(sys.argv[1]) if len(sys.argv) > 1 else TRIALS_PER_SETTING)))
