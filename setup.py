"""The one packaging fact ``pyproject.toml`` cannot state: the top-level ``conf/`` (the YAML options, the
user's layout) ships inside the wheel as the package ``graspexp.conf``, beside every ``graspexp*``
package found in the checkout. Everything else is in ``pyproject.toml``."""

from setuptools import find_namespace_packages, setup

setup(
    # namespace discovery, as pyproject.toml's default: data folders without __init__.py (e.g.
    # graspexp/datasets/regions) are packages whose YAML and JSON ship ("*" in package-data)
    packages=[
        *find_namespace_packages(include=["graspexp", "graspexp.*"], exclude=["*.__pycache__"]),
        "graspexp.conf",
    ],
    package_dir={"graspexp.conf": "conf"},
)
