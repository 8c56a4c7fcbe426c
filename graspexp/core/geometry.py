"""Rigid-body geometry helpers; the one place that converts between rotation conventions.

Quaternion orders: SAPIEN uses wxyz, Foxglove uses xyzw. Functions here say which they take.
Poses are 4x4 homogeneous float64 matrices (rotation columns = the frame's axes in the parent frame).
"""

import numpy as np


def make_pose(rotation: np.ndarray, translation: np.ndarray) -> np.ndarray:
    """(3,3) rotation and (3,) translation -> (4,4) homogeneous pose."""
    T = np.eye(4)
    T[:3, :3] = rotation
    T[:3, 3] = translation
    return T


def transform_points(pose: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Apply a (4,4) pose to (n,3) points."""
    return points @ pose[:3, :3].T + pose[:3, 3]


def quat_wxyz_to_matrix(q: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z) -> (3,3) rotation matrix."""
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_to_quat_wxyz(R: np.ndarray) -> np.ndarray:
    """(3,3) rotation matrix -> unit quaternion (w, x, y, z) with w >= 0."""
    m = np.asarray(R, dtype=float)
    tr = np.trace(m)
    if tr > 0:
        s = 2.0 * np.sqrt(tr + 1.0)
        q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s]
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s]
    else:
        s = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s]
    q = np.asarray(q)
    q /= np.linalg.norm(q)
    return q if q[0] >= 0 else -q


def axis_angle_matrix(axis: np.ndarray, angle_rad: float) -> np.ndarray:
    """Rotation of ``angle_rad`` about ``axis`` (Rodrigues)."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle_rad) * K + (1 - np.cos(angle_rad)) * K @ K


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """Uniformly random rotation matrix (normalised Gaussian quaternion)."""
    q = rng.normal(size=4)
    return quat_wxyz_to_matrix(q / np.linalg.norm(q))


def yaw_rotation(angle_rad: float) -> np.ndarray:
    """Rotation about world +Z."""
    return axis_angle_matrix(np.array([0.0, 0.0, 1.0]), angle_rad)


def pose_error(rng: np.random.Generator, trans_mm: float, rot_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """One draw of the pose estimator's error: (3, 3) rotation about a random axis by a Gaussian angle
    (std ``rot_deg``) and (3,) Gaussian translation (std ``trans_mm`` per axis), m. The one error model of
    the simulated perception (:func:`graspexp.perception.scene_view.perceived_pose`), of the registration
    bench (:mod:`graspexp.run.bench.registration`) and of the planner's noise check
    (:mod:`graspexp.planning.stability`)."""
    rotation = axis_angle_matrix(rng.normal(size=3), np.deg2rad(rng.normal(0.0, rot_deg)))
    return rotation, rng.normal(0.0, trans_mm, size=3) / 1000.0
