"""The results pages ``python -m graspexp results`` regenerates (:func:`pages`), one :class:`Page` each:
its file, which sweeps it uses, how its generated block is rendered and which sweeps its fingerprint runs.
The sweeps themselves (every override list) are job matrices, defined in :mod:`graspexp.run.suites`; the
learned planners' sweeps and columns come from their plugins
(:func:`graspexp.config.plugins.learned_planners`), so a new learned planner joins the camera, learned and
camera clutter pages without an edit here. A new page is one more entry here (and a page file holding the
generated block's two marker lines, :data:`graspexp.report.pages.BEGIN` / :data:`~graspexp.report.pages.END`).
"""

from __future__ import annotations

import dataclasses
import shlex
import subprocess
import sys
from collections.abc import Callable, Sequence

from graspexp.report.build import agreement_section, build_report
from graspexp.report.camera import COLUMNS, Column, camera_markdown, learned_columns
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
from graspexp.run import suites
from graspexp.run.results import Page, PageInput, ResultsError
from graspexp.run.score import score_study
from graspexp.run.suites import Sweep

GALLERY_PER_REASON = 1
"""Failures drawn per dataset, setting and reason in a page's gallery."""
SCORE_TRIALS = 20
"""Trials per held-out object when a tuning page scores its study's constants."""


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


def _camera(sweeps: Sequence[Sweep], columns: Sequence[Column]) -> Callable[[PageInput], str]:
    """Table 1 measured in one physics (:func:`graspexp.report.camera.camera_markdown`): every column of
    ``columns``, its trials from ``sweeps``."""

    def render(page: PageInput) -> str:
        import pandas as pd

        results = pd.concat([_table1_trials(page, s) for s in sweeps], ignore_index=True)
        return camera_markdown(results, columns) + "\n" + _registration(page)

    return render


REGISTRATION_POSES = 10
"""Seeded random orientations per object of the registration measurement on the camera page."""


def _registration(page: PageInput) -> str:
    """The registration accuracy and cost of every Table 1 and Table 2 object
    (:func:`graspexp.run.bench.registration.registration_report`, as
    ``python -m graspexp bench.registration`` prints it), measured while the page is written."""
    from omegaconf import OmegaConf
    from threadpoolctl import threadpool_limits

    from graspexp.config.compose import compose_config
    from graspexp.datasets import available_objects, job_object
    from graspexp.report.paper import PAPER_TABLES
    from graspexp.run.bench.registration import registration_report

    models, cfg, absent = {}, None, []
    for dataset, table in PAPER_TABLES.items():
        cfg = OmegaConf.to_object(compose_config(suites.registration_job(dataset)))
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
    """``python -m graspexp bench.learned`` (every learned planner's CPU time per plan on Table 1's objects),
    run while the page is written; its printout."""
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


def _clutter(sweep: Sweep) -> Callable[[PageInput], str]:
    """The clutter table (:func:`graspexp.report.round_tables.clutter_markdown`) of ``sweep``'s rounds."""
    return lambda page: clutter_markdown(find_rounds(page.runs[sweep])) + "\n"


def _clutter_camera(runs: dict[str, Sweep], exact: Sweep) -> Callable[[PageInput], str]:
    """The clutter table and the registered poses' errors of the camera clutter page, each sweep's rows
    named by its label (:func:`graspexp.run.suites.clutter_camera_runs`), and the planners that also ran with exact poses
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


def pages() -> tuple[Page, ...]:
    """Every results page, in the order they are regenerated; the camera, learned and camera clutter pages
    hold every learned planner installed (:func:`graspexp.config.plugins.learned_planners`; the learned page
    only where there is one)."""
    s = suites
    camera = s.camera_sweeps()
    learned = s.learned_runs()
    clutter_camera = s.clutter_camera_runs()
    return (
        Page("readme", "README.md", (s.DEFAULT,), _readme(s.DEFAULT), (s.DEFAULT,), admonition=False),
        Page(
            "index",
            "docs/results/index.md",
            s.TABLES,
            _joined(readings_tables(s.TABLES), _agreement_and_gallery(s.DEFAULT)),
            s.TABLES,
        ),
        Page(
            "readings",
            "docs/results/readings.md",
            s.READINGS_SWEEPS,
            readings_tables(s.READINGS_SWEEPS),
            s.READINGS_FINGERPRINT,
        ),
        Page(
            "optimal_plus",
            "docs/results/optimal_plus.md",
            (*s.COMPARED, *s.THIRTY),
            _joined(
                _with_title("Every planner on the same drops", readings_tables(s.COMPARED)),
                _with_title("30 drops per object and setting", readings_tables(s.THIRTY)),
            ),
            s.COMPARED,
        ),
        Page(
            "generalisation",
            "docs/results/generalisation.md",
            s.GENERALISATION,
            readings_tables(s.GENERALISATION),
            s.GENERALISATION_FINGERPRINT,
            s.GENERALISATION_SUBSET,
        ),
        Page(
            "ablation",
            "docs/results/ablation.md",
            s.ABLATION,
            readings_tables(s.ABLATION),
            s.ABLATION_FINGERPRINT,
        ),
        Page(
            "camera",
            "docs/results/camera.md",
            camera,
            _camera(camera, (*COLUMNS, *learned_columns())),
            s.camera_fingerprint(),
        ),
        *(
            (
                Page(
                    "learned",
                    "docs/results/learned.md",
                    tuple(learned.values()),
                    _learned(learned),
                    tuple(learned.values()),
                ),
            )
            if learned
            else ()
        ),
        Page(
            "clutter",
            "docs/results/clutter.md",
            (s.CLUTTER,),
            _clutter(s.CLUTTER),
            s.CLUTTER_FINGERPRINT,
            s.CLUTTER_SUBSET,
            s.CLUTTER_SETTINGS,
        ),
        Page(
            "clutter_camera",
            "docs/results/clutter_camera.md",
            (*clutter_camera.values(), s.CLUTTER),
            _clutter_camera(clutter_camera, s.CLUTTER),
            s.clutter_camera_fingerprint(),
            s.CLUTTER_SUBSET,
            s.CLUTTER_SETTINGS,
        ),
        Page("tuning", "docs/results/tuning.md", (s.STUDY_Z,), _tuning(s.STUDY_Z), (s.DEFAULT,)),
        Page("tuning_xyz", "docs/results/xyz/tuning.md", (s.STUDY_XYZ,), _tuning(s.STUDY_XYZ), (s.DEFAULT,)),
    )
