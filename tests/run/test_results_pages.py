"""``results`` and ``results --check`` on pages a user broke or cannot write (issue 51, finding 10): every
problem is one line naming the page (and the line), found before any sweep runs; no fingerprint job runs
here (they are faked)."""

import dataclasses
from pathlib import Path

import pytest

from graspexp.report.pages import BEGIN, END, Stamp, page_stamps, stamp
from graspexp.run import results
from graspexp.run.result_pages import pages
from graspexp.tools.results import main as results_main

ROOT = Path(__file__).resolve().parents[2]
PAGES = pages()
CPU = "x86_64-v4-intel"
GOOD = Stamp("index", "1111", "abc1234", CPU)
"""The stamp of this class the faked fingerprint jobs reproduce."""


@pytest.fixture
def page(tmp_path, monkeypatch):
    """The index page, moved to ``tmp_path/page.md``; the fingerprint jobs faked (they give ``1111``, and
    record which pages they ran for); the CPU class fixed."""
    ran: list[str] = []

    def fingerprints(pages, *args, **kwargs):
        ran.extend(p.name for p in pages)
        return {p.name: "1111" for p in pages}

    monkeypatch.setattr(results, "run_fingerprints", fingerprints)
    monkeypatch.setattr(results, "cpu_class", lambda: CPU)
    index = dataclasses.replace(next(p for p in PAGES if p.name == "index"), path="page.md")
    return index, tmp_path / "page.md", ran


def _write(path: Path, *lines: str) -> None:
    path.write_text("\n".join(["# P", "", *lines, "", "After."]) + "\n")


def test_a_stamped_block_is_current(page, tmp_path):
    index, path, ran = page
    _write(path, BEGIN, stamp(GOOD), "", "tables", END)
    assert results.check([index], tmp_path, 1) == [] and ran == ["index"]


def test_a_garbled_stamp_is_a_problem_naming_the_page_and_line(page, tmp_path):
    index, path, ran = page
    garbled = "<!-- graspexp results page=index fingerprint=12zz commit=abc1234 cpu=x86_64-v4-amd -->"
    _write(path, BEGIN, stamp(GOOD), garbled, "", "tables", END)
    (problem,) = results.check([index], tmp_path, 1)
    assert problem == f"page.md:5: a garbled stamp line, not read: {garbled!r}"
    assert ran == []
    _write(path, BEGIN, stamp(GOOD), "<!-- graspexp results page=index fingerprint=1111", "tables", END)
    assert results.check([index], tmp_path, 1)[0].startswith("page.md:5: a garbled stamp line")


def test_a_stamp_outside_the_block_is_not_trusted(page, tmp_path):
    index, path, ran = page
    _write(path, BEGIN, "tables", END, "", stamp(GOOD))
    (problem,) = results.check([index], tmp_path, 1)
    assert (
        problem == f"page.md:7: a stamp outside the generated block (lines 3-5), not trusted: {stamp(GOOD)}"
    )
    _write(path, stamp(GOOD), BEGIN, stamp(GOOD), "tables", END)
    assert results.check([index], tmp_path, 1) == [
        f"page.md:3: a stamp outside the generated block (lines 4-7), not trusted: {stamp(GOOD)}"
    ]
    assert ran == []


def test_two_stamps_of_one_cpu_class_are_a_conflict_not_the_first_one(page, tmp_path):
    index, path, ran = page
    other = dataclasses.replace(GOOD, fingerprint="2222", commit="def5678")
    _write(path, BEGIN, stamp(GOOD), stamp(other), "", "tables", END)
    (problem,) = results.check([index], tmp_path, 1)
    assert problem == (
        "page.md: 2 stamps of page 'index' for CPU class x86_64-v4-intel, lines 4 (1111), 5 (2222): one class "
        "holds one fingerprint; delete the wrong line or regenerate the page"
    )
    assert ran == []
    _write(path, BEGIN, stamp(GOOD), stamp(Stamp("readme", "1111", "abc1234", CPU)), "tables", END)
    assert results.check([index], tmp_path, 1) == [
        "page.md:5: a stamp of page 'readme' in the block of page 'index'"
    ]


def test_a_page_whose_block_was_deleted_is_not_current(page, tmp_path):
    index, path, ran = page
    _write(path, stamp(GOOD), "", "tables")  # the two marker lines deleted, the stamp kept
    (problem,) = results.check([index], tmp_path, 1)
    assert problem.startswith(
        f"page.md: no generated block: it needs one line {BEGIN!r} and, after it, one line"
    )
    assert problem.endswith("regenerate the page with python -m graspexp results --pages index")
    _write(path, BEGIN, stamp(GOOD), "tables", END, BEGIN, END)
    assert (
        "no single generated block (2 opening and 2 closing marker lines)"
        in results.check([index], tmp_path, 1)[0]
    )
    path.unlink()
    assert results.check([index], tmp_path, 1) == [
        f"page.md: no such file under {tmp_path}: run python -m graspexp results --pages index"
    ]
    assert ran == []


def test_stamp_cpu_leaves_a_page_with_a_broken_block_alone(page, tmp_path):
    index, path, ran = page
    other = Stamp("index", "0000", "abc1234", "x86_64-v3-amd")
    _write(path, BEGIN, stamp(other), "tables", END, stamp(other))
    (problem,) = results.stamp_cpu([index], tmp_path, 1)
    assert "a stamp outside the generated block" in problem and ran == []
    _write(path, BEGIN, stamp(other), "tables", END)
    assert results.stamp_cpu([index], tmp_path, 1) == [] and ran == ["index"]
    added = dataclasses.replace(GOOD, commit="unknown")  # tmp_path is no git checkout
    assert page_stamps(path.read_text(), "index", "page.md") == ([other, added], [])


def test_the_pages_of_this_repository_have_one_block_and_sound_stamps():
    """Every results page's stamps are in its block, parse, and hold one fingerprint per CPU class (what
    ``results --check --pages readme,index`` reports current on this machine)."""
    for p in PAGES:
        stamps, problems = page_stamps((ROOT / p.path).read_text(), p.name, p.path)
        assert problems == [] and stamps, p.path


@pytest.fixture
def no_sweep(monkeypatch):
    """Any sweep or fingerprint job that would run fails the test: the checks come first."""

    def refuse(*args, **kwargs):
        raise AssertionError("a sweep or fingerprint job ran before the pages were checked")

    monkeypatch.setattr(results, "run_sweep", refuse)
    monkeypatch.setattr(results, "run_fingerprints", refuse)


def test_regenerate_without_the_page_file_is_refused_before_any_sweep(tmp_path, no_sweep):
    index = dataclasses.replace(next(p for p in PAGES if p.name == "index"), path="docs/page.md")
    with pytest.raises(results.ResultsError) as exc:
        results.regenerate([index], tmp_path, tmp_path / "out", [], "python -m graspexp results", 1)
    assert str(exc.value) == (
        f"nothing run: page index: {tmp_path / 'docs/page.md'} does not exist (--root names the repository root)"
    )
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "page.md").write_text("# no block\n")
    with pytest.raises(
        results.ResultsError, match=r"^nothing run: .*page.md has no generated block: add a line"
    ):
        results.regenerate([index], tmp_path, tmp_path / "out", [], "python -m graspexp results", 1)


def test_regenerate_on_a_read_only_root_is_refused_before_any_sweep(tmp_path, no_sweep, monkeypatch):
    """A read-only checkout (or run folder): os.access says so, for root too on a read-only file system;
    faked here, as the tests may run as root."""
    index = dataclasses.replace(next(p for p in PAGES if p.name == "index"), path="page.md")
    _write(tmp_path / "page.md", BEGIN, END)
    root = tmp_path.resolve()
    monkeypatch.setattr(results, "_writable", lambda path: not Path(path).resolve().is_relative_to(root))
    with pytest.raises(results.ResultsError) as exc:
        results.regenerate([index], tmp_path, tmp_path / "out", [], "python -m graspexp results", 1)
    assert str(exc.value) == (
        f"nothing run: page index: {tmp_path / 'page.md'} is not writable (a read-only root?); the run folder "
        f"{tmp_path / 'out'} cannot be made: {tmp_path} is not a writable folder (choose --out)"
    )


def test_the_results_tool_on_a_missing_page_is_one_line_and_exit_2(tmp_path, no_sweep, capsys):
    with pytest.raises(SystemExit) as exc:
        results_main(["--pages", "index", "--root", str(tmp_path), "--out", str(tmp_path / "out")])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"graspexp results: error: nothing run: page index: {tmp_path / 'docs/results/index.md'} does not "
        "exist (--root names the repository root)"
    ]
