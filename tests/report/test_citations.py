"""The documentation that generated text cites exists: every section of
:data:`graspexp.report.citations.SECTIONS`, every ``docs/....md`` page and ``(docs/<page>, "<section>")``
citation in the package's text (reports, results pages, the configuration reference's docstrings), and
no citation of a README section the README lacks."""

import re
from pathlib import Path

import pytest

import graspexp
from graspexp.report.citations import SECTIONS
from graspexp.report.pages import missing_links

PACKAGE = Path(graspexp.__file__).parent
ROOT = PACKAGE.parent
DOCS = ROOT / "docs"


def _headings(page: Path) -> set[str]:
    return {ln.lstrip("#").strip() for ln in page.read_text().splitlines() if re.match(r"#{1,6} ", ln)}


def _sources() -> dict[str, str]:
    return {str(p.relative_to(ROOT)): p.read_text() for p in sorted(PACKAGE.rglob("*.py"))}


@pytest.mark.parametrize("section", SECTIONS, ids=lambda s: s.title)
def test_every_cited_section_exists(section):
    page = DOCS / section.page
    assert page.is_file(), section
    assert section.title in _headings(page), f"{section.page} has no heading {section.title!r}"


def test_the_package_cites_only_pages_and_sections_that_exist():
    wrong = []
    readme = _headings(ROOT / "README.md")
    for name, text in _sources().items():
        flat = re.sub(r"\s*\n\s*", " ", text)
        for page in set(re.findall(r"docs/((?:[\w.-]+/)*[\w.-]+\.md)", flat)):
            if "*" not in page and not (DOCS / page).is_file():
                wrong.append(f"{name}: docs/{page} does not exist")
        for page, title in re.findall(r'\(docs/([\w./-]+\.md), "([^"]+)"\)', flat):
            if (DOCS / page).is_file() and title not in _headings(DOCS / page):
                wrong.append(f"{name}: docs/{page} has no section {title!r}")
        for title in re.findall(r'\(README, "?([^")]+)"?\)', flat):
            if title not in readme:
                wrong.append(f"{name}: the README has no section {title!r}")
    assert not wrong, "\n".join(wrong)


def test_the_report_cites_the_determinism_section():
    text = (PACKAGE / "report" / "build.py").read_text()
    assert "DETERMINISM.cite()" in text and "(README, Determinism)" not in text


def _slug(title: str) -> str:
    """The anchor mkdocs' toc extension gives a heading."""
    return re.sub(r"[\s]+", "-", re.sub(r"[^\w\s-]", "", title).strip().lower())


def test_readme_and_results_pages_link_only_to_files_and_sections_that_exist():
    for path in [ROOT / "README.md", *sorted((DOCS / "results").rglob("*.md"))]:
        text = path.read_text()
        assert missing_links(text, path) == [], path
        for target, anchor in re.findall(r"\]\(([\w./-]+\.md)#([\w-]+)\)", text):
            assert anchor in {_slug(t) for t in _headings(path.parent / target)}, (path, target, anchor)
