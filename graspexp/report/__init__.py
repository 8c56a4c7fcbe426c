"""Reports from trial logs: the paper's Tables 1 and 2 with our numbers beside the paper's, Wilson
intervals, failure reasons, planner runtime and bar charts (``python -m graspexp report DIR``).

The package imports nothing itself: a run that writes its clutter summary (:mod:`graspexp.report.round_tables`)
does not load the tables' plotting and statistics modules (:mod:`graspexp.report.build`)."""
