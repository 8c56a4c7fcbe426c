"""Helpers the tests share (import them as ``helpers.<module>``; ``tests/`` is on ``sys.path``):
configs and the data root, the CLI in a subprocess, object folders and grippers written at test time,
MCAP checks, synthetic planner inputs and the grip-force measurement."""
