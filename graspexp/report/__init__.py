"""Reports from trial logs: the paper's Tables 1 and 2 with our numbers beside the paper's, Wilson
intervals, failure reasons, planner runtime and bar charts (``python -m graspexp report DIR``)."""

from graspexp.report.build import Report, build_report, write_report
from graspexp.report.collect import Collected, collect, find_trial_logs
from graspexp.report.stats import percentiles, wilson_interval

__all__ = [
    "Collected",
    "Report",
    "build_report",
    "collect",
    "find_trial_logs",
    "percentiles",
    "wilson_interval",
    "write_report",
]
