"""Planner comparison on the same drops: success per planner x setting x dataset, and versus pose noise.

``python -m graspexp.compare DIR [--out OUT]`` (see :mod:`graspexp.compare.report`).
"""

from graspexp.compare.report import (
    NOISE_KEYS,
    SETTING_KEYS,
    check_same_drops,
    collect_trials,
    plot_success_vs_noise,
    render_markdown,
    success_by_noise,
    write_comparison,
)

__all__ = [
    "NOISE_KEYS",
    "SETTING_KEYS",
    "check_same_drops",
    "collect_trials",
    "plot_success_vs_noise",
    "render_markdown",
    "success_by_noise",
    "write_comparison",
]
