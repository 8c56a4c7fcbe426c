"""Benchmarks run by ``nox -s bench`` (``python -m graspexp.tools.bench.<name>``)."""
