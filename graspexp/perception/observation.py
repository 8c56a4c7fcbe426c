"""What a depth camera gave the planner: the views (depth, per-pixel object ids, calibration) and the
observed cloud built from them. Plain frozen dataclasses of numpy arrays: the planning stage reads them
without importing the camera, the ray caster or the registration library."""

from dataclasses import dataclass

import numpy as np


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


@dataclass(frozen=True)
class Observation:
    """Everything the camera saw at planning time, world frame, metres.

    views : the depth frames, one per camera placement.
    points : (N, 3) float64 observed cloud (all views back-projected, noise included, cropped to the
        workspace ``perception.camera.workspace_*``).
    normals : (N, 3) float64 unit normals estimated from the cloud, oriented towards the camera that saw
        each point.
    point_ids : (N,) int32 object id of each point (0 = support or background).
    target_id : the id of the object to grasp.
    """

    views: tuple[CameraView, ...]
    points: np.ndarray
    normals: np.ndarray
    point_ids: np.ndarray
    target_id: int

    def target(self) -> tuple[np.ndarray, np.ndarray]:
        """(points (M, 3), normals (M, 3)) of the target object's observed points."""
        mask = self.point_ids == self.target_id
        return self.points[mask], self.normals[mask]
