"""The results pages ``python -m graspexp results`` regenerates (:data:`PAGES`), one :class:`Page` each:
its file, its sweeps, how its generated block is rendered and its fingerprint jobs. A new page is one
more entry here (and a page file holding the generated block's two marker lines,
:data:`graspexp.report.pages.BEGIN` / :data:`~graspexp.report.pages.END`).
"""

from __future__ import annotations

import dataclasses
import shlex
import subprocess
import sys
from collections.abc import Callable, Sequence

from graspexp.report.build import agreement_section, build_report
from graspexp.report.camera import COLUMNS, LEARNED_COLUMNS, camera_markdown
from graspexp.report.collect import collect
from graspexp.report.gallery import write_gallery
from graspexp.report.learned import learned_markdown
from graspexp.report.pages import embed
from graspexp.report.readings import beside_paper, reading_averages, readings_report
from graspexp.report.round_tables import (
    clutter_markdown,
    find_rounds,
    registration_markdown,
    side_by_side_markdown,
)
from graspexp.report.study import plot_study, read_sweep_study, study_table
from graspexp.report.tuning import scored_trial, tuning_markdown
from graspexp.run.results import Page, PageInput, ResultsError, Sweep
from graspexp.run.score import score_study
from graspexp.run.suites import ABLATIONS, ALL, READINGS, Reading

GALLERY_PER_REASON = 1
"""Failures drawn per dataset, setting and reason in a page's gallery."""
SCORE_TRIALS = 20
"""Trials per held-out object when a tuning page scores its study's constants."""
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


def _sweeps(names: Sequence[str], extra: tuple[str, ...] = ()) -> tuple[Sweep, ...]:
    return tuple(Sweep(ALL[n], extra) for n in names)


def readings_tables(sweeps: Sequence[Sweep]) -> Callable[[PageInput], str]:
    """A render function: the readings tables (:func:`graspexp.report.readings.readings_report`) of
    ``sweeps``, one row per sweep, CSVs in the page's work folder."""

    def render(page: PageInput) -> str:
        entries = {s.reading.name: (page.runs[s], s.reading.what) for s in sweeps}
        return embed(readings_report(entries, page.work))

    return render


def _with_title(title: str, render: Callable[[PageInput], str]) -> Callable[[PageInput], str]:
    return lambda page: f"## {title}\n\n{render(page)}"


def _joined(*parts: Callable[[PageInput], str]) -> Callable[[PageInput], str]:
    return lambda page: "\n".join(part(page) for part in parts)


def _agreement_and_gallery(sweep: Sweep) -> Callable[[PageInput], str]:
    """The paper agreement (Fisher's exact test per object cell) of ``sweep``'s runs, and a gallery of
    its failures, drawn into the page's assets folder."""

    def render(page: PageInput) -> str:
        report = build_report(page.runs[sweep], progress=False)
        page.assets.mkdir(parents=True, exist_ok=True)
        prefix = f"{page.assets.name}/"
        md = []
        for ag in report.agreements:
            text = "\n".join(agreement_section(ag, report.collected.results, page.assets))
            (page.assets / f"{ag.name}.md").unlink()  # the site links its CSV: every cell
            md.append(embed(text.replace(f"]({ag.name}.md)", f"]({ag.name}.csv)"), prefix=prefix))
        gallery = write_gallery(report.collected.results, page.assets, GALLERY_PER_REASON)
        (page.assets / "gallery.md").unlink()  # the page embeds it
        md.append("## Failures of `" + sweep.reading.name + "`, one per setting and reason\n")
        md.append(embed(gallery, shift=2, prefix=prefix))
        return "\n".join(md)

    return render


def _tuning(sweep: Sweep) -> Callable[[PageInput], str]:
    """The study's report (:func:`graspexp.report.tuning.tuning_markdown`): its trials, the baseline and
    the scored trial (:func:`graspexp.report.tuning.scored_trial`) on the held-out objects, the plots."""

    def render(page: PageInput) -> str:
        study_dir = page.runs[sweep]
        found = read_sweep_study(study_dir)
        trial = scored_trial(found.study)
        scored = score_study(found, study_dir, "test", SCORE_TRIALS, (), trial)
        page.assets.mkdir(parents=True, exist_ok=True)
        study_table(found.study).to_csv(page.assets / "tuning_trials.csv", index=False)
        pngs = [p.name for p in plot_study(found.study, page.assets)]
        command = f"python -m graspexp tune {study_dir} --trials {SCORE_TRIALS}"
        command += f" --trial {trial}" if trial is not None else ""
        return embed(tuning_markdown(found, scored, command, pngs), prefix=f"{page.assets.name}/")

    return render


def _readme(sweep: Sweep) -> Callable[[PageInput], str]:
    def render(page: PageInput) -> str:
        avg = reading_averages({sweep.reading.name: (page.runs[sweep], sweep.reading.what)})
        return beside_paper(avg, sweep.reading.name, "`optimal`") + "\n"

    return render


def _table1_trials(page: PageInput, sweep: Sweep):
    """The Table 1 (YCB) trials of ``sweep``'s runs."""
    results = collect(page.runs[sweep]).results
    return results[results["dataset"] == "ycb"]


def _camera(sweeps: Sequence[Sweep]) -> Callable[[PageInput], str]:
    """Table 1 measured in one physics (:func:`graspexp.report.camera.camera_markdown`): every column's
    trials, from ``sweeps``."""

    def render(page: PageInput) -> str:
        import pandas as pd

        results = pd.concat([_table1_trials(page, s) for s in sweeps], ignore_index=True)
        return camera_markdown(results, (*COLUMNS, *LEARNED_COLUMNS)) + "\n" + _registration(page)

    return render


REGISTRATION_POSES = 10
"""Seeded random orientations per object of the registration measurement on the camera page."""


def _registration(page: PageInput) -> str:
    """The registration accuracy and cost of every Table 1 and Table 2 object
    (:func:`graspexp.report.registration.registration_report`, as ``python -m graspexp bench.registration``
    prints it), measured while the page is written."""
    from omegaconf import OmegaConf
    from threadpoolctl import threadpool_limits

    from graspexp.config.compose import compose_config
    from graspexp.datasets import available_objects, job_object
    from graspexp.report.paper import PAPER_TABLES
    from graspexp.report.registration import registration_report

    models, cfg, absent = {}, None, []
    for dataset, table in PAPER_TABLES.items():
        cfg = OmegaConf.to_object(compose_config([f"dataset={dataset}", "perception.source=depth"]))
        present = set(available_objects(cfg.dataset))
        models[dataset] = [job_object(cfg, name) for name in table.labels if name in present]
        absent += [f"{dataset} {name}" for name in table.labels if name not in present]
    with threadpool_limits(limits=1):
        text = registration_report(cfg.perception, models, REGISTRATION_POSES, int(cfg.seed), 10.0, 10.0)
    missing = f" Not measured (no mesh in the data root): {', '.join(absent)}." if absent else ""
    return "\n".join(
        [
            "### Registration accuracy and cost",
            "",
            "`python -m graspexp bench.registration` (with BLAS and Open3D on one thread), run while this page "
            f"was written, on the machine above.{missing}",
            "",
            "```",
            text,
            "```",
            "",
        ]
    )


INFERENCE_RUNS = 10
"""Timed plans per object of the inference-time measurement on the learned planners' page."""


def _inference(page: PageInput) -> str:
    """``python -m graspexp bench.learned`` (planner=vgn's CPU time per plan on Table 1's objects), run while
    the page is written; its printout."""
    command = [sys.executable, "-m", "graspexp", "bench.learned", "--runs", str(INFERENCE_RUNS)]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise ResultsError(
            f"{shlex.join(command[1:])} failed: {(done.stderr.strip() or '?').splitlines()[-1]}"
        )
    return "\n".join(
        [
            "### Inference time",
            "",
            f"`python -m graspexp bench.learned --runs {INFERENCE_RUNS}` (one torch thread), run while this page "
            "was written, on the machine above:",
            "",
            "```",
            done.stdout.strip(),
            "```",
            "",
        ]
    )


def _learned(runs: dict[str, Sweep]) -> Callable[[PageInput], str]:
    """A learned planner's tables (:func:`graspexp.report.learned.learned_markdown`), one run per label, and
    its inference time (:func:`_inference`)."""
    return lambda page: "\n".join(
        [learned_markdown({label: _table1_trials(page, s) for label, s in runs.items()}), _inference(page)]
    )


CAMERA_COMMON = ("dataset=ycb", "record=false")
"""Table 1's objects (10 trials, the paper's settings: :func:`graspexp.run.suites.reading_sweep`), no logs."""
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
VGN_PANDA = Sweep(
    Reading(
        "vgn_panda",
        ("planner=vgn", "gripper=panda", *CAMERA_COMMON),
        "vgn with the gripper it was trained for",
    )
)
VGN_RG2 = Sweep(
    Reading(
        "vgn_rg2", ("planner=vgn", "gripper=rg2", *CAMERA_COMMON), "vgn on the paper's gripper (a transfer)"
    )
)
DEFAULT = Sweep(ALL["default"])
TABLES = _sweeps(["default", "in_area", "literal"])
COMPARED = _sweeps(["optimal_plus", "default", "antipodal_area", "antipodal_area_pads", "antipodal", "obb"])
THIRTY = _sweeps(["optimal_plus", "antipodal_area_pads"], ("trials=30", "record=false"))
GENERALISATION = _sweeps(
    ["optimal_plus", "default", "antipodal_area", "antipodal_area_pads", "antipodal"],
    ("dataset=ycb", "dataset.split=test"),
)
ABLATION = tuple(Sweep(r, ("trials=5",)) for r in ABLATIONS)
CAMERA = (DEFAULT, REGISTERED_OPTIMAL, REGISTERED_PLUS, Sweep(ALL["antipodal"]), ANTIPODAL_VIEW, VGN_PANDA)
"""Table 1 in one physics: the exact-pose and full-model columns are the readings' own sweeps (the same
drops; their Table 2 trials are left out), the camera's columns run on Table 1 alone."""
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


def _clutter(sweep: Sweep) -> Callable[[PageInput], str]:
    """The clutter table (:func:`graspexp.report.round_tables.clutter_markdown`) of ``sweep``'s rounds."""
    return lambda page: clutter_markdown(find_rounds(page.runs[sweep])) + "\n"


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
CLUTTER_CAMERA_RUNS = {
    "": Sweep(
        Reading(
            "clutter_camera",
            (*CLUTTER_CAMERA_COMMON, f"planner={','.join(CLUTTER_CAMERA_PLANNERS)}"),
            "clutter removal with the camera: registered poses, antipodal sampling on the cloud",
        ),
        settings=False,
    ),
    "vgn, gripper=panda (trained for it)": Sweep(
        Reading(
            "clutter_camera_vgn",
            (*CLUTTER_CAMERA_COMMON, "planner=vgn", "gripper=panda"),
            "vgn in clutter removal with the gripper it was trained for",
        ),
        settings=False,
    ),
    "vgn, gripper=panda, quality_threshold=0.8 (experiment)": Sweep(
        Reading(
            "clutter_camera_vgn_q08",
            (*CLUTTER_CAMERA_COMMON, "planner=vgn", "gripper=panda", VGN_THRESHOLD_EXPERIMENT),
            "vgn with a lower quality threshold than its authors' (a sensitivity experiment)",
        ),
        settings=False,
    ),
}
"""The camera clutter page's sweeps by the label of their rows ('': each row named by its planner)."""
CLUTTER_CAMERA_FINGERPRINT = tuple(
    Sweep(
        Reading(f"clutter_camera_{p}", (*REGISTERED, *extra, f"planner={p}"), f"{p} in one clutter round"),
        settings=False,
    )
    for p, extra in (*((p, ()) for p in CLUTTER_CAMERA_PLANNERS), ("vgn", ("gripper=panda",)))
)
"""One round of each planner in each scene (:data:`CLUTTER_SETTINGS`), poses registered from the camera."""


def _clutter_camera(runs: dict[str, Sweep], exact: Sweep) -> Callable[[PageInput], str]:
    """The clutter table and the registered poses' errors of the camera clutter page, each sweep's rows
    named by its label (:data:`CLUTTER_CAMERA_RUNS`), and the planners that also ran with exact poses
    (``exact``: the exact-pose page's rounds) side by side."""

    def render(page: PageInput) -> str:
        rounds = [
            dataclasses.replace(r, planner=label) if label else r
            for label, sweep in runs.items()
            for r in find_rounds(page.runs[sweep])
        ]
        return "\n".join(
            [
                clutter_markdown(rounds),
                "",
                "### Exact and registered poses side by side",
                "",
                "The exact-pose rounds are the [exact-pose page](clutter.md)'s, taken over the rounds that "
                "ran here (round r draws and places the same objects in both: the same heaps).",
                "",
                side_by_side_markdown(find_rounds(page.runs[exact]), rounds),
                "",
                "### Registered poses of the grasped objects",
                "",
                registration_markdown(rounds),
                "",
            ]
        )

    return render


PAGES: tuple[Page, ...] = (
    Page("readme", "README.md", (DEFAULT,), _readme(DEFAULT), (DEFAULT,), admonition=False),
    Page(
        "index",
        "docs/results/index.md",
        TABLES,
        _joined(readings_tables(TABLES), _agreement_and_gallery(DEFAULT)),
        TABLES,
    ),
    Page(
        "readings",
        "docs/results/readings.md",
        _sweeps([r.name for r in READINGS]),
        readings_tables(_sweeps([r.name for r in READINGS])),
        _sweeps(
            ["default", "literal", "in_area", "pose_axis_area", "no_swept_check", "k_half_stroke", "tcp_25mm"]
        ),
    ),
    Page(
        "optimal_plus",
        "docs/results/optimal_plus.md",
        (*COMPARED, *THIRTY),
        _joined(
            _with_title("Every planner on the same drops", readings_tables(COMPARED)),
            _with_title("30 drops per object and setting", readings_tables(THIRTY)),
        ),
        COMPARED,
    ),
    Page(
        "generalisation",
        "docs/results/generalisation.md",
        GENERALISATION,
        readings_tables(GENERALISATION),
        _sweeps([s.reading.name for s in GENERALISATION], ("dataset=ycb",)),
        ("objects=[024_bowl,003_cracker_box]", "trials=1"),  # two objects of the test split
    ),
    Page(
        "ablation",
        "docs/results/ablation.md",
        ABLATION,
        readings_tables(ABLATION),
        tuple(
            Sweep(ALL[n], ("trials=5",)) for n in ("plus", "plus_choose_cost", "plus_noise", "default_noise")
        ),
    ),
    Page(
        "camera",
        "docs/results/camera.md",
        CAMERA,
        _camera(CAMERA),
        (DEFAULT, Sweep(ALL["antipodal"]), REGISTERED_OPTIMAL, ANTIPODAL_VIEW, VGN_PANDA),
    ),
    Page(
        "learned",
        "docs/results/learned.md",
        (VGN_PANDA, VGN_RG2),
        _learned({"vgn, gripper=panda": VGN_PANDA, "vgn, gripper=rg2 (transfer)": VGN_RG2}),
        (VGN_PANDA, VGN_RG2),
    ),
    Page(
        "clutter",
        "docs/results/clutter.md",
        (CLUTTER,),
        _clutter(CLUTTER),
        CLUTTER_FINGERPRINT,
        ("dataset=ycb", "trials=1"),
        CLUTTER_SETTINGS,
    ),
    Page(
        "clutter_camera",
        "docs/results/clutter_camera.md",
        (*CLUTTER_CAMERA_RUNS.values(), CLUTTER),
        _clutter_camera(CLUTTER_CAMERA_RUNS, CLUTTER),
        CLUTTER_CAMERA_FINGERPRINT,
        ("dataset=ycb", "trials=1"),
        CLUTTER_SETTINGS,
    ),
    Page("tuning", "docs/results/tuning.md", (STUDY_Z,), _tuning(STUDY_Z), (DEFAULT,)),
    Page("tuning_xyz", "docs/results/xyz/tuning.md", (STUDY_XYZ,), _tuning(STUDY_XYZ), (DEFAULT,)),
)
"""Every results page, in the order they are regenerated."""
