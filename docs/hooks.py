"""mkdocs hook: the configuration reference page, generated from the schemas at every build.

``reference/configuration.md`` is not a file in ``docs/``: it is rendered by
:func:`graspexp.config.reference.render` (the same text as ``python -m graspexp config_reference``),
so it names every key of every group and planner the code has, and nothing else.
"""

import sys
from pathlib import Path

from mkdocs.structure.files import File, Files

PAGE = "reference/configuration.md"


def on_files(files: Files, config) -> Files:
    root = str(Path(config.config_file_path).resolve().parent)
    if root not in sys.path:  # the checkout being documented, also under the ``mkdocs`` script
        sys.path.insert(0, root)
    from graspexp.config.reference import render

    files.append(File.generated(config, PAGE, content=render()))
    return files
