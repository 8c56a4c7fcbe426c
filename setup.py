"""The one packaging fact ``pyproject.toml`` cannot state: the top-level ``conf/`` (the YAML options, the
user's layout) ships inside the wheel as the package ``graspexp.conf``, beside every ``graspexp*``
package found in the checkout. Everything else is in ``pyproject.toml``."""

from setuptools import find_packages, setup

setup(
    packages=[*find_packages(include=["graspexp", "graspexp.*"]), "graspexp.conf"],
    package_dir={"graspexp.conf": "conf"},
)
