"""Base modules every stage may import, and that import no stage: geometry (frames, rotations), seeding
(derived seeds), outcome (a trial's result and failure reasons), bodies (the scene's body names, the floor's
size) and files (atomic writes)."""
