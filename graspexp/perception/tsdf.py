"""The camera's depth views (:class:`graspexp.perception.observation.CameraView`) fused into a truncated
signed distance grid with Open3D's ``UniformTSDFVolume``, for volumetric planners; encoded as VGN's network
input (Breyer et al., CoRL 2020, Sec. III-A: a 40^3 TSDF of a 30 cm cube, truncated at four voxels).

Encoding (what VGN's training data holds): a voxel that the views saw within the truncation distance
holds ``(tsdf + 1) / 2`` in (0.01, 0.99), 0.5 on the surface, above 0.5 in front of it (free space towards
a camera), below 0.5 behind it; every other voxel (unseen, or farther than the truncation from any
surface) holds 0. Voxel (i, j, k) covers [i, i + 1) x [j, j + 1) x [k, k + 1) voxel lengths of the
workspace frame; its value is the distance at its centre.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import open3d as o3d

from graspexp.perception.observation import CameraView

TRUNCATION_VOXELS = 4.0
"""Truncation distance of the signed distance, in voxel lengths (VGN's: 4 x 7.5 mm = 3 cm)."""
SEEN_LIMIT = 0.98
"""A voxel whose normalised |tsdf| reaches this counts as not near a surface (Open3D's voxel cloud test)."""


def fuse(
    views: Sequence[CameraView],
    world_from_volume: np.ndarray,
    size_m: float,
    resolution: int,
    depth_max_m: float,
) -> np.ndarray:
    """(resolution,)*3 float32 grid, indexed [i, j, k] along x, y, z of the volume frame, in the encoding
    above, of the ``size_m`` cube whose corner is ``world_from_volume``'s origin (axes along its x, y, z),
    fused from the camera's ``views`` (their depth, intrinsics and pose; the ids are not read). Depths
    beyond ``depth_max_m`` are left out (Open3D's depth truncation)."""
    voxel = size_m / resolution
    volume = o3d.pipelines.integration.UniformTSDFVolume(
        length=size_m,
        resolution=resolution,
        sdf_trunc=TRUNCATION_VOXELS * voxel,
        color_type=o3d.pipelines.integration.TSDFVolumeColorType.NoColor,
    )
    for view in views:
        depth = np.ascontiguousarray(view.depth, dtype=np.float32)
        h, w = depth.shape
        rgbd = o3d.geometry.RGBDImage.create_from_color_and_depth(
            o3d.geometry.Image(np.zeros_like(depth)),
            o3d.geometry.Image(depth),
            depth_scale=1.0,
            depth_trunc=depth_max_m,
            convert_rgb_to_intensity=False,
        )
        K = np.asarray(view.K, dtype=np.float64)
        intrinsic = o3d.camera.PinholeCameraIntrinsic(w, h, K[0, 0], K[1, 1], K[0, 2], K[1, 2])
        camera_from_volume = np.linalg.inv(np.asarray(view.world_from_camera, np.float64)) @ world_from_volume
        volume.integrate(rgbd, intrinsic, camera_from_volume)
    # (tsdf, weight) of voxel (x, y, z) at row (x * res + y) * res + z: C order [x, y, z]
    tsdf_weight = np.asarray(volume.extract_volume_tsdf()).reshape(resolution, resolution, resolution, 2)
    tsdf, weight = tsdf_weight[..., 0], tsdf_weight[..., 1]
    seen = (weight > 0) & (np.abs(tsdf) < SEEN_LIMIT)
    return np.where(seen, (tsdf + 1.0) * 0.5, 0.0).astype(np.float32)
