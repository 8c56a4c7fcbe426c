"""Two-contact force closure, as GraspNet-1Billion scores grasps (the dex-net test).

A parallel-jaw grasp touches the object at two points ``p1``, ``p2`` with OUTWARD unit surface normals
``n1``, ``n2``; they are in force closure for friction ``mu`` when the line joining them lies inside both
friction cones (the test in :mod:`graspexp.planning.friction`, which the antipodal planner uses too).
:func:`min_friction_for_closure` returns the smallest ``mu`` of a list (GraspNet uses 0.2 ... 1.2 in
steps of 0.2; lower is a better grasp) for which that holds, ``inf`` if none does.

Contacts of a planned grasp (:func:`contacts_for_grasp`): the closing line is the grasp frame's Y axis
through the grasp point. From each side it is traced inwards, starting outside the object, and the
first surface point hit is that finger's contact: ``p1`` on the +Y side (its finger moves along -Y),
``p2`` on the -Y side. On a mesh this is trimesh ray casting (the hit triangle's normal is ``n``); on a
cloud it is the extreme points along +-Y among those within ``line_radius_m`` of the line (their cloud
normals are ``n``). Everything is in the world frame, metres.
"""

import math

import numpy as np
import trimesh

from graspexp.planning.friction import line_cone_cosines
from graspexp.planning.grasp import Grasp

DEFAULT_MUS = (0.2, 0.4, 0.6, 0.8, 1.0, 1.2)
"""Friction coefficients tried in ascending order (GraspNet-1Billion's list)."""

ANGLE_TOL_RAD = 1e-9
"""Slack on the cone test, so a contact exactly on the cone boundary counts as inside."""

LINE_RADIUS_M = 0.003
"""Cloud contacts: points within this distance of the closing line are candidates, m."""


def cone_angles_rad(p1: np.ndarray, n1: np.ndarray, p2: np.ndarray, n2: np.ndarray) -> tuple[float, float]:
    """Angles between the contact line and each inward normal, radians; (pi, pi) for coincident points.

    p1, p2 : (3,) contact points, m; n1, n2 : (3,) outward normals (normalised here).
    """
    m1, m2 = float(np.linalg.norm(n1)), float(np.linalg.norm(n2))
    d, cos1, cos2 = line_cone_cosines(
        p1, np.asarray(n1, dtype=np.float64), p2, np.asarray(n2, dtype=np.float64)
    )
    if d == 0.0 or m1 == 0.0 or m2 == 0.0:
        return (math.pi, math.pi)
    c1 = float(np.clip(cos1 / m1, -1.0, 1.0))
    c2 = float(np.clip(cos2 / m2, -1.0, 1.0))
    return (math.acos(c1), math.acos(c2))


def min_friction_for_closure(
    p1: np.ndarray, n1: np.ndarray, p2: np.ndarray, n2: np.ndarray, mus: tuple[float, ...] = DEFAULT_MUS
) -> float:
    """Smallest ``mu`` in ``mus`` (taken in ascending order) for which the two contacts are in force
    closure (module doc); ``inf`` when none is, or when the points coincide."""
    worst = max(cone_angles_rad(p1, n1, p2, n2))
    for mu in sorted(float(m) for m in mus):
        if worst <= math.atan(mu) + ANGLE_TOL_RAD:
            return mu
    return math.inf


def _mesh_contacts(mesh: trimesh.Trimesh, centre: np.ndarray, y: np.ndarray):
    far = float(np.linalg.norm(mesh.bounds[1] - mesh.bounds[0])) + float(
        np.linalg.norm(mesh.centroid - centre)
    )
    out = []
    for sign in (1.0, -1.0):
        origin = centre + sign * far * y
        locs, _, tris = mesh.ray.intersects_location([origin], [-sign * y], multiple_hits=True)
        if len(locs) == 0:
            return None
        j = int(np.argmin(np.linalg.norm(locs - origin, axis=1)))
        out += [locs[j], np.asarray(mesh.face_normals[tris[j]], dtype=np.float64)]
    return tuple(out)


def _cloud_contacts(
    points: np.ndarray, normals: np.ndarray, centre: np.ndarray, y: np.ndarray, radius: float
):
    rel = points - centre
    t = rel @ y
    off = np.linalg.norm(rel - t[:, None] * y, axis=1)
    near = np.flatnonzero(off <= radius)
    if len(near) < 2:
        return None
    i1, i2 = near[np.argmax(t[near])], near[np.argmin(t[near])]
    if i1 == i2:
        return None
    return (points[i1], normals[i1], points[i2], normals[i2])


def contacts_for_grasp(
    obj: trimesh.Trimesh | np.ndarray,
    grasp: Grasp,
    *,
    normals: np.ndarray | None = None,
    line_radius_m: float = LINE_RADIUS_M,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """The two finger contacts ``(p1, n1, p2, n2)`` of ``grasp`` on the object (module doc), or None
    when the closing line misses the object on a side.

    obj : a ``trimesh.Trimesh`` in the world frame, or an (N, 3) world cloud with ``normals`` (N, 3)
        outward. p1 is on the grasp's +Y side, p2 on its -Y side; normals are outward, unit.
    """
    centre = np.asarray(grasp.pose[:3, 3], dtype=np.float64)
    y = np.asarray(grasp.pose[:3, 1], dtype=np.float64)
    y = y / np.linalg.norm(y)
    if isinstance(obj, trimesh.Trimesh):
        found = _mesh_contacts(obj, centre, y)
    else:
        if normals is None:
            raise ValueError("contacts_for_grasp on a point cloud needs normals=(N, 3) outward normals")
        found = _cloud_contacts(np.asarray(obj, float), np.asarray(normals, float), centre, y, line_radius_m)
    if found is None:
        return None
    p1, n1, p2, n2 = (np.asarray(a, dtype=np.float64) for a in found)
    return p1, n1 / np.linalg.norm(n1), p2, n2 / np.linalg.norm(n2)


def fc_min_mu(mesh: trimesh.Trimesh, grasp: Grasp) -> float:
    """Smallest friction coefficient of :data:`DEFAULT_MUS` at which ``grasp`` is force-closure on ``mesh``
    (both in the same frame); inf when none is or the closing line misses the mesh."""
    return grasp_quality(mesh, grasp)["fc_min_mu"]


def grasp_quality(mesh_world: trimesh.Trimesh, grasp: Grasp, mus: tuple[float, ...] = DEFAULT_MUS) -> dict:
    """Physics-free quality of a planned grasp, for the trial log.

    mesh_world : the object's mesh transformed to its (true) world pose.

    Returns
    -------
    ``{"fc_min_mu": float (inf when not force-closure for any mu or the line misses the object),
    "contacts": [[p1, n1], [p2, n2]] as lists of floats (world, m; empty when missed)}``.
    """
    found = contacts_for_grasp(mesh_world, grasp)
    if found is None:
        return {"fc_min_mu": math.inf, "contacts": []}
    p1, n1, p2, n2 = found
    return {
        "fc_min_mu": min_friction_for_closure(p1, n1, p2, n2, mus),
        "contacts": [[p1.tolist(), n1.tolist()], [p2.tolist(), n2.tolist()]],
    }
