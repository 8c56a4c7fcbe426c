"""The measurements behind the ``bench.*`` tools: plan latency, per-phase trial timings, collision shapes,
registration accuracy and the shortlist study (each tool parses its arguments and calls these)."""
