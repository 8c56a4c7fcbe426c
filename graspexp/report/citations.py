"""The documentation sections that generated text cites (reports, results pages), one home each;
``tests/report/test_citations.py`` checks that each page and section exists."""

from dataclasses import dataclass


@dataclass(frozen=True)
class DocSection:
    """A section of the documentation: its page (relative to ``docs/``) and its heading."""

    page: str
    title: str

    def cite(self) -> str:
        """The citation as generated text prints it: ``(docs/<page>, "<title>")``."""
        return f'(docs/{self.page}, "{self.title}")'


DETERMINISM = DocSection("guide/config_groups.md", "Seeds and determinism")
"""Same config and seed, same trials bit for bit on one machine; what may differ on another CPU."""
SECTIONS: tuple[DocSection, ...] = (DETERMINISM,)
"""Every section generated text cites."""
