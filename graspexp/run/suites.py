"""Every job matrix graspexp runs, built from the one statement of the paper's settings
(:mod:`graspexp.report.paper`): the paper suite (its four settings x Tables 1 and 2 x 10 trials), the
readings (each way to read the paper, the other planners, optimal_plus's ablations), the benchmark's
standard suite (every planner x dataset x setting x pose-noise level), ``nox -s compare``'s matrix
(:data:`COMPARE_SUITE`) and the results pages' sweeps and fingerprint jobs (:class:`Sweep`; the pages,
:mod:`graspexp.run.result_pages`, say which they use and how they render them), as Hydra multirun overrides
or job lists. The learned planners' sweeps are built from their plugins
(:func:`graspexp.config.plugins.learned_planners`): a new learned planner joins them without an edit here.
The tools and ``nox`` sessions launch them with Hydra (``python -m graspexp -m ...``)::

    python -m graspexp.run.suites [TRIALS]    # the paper suite's overrides
    python -m graspexp.run.suites compare     # nox -s compare's
"""

import hashlib
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from graspexp.config.plugins import learned_planners
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


COMPARE_SUITE: tuple[str, ...] = (
    "planner=optimal,optimal_in_area,optimal_plus,antipodal,obb,random",
    "perception.noise.trans_mm=0,10,20",
    "perception.noise.rot_deg=0,10",
    "dataset=primitives",
    "objects=[can,mug,banana]",
    "mode=bin",
    "rot=z",
    "trials=3",
)
"""``nox -s compare``: six planners x pose noise on a small setting (primitives can/mug/banana, bin, rot z,
3 trials), as multirun overrides."""


# The results pages' sweeps and fingerprint jobs (graspexp.run.result_pages assembles the pages from them).


@dataclass(frozen=True)
class Sweep:
    """One sweep of a results page: a reading (name, overrides, what it is) and overrides beside it
    (``trials=30``, another dataset or object list), run on the paper's four settings."""

    reading: Reading
    extra: tuple[str, ...] = ()
    settings: bool = True
    """Run on the paper's four settings and both tables (:func:`reading_sweep`); False: the reading's
    overrides are the whole sweep (e.g. an Optuna study, ``hydra/sweeper=study``)."""

    @property
    def name(self) -> str:
        """The reading's name, and a hash of the extra overrides when there are any."""
        if not self.extra:
            return self.reading.name
        return f"{self.reading.name}-{hashlib.sha256(' '.join(self.extra).encode()).hexdigest()[:8]}"


FINGERPRINT_SETTINGS: tuple[tuple[str, str], ...] = (("collab", "z"), ("bin", "xyz"))
"""(mode, rot) of every fingerprint job: one setting of each mode, the turned drop in bin picking."""
FINGERPRINT_SUBSET: tuple[str, ...] = ("dataset=ycb", "objects=[025_mug,035_power_drill]", "trials=1")
"""The default fingerprint objects and trials: two Table 1 objects, one drop each per setting."""


def sweeps(names: Sequence[str], extra: tuple[str, ...] = ()) -> tuple[Sweep, ...]:
    """The sweeps of the readings ``names`` (of :data:`ALL`), each with ``extra``."""
    return tuple(Sweep(ALL[n], extra) for n in names)


DEFAULT = Sweep(ALL["default"])
ANTIPODAL = Sweep(ALL["antipodal"])
TABLES = sweeps(["default", "in_area", "literal"])
"""The index page: the paper's method as read here, the area rule, the paper as printed."""
READINGS_SWEEPS = sweeps([r.name for r in READINGS])
READINGS_FINGERPRINT = sweeps(
    ["default", "literal", "in_area", "pose_axis_area", "no_swept_check", "k_half_stroke", "tcp_25mm"]
)
COMPARED = sweeps(["optimal_plus", "default", "antipodal_area", "antipodal_area_pads", "antipodal", "obb"])
THIRTY = sweeps(["optimal_plus", "antipodal_area_pads"], ("trials=30", "record=false"))
GENERALISATION = sweeps(
    ["optimal_plus", "default", "antipodal_area", "antipodal_area_pads", "antipodal"],
    ("dataset=ycb", "dataset.split=test"),
)
GENERALISATION_FINGERPRINT = sweeps([s.reading.name for s in GENERALISATION], ("dataset=ycb",))
GENERALISATION_SUBSET = ("objects=[024_bowl,003_cracker_box]", "trials=1")
"""Two objects of the test split."""
ABLATION = tuple(Sweep(r, ("trials=5",)) for r in ABLATIONS)
ABLATION_FINGERPRINT = sweeps(["plus", "plus_choose_cost", "plus_noise", "default_noise"], ("trials=5",))

CAMERA_COMMON = ("dataset=ycb", "record=false")
"""Table 1's objects (10 trials, the paper's settings: :func:`reading_sweep`), no logs."""
REGISTERED = ("perception.source=depth", "perception.noise.trans_mm=10", "perception.noise.rot_deg=10")
"""The pose registered from the camera, ICP from a prior 10 mm / 10 deg (std) off the truth."""
ANTIPODAL_VIEW = Sweep(
    Reading(
        "antipodal_view",
        ("planner=antipodal_view", *CAMERA_COMMON),
        "antipodal sampling on the camera's cloud",
    )
)
REGISTERED_OPTIMAL = Sweep(
    Reading(
        "registered_optimal", ("planner=optimal", *REGISTERED, *CAMERA_COMMON), "optimal, registered pose"
    )
)
REGISTERED_PLUS = Sweep(
    Reading(
        "registered_optimal_plus",
        ("planner=optimal_plus", *REGISTERED, *CAMERA_COMMON),
        "optimal_plus, registered pose",
    )
)


def registration_job(dataset: str) -> list[str]:
    """The job of the camera page's registration measurement on ``dataset``'s objects: the pose registered
    from the camera."""
    return [f"dataset={dataset}", "perception.source=depth"]


PAPER_GRIPPER = "rg2"
"""The paper's gripper (the default ``gripper``): a learned planner trained for another runs on it as a
transfer."""


def learned_sweep(planner: str, gripper: str) -> Sweep:
    """The learned planner ``planner`` on Table 1 with ``gripper``: the gripper it was trained for, or the
    paper's (a transfer)."""
    trained = gripper == learned_planners()[planner].gripper
    what = "with the gripper it was trained for" if trained else "on the paper's gripper (a transfer)"
    return Sweep(
        Reading(
            f"{planner}_{gripper}",
            (f"planner={planner}", f"gripper={gripper}", *CAMERA_COMMON),
            f"{planner} {what}",
        )
    )


def learned_trained() -> tuple[Sweep, ...]:
    """Every learned planner (:func:`graspexp.config.plugins.learned_planners`) on Table 1 with the gripper
    it was trained for: the camera page's learned columns."""
    return tuple(learned_sweep(name, learned.gripper) for name, learned in learned_planners().items())


def learned_runs() -> dict[str, Sweep]:
    """The learned page's runs by label: every learned planner on the gripper it was trained for, then on
    the paper's (a transfer; not when it was trained for it)."""
    runs = {}
    for name, learned in learned_planners().items():
        runs[f"{name}, gripper={learned.gripper}"] = learned_sweep(name, learned.gripper)
        if learned.gripper != PAPER_GRIPPER:
            runs[f"{name}, gripper={PAPER_GRIPPER} (transfer)"] = learned_sweep(name, PAPER_GRIPPER)
    return runs


def camera_sweeps() -> tuple[Sweep, ...]:
    """Table 1 in one physics: the exact-pose and full-model columns are the readings' own sweeps (the same
    drops; their Table 2 trials are left out), the camera's columns run on Table 1 alone, the learned
    planners on the gripper each was trained for."""
    return (DEFAULT, REGISTERED_OPTIMAL, REGISTERED_PLUS, ANTIPODAL, ANTIPODAL_VIEW, *learned_trained())


def camera_fingerprint() -> tuple[Sweep, ...]:
    """The camera page's fingerprint sweeps."""
    return (DEFAULT, ANTIPODAL, REGISTERED_OPTIMAL, ANTIPODAL_VIEW, *learned_trained())


STUDY = (
    "hydra/sweeper=study",
    "mode=bin",
    "dataset=ycb",
    "dataset.split=train",
    "trials=10",
    "record=false",
    "cost.angle_weight=tag(log, interval(0.01, 1))",
    "cost.distance_numerator_mm2=tag(log, interval(2, 200))",
    "cost.distance_offset_mm2=tag(log, interval(0.1, 10))",
    "cost.table_beta_divisor=tag(log, interval(0.2, 20))",
    "cost.table_offset=tag(log, interval(0.005, 0.5))",
)
"""An Optuna study of Eq. (1)-(3)'s constants in bin picking on the training objects (docs/guide/tuning.md)."""
STUDY_Z = Sweep(
    Reading(
        "tuning_bin_z", (*STUDY, "rot=z", "hydra.sweeper.n_trials=60"), "the constants' study, bin, rot z"
    ),
    settings=False,
)
STUDY_XYZ = Sweep(
    Reading("tuning_bin_xyz", (*STUDY, "rot=xyz", "hydra.sweeper.n_trials=40"), "the same study, rot xyz"),
    settings=False,
)

CLUTTER_PLANNERS = ("optimal", "optimal_plus", "antipodal")
"""The planners of the clutter page: the paper's, this project's and antipodal sampling."""
CLUTTER = Sweep(
    Reading(
        "clutter",
        (
            "mode=pile,packed",
            f"planner={','.join(CLUTTER_PLANNERS)}",
            "dataset=ycb",
            "trials=100",
            "record=false",
        ),
        "clutter removal, pile and packed, 100 rounds of 5 objects from the staged YCB objects, exact poses",
    ),
    settings=False,
)
CLUTTER_FINGERPRINT = tuple(
    Sweep(Reading(f"clutter_{p}", (f"planner={p}",), f"{p} in one clutter round"), settings=False)
    for p in CLUTTER_PLANNERS
)
"""One round of each planner in each scene (:data:`CLUTTER_SETTINGS`): 5 objects drawn from the pool."""
CLUTTER_SETTINGS = (("pile", "z"), ("packed", "z"))
"""The fingerprint's scenes (the drop rotation is not read by the clutter modes)."""
CLUTTER_SUBSET = ("dataset=ycb", "trials=1")
"""The clutter fingerprint's pool and rounds: one round of the staged YCB objects."""

CLUTTER_CAMERA_ROUNDS = 50
"""Rounds per planner and scene of the camera clutter page: 50, not the exact-pose page's 100. Measured on the
shared 2-core machine (3-round runs, CPU per round, pile / packed): optimal 3.7 / 2.4 s, optimal_plus
4.6 / 2.6 s, antipodal_view 7.8 / 6.2 s, vgn about 2 s: about 37 s per round of all eight rows, an hour of
CPU for 100 rounds."""
CLUTTER_CAMERA_COMMON = (
    "mode=pile,packed",
    *REGISTERED,
    "dataset=ycb",
    f"trials={CLUTTER_CAMERA_ROUNDS}",
    "record=false",
)
"""Clutter removal with every pose registered from the camera (the default D435 preset) from a prior 10 mm /
10 deg (std) off the truth; the staged YCB objects as the pool."""
CLUTTER_CAMERA_PLANNERS = ("optimal", "optimal_plus", "antipodal_view")
"""The camera clutter page's planners on the RG2: the paper's and this project's on registered poses,
antipodal sampling on the camera's cloud."""
VGN_THRESHOLD_EXPERIMENT = "planner.quality_threshold=0.8"
"""A non-default setting of the camera clutter page's sensitivity row (VGN's own threshold is 0.9)."""
CLUTTER_CAMERA_EXPERIMENTS: tuple[tuple[str, str, Sweep], ...] = (
    (
        "vgn",
        "vgn, gripper=panda, quality_threshold=0.8 (experiment)",
        Sweep(
            Reading(
                "clutter_camera_vgn_q08",
                (*CLUTTER_CAMERA_COMMON, "planner=vgn", "gripper=panda", VGN_THRESHOLD_EXPERIMENT),
                "vgn with a lower quality threshold than its authors' (a sensitivity experiment)",
            ),
            settings=False,
        ),
    ),
)
"""Experiments of a learned planner on the camera clutter page (planner, row label, sweep), run where that
planner is installed, after every learned planner's own row."""


def clutter_camera_runs() -> dict[str, Sweep]:
    """The camera clutter page's sweeps by the label of their rows ('': each row named by its planner):
    the planners of :data:`CLUTTER_CAMERA_PLANNERS`, every learned planner on the gripper it was trained for
    (:func:`graspexp.config.plugins.learned_planners`), then :data:`CLUTTER_CAMERA_EXPERIMENTS`."""
    learned = learned_planners()
    runs = {
        "": Sweep(
            Reading(
                "clutter_camera",
                (*CLUTTER_CAMERA_COMMON, f"planner={','.join(CLUTTER_CAMERA_PLANNERS)}"),
                "clutter removal with the camera: registered poses, antipodal sampling on the cloud",
            ),
            settings=False,
        )
    }
    for name, spec in learned.items():
        runs[f"{name}, gripper={spec.gripper} (trained for it)"] = Sweep(
            Reading(
                f"clutter_camera_{name}",
                (*CLUTTER_CAMERA_COMMON, f"planner={name}", f"gripper={spec.gripper}"),
                f"{name} in clutter removal with the gripper it was trained for",
            ),
            settings=False,
        )
    runs |= {label: sweep for planner, label, sweep in CLUTTER_CAMERA_EXPERIMENTS if planner in learned}
    return runs


def clutter_camera_fingerprint() -> tuple[Sweep, ...]:
    """One round of each planner of the camera clutter page in each scene (:data:`CLUTTER_SETTINGS`), poses
    registered from the camera, each learned planner on the gripper it was trained for."""
    planners = (
        *((p, ()) for p in CLUTTER_CAMERA_PLANNERS),
        *((name, (f"gripper={spec.gripper}",)) for name, spec in learned_planners().items()),
    )
    return tuple(
        Sweep(
            Reading(
                f"clutter_camera_{p}", (*REGISTERED, *extra, f"planner={p}"), f"{p} in one clutter round"
            ),
            settings=False,
        )
        for p, extra in planners
    )


def main(argv: Sequence[str]) -> str:
    """``python -m graspexp.run.suites [TRIALS]``: the paper suite's overrides; ``... compare``:
    :data:`COMPARE_SUITE`; on one line, for scripts and ``nox``."""
    if argv[:1] == ["compare"]:
        return " ".join(COMPARE_SUITE)
    return " ".join(paper_suite(int(argv[0]) if argv else TRIALS_PER_SETTING))


if __name__ == "__main__":
    print(main(sys.argv[1:]))
