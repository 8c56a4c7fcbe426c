"""What a depth camera gave the planner: the views (depth, per-pixel object ids, calibration) and the
observed cloud built from them. Plain frozen dataclasses of numpy arrays: the planning stage reads them
without importing the camera, the ray caster or the registration library.

The cloud's normals are estimated when first read (:attr:`Observation.normals`), through the callable the
camera stage put in the observation; :meth:`Observation.target` estimates only the target's (with the
whole cloud as their neighbourhood: the same numbers). A planner that reads only the target, and the
registration, never pay for the normals of the support and the floor.
"""

import functools
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

NormalsAt = Callable[[np.ndarray], np.ndarray]
"""``normals_at(index)``: the (len(index), 3) float64 unit normals of the cloud's points ``index`` (a
sorted (K,) int array), oriented towards the camera that saw each point."""


@dataclass(frozen=True)
class CameraView:
    """One depth frame.

    depth : (H, W) float32, metres along the optical axis (+Z of the camera); 0 = no return.
    ids : (H, W) int32 per-pixel object id, as an instance segmenter gives it: 0 = background or
        support, k > 0 = the object with id k.
    K : (3, 3) float64 pinhole intrinsics, px: [[fx, 0, cx], [0, fy, cy], [0, 0, 1]].
    world_from_camera : (4, 4) float64 pose of the camera frame in the world; OpenCV convention:
        +Z forward (optical axis), +X right, +Y down in the image.
    name : the view's name (``view0``, ``view1``, ...): its frame id in the log.
    """

    depth: np.ndarray
    ids: np.ndarray
    K: np.ndarray
    world_from_camera: np.ndarray
    name: str


def given_normals(normals: np.ndarray) -> NormalsAt:
    """A :data:`NormalsAt` of normals known beforehand, (N, 3) (a cloud that did not come from a camera)."""
    return functools.partial(_take, np.asarray(normals, dtype=np.float64))


def _take(normals: np.ndarray, index: np.ndarray) -> np.ndarray:
    return normals[index]


@dataclass(frozen=True)
class Observation:
    """Everything the camera saw at planning time, world frame, metres.

    views : the depth frames, one per camera placement.
    points : (N, 3) float64 observed cloud (all views back-projected, noise included, cropped to the
        workspace ``perception.camera.workspace_*``).
    point_ids : (N,) int32 object id of each point (0 = support or background).
    target_id : the id of the object to grasp.
    normals_at : estimates the normals of some of the points (:data:`NormalsAt`); read them through
        :attr:`normals` or :meth:`target`.
    """

    views: tuple[CameraView, ...]
    points: np.ndarray
    point_ids: np.ndarray
    target_id: int
    normals_at: NormalsAt = field(repr=False, compare=False)

    @functools.cached_property
    def normals(self) -> np.ndarray:
        """(N, 3) float64 unit normals estimated from the cloud, oriented towards the camera that saw each
        point (estimated at the first read)."""
        return self.normals_at(np.arange(len(self.points)))

    @functools.cached_property
    def _target(self) -> tuple[np.ndarray, np.ndarray]:
        index = np.flatnonzero(self.point_ids == self.target_id)
        normals = self.__dict__.get("normals")
        return self.points[index], (normals[index] if normals is not None else self.normals_at(index))

    def target(self) -> tuple[np.ndarray, np.ndarray]:
        """(points (M, 3), normals (M, 3)) of the target object's observed points (copies)."""
        points, normals = self._target
        return points.copy(), normals.copy()
