"""Grasp quality without physics: the two-contact force-closure metric (GraspNet style)."""

from graspexp.quality.force_closure import (
    DEFAULT_MUS,
    contacts_for_grasp,
    fc_min_mu,
    grasp_quality,
    min_friction_for_closure,
)

__all__ = ["DEFAULT_MUS", "contacts_for_grasp", "fc_min_mu", "grasp_quality", "min_friction_for_closure"]
