"""The job matrices live in :mod:`graspexp.run.suites` alone (the results pages only pick and render
sweeps), and a learned planner joins the results pages, the camera page's columns, ``bench.learned``,
``download_checkpoint`` and ``nox -s learned``'s page list through its plugin alone."""

import ast
import re
from pathlib import Path

import pytest

from graspexp.config import plugins
from graspexp.config.planner.base import BASE_CONSTRAINTS, PlannerConfig
from graspexp.config.plugins import Learned, LoadedPlanner, PlannerPlugin
from graspexp.core.checkpoints import Checkpoint
from graspexp.run import result_pages, suites
from graspexp.run.results import fingerprint_jobs, learned_pages
from graspexp.run.suites import Sweep

OVERRIDE = re.compile(r"^[+~]?[A-Za-z_][\w./]*=\S*$")
"""A Hydra override (``key=value``, ``hydra/launcher=x``), or the start of one in an f-string."""


def _suites_sweeps() -> set[Sweep]:
    """Every sweep :mod:`graspexp.run.suites` defines: its module-level sweeps and groups of sweeps, and
    what its sweep functions build."""
    found: set[Sweep] = set()
    built = [
        suites.camera_sweeps(),
        suites.camera_fingerprint(),
        suites.learned_runs().values(),
        suites.clutter_camera_runs().values(),
        suites.clutter_camera_fingerprint(),
    ]
    for value in [*vars(suites).values(), *built]:
        if isinstance(value, Sweep):
            found.add(value)
        elif isinstance(value, (tuple, list, type({}.values()))):
            found.update(v for v in value if isinstance(v, Sweep))
    return found


def test_the_results_pages_spell_no_override_and_build_no_sweep():
    """result_pages.py holds page assembly only: no ``key=value`` string (nor the start of one in an
    f-string) and no ``Sweep(...)`` or ``Reading(...)``; the job matrices are in suites.py."""
    tree = ast.parse(Path(result_pages.__file__).read_text())
    strings = [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)]
    assert [s for s in strings if OVERRIDE.match(s)] == []
    calls = {n.func.id for n in ast.walk(tree) if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}
    assert not calls & {"Sweep", "Reading"}


def test_every_sweep_of_every_page_comes_from_suites():
    known = _suites_sweeps()
    for page in result_pages.pages():
        assert set(page.sweeps) | set(page.fingerprint) <= known, page.name


def test_the_suites_print_the_paper_suite_and_the_compare_matrix():
    assert suites.main([]) == " ".join(suites.paper_suite())
    assert suites.main(["30"]).endswith("trials=30")
    compare = suites.main(["compare"]).split()
    assert compare[0] == "planner=optimal,optimal_in_area,optimal_plus,antipodal,obb,random"
    assert "objects=[can,mug,banana]" in compare and compare == list(suites.COMPARE_SUITE)


FAKE_CHECKPOINT = Checkpoint(
    "fakenet_weights", "fakenet.pt", "https://example.invalid/fakenet.pt", "0" * 64, 1, "", ""
)
FAKE = LoadedPlanner(
    "fakenet",
    "fakenet-planner 0.1",
    "fakenet:PLUGIN",
    PlannerPlugin(
        plan="fakenet:plan",
        config=PlannerConfig,
        constraints=BASE_CONSTRAINTS,
        needs_observation=True,
        learned=Learned(gripper="robotiq_2f85", checkpoints=(FAKE_CHECKPOINT,)),
    ),
)
"""A learned planner of another package, trained for the Robotiq 2F-85."""


@pytest.fixture
def fake_learned(monkeypatch):
    """The installed planners and :data:`FAKE` (as its entry point would add it: nothing else edited)."""
    installed = plugins.load_planners()
    monkeypatch.setattr(plugins, "load_planners", lambda: {**installed, "fakenet": FAKE})
    return FAKE


def _names(sweeps) -> list[str]:
    return [s.name for s in sweeps]


def test_a_learned_plugin_joins_the_pages_and_columns_without_an_edit(fake_learned):
    from graspexp.report.camera import learned_columns

    assert learned_columns() == (
        ("fakenet", False, "fakenet, gripper=robotiq_2f85, camera views"),
        ("giga", False, "giga, gripper=panda, camera views"),
        ("vgn", False, "vgn, gripper=panda, camera views"),
    )
    pages = {p.name: p for p in result_pages.pages()}
    camera = pages["camera"]
    assert _names(camera.sweeps)[-3:] == ["fakenet_robotiq_2f85", "giga_panda", "vgn_panda"]
    fake = camera.sweeps[-3].reading.overrides
    assert fake == ("planner=fakenet", "gripper=robotiq_2f85", "dataset=ycb", "record=false")
    assert "fakenet_robotiq_2f85" in _names(camera.fingerprint)
    learned = ["fakenet_robotiq_2f85", "fakenet_rg2", "giga_panda", "giga_rg2", "vgn_panda", "vgn_rg2"]
    assert _names(pages["learned"].sweeps) == learned
    assert pages["learned"].sweeps[1].reading.what == "fakenet on the paper's gripper (a transfer)"
    clutter = pages["clutter_camera"]
    assert "clutter_camera_fakenet" in _names(clutter.sweeps)
    jobs = [j for j in fingerprint_jobs(clutter) if "planner=fakenet" in j]
    assert len(jobs) == 2 and all(
        "gripper=robotiq_2f85" in j and "perception.source=depth" in j for j in jobs
    )
    assert [p.name for p in learned_pages(list(pages.values()))] == ["camera", "learned", "clutter_camera"]


def test_bench_learned_and_download_checkpoint_take_a_learned_plugin(fake_learned):
    from graspexp.tools.bench.learned import bench_jobs
    from graspexp.tools.download_checkpoint import known_checkpoints

    assert bench_jobs([]) == [
        ["planner=fakenet", "gripper=robotiq_2f85", "dataset=ycb", "mode=bin"],
        ["planner=giga", "gripper=panda", "dataset=ycb", "mode=bin"],
        ["planner=vgn", "gripper=panda", "dataset=ycb", "mode=bin"],
    ]
    assert bench_jobs(["planner=fakenet", "gripper=rg2", "objects=[025_mug]"]) == [
        ["dataset=ycb", "mode=bin", "planner=fakenet", "gripper=rg2", "objects=[025_mug]"]
    ]
    assert bench_jobs(["planner=optimal"]) == [["dataset=ycb", "mode=bin", "planner=optimal"]]
    assert known_checkpoints()["fakenet_weights"] is FAKE_CHECKPOINT and "vgn" in known_checkpoints()


def test_without_learned_planners_the_pages_keep_their_other_sweeps(monkeypatch):
    """No learned planner installed (vgn's and giga's entry points gone): no learned page, no learned column or
    row."""
    installed = plugins.load_planners()
    learned = set(plugins.learned_planners())
    monkeypatch.setattr(
        plugins, "load_planners", lambda: {k: v for k, v in installed.items() if k not in learned}
    )
    pages = {p.name: p for p in result_pages.pages()}
    assert "learned" not in pages and learned_pages(list(pages.values())) == []
    assert _names(pages["camera"].sweeps)[-1] == "antipodal_view"
    assert list(suites.clutter_camera_runs()) == [""]
