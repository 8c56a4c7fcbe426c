"""Benchmarks run by ``nox -s bench`` (``python -m graspexp.bench.<name>``)."""
