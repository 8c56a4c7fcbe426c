"""``planner=giga``: grasps from GIGA (Jiang et al., RSS 2021) on the camera's depth views, through VGN's pre-
and post-processing (:mod:`graspexp.planning.learned.vgn`), which GIGA shares.

1. Workspace and TSDF: VGN's (GIGA keeps VGN's 30 cm cube, 40^3 grid and encoding;
   :mod:`graspexp.perception.tsdf`), the one volume per clutter scene included.
2. One forward pass (:mod:`graspexp.planning.learned.giga_network`): the encoder on the grid, the grasp
   decoders queried at every voxel (i, j, k) (GIGA's ``VGNImplicit``: the point (i, j, k) voxel lengths from
   the volume's corner, where VGN places the grasp of that voxel), giving VGN's outputs: a quality, a grasp
   orientation and a width per voxel.
3. VGN's detection (:func:`graspexp.planning.learned.vgn.detect`: GIGA's ``process``, ``bound`` and
   ``select`` are VGN's chain with the wall margin and the forced candidate), VGN's frames, target
   assignment and choice.

GIGA's grasp frame, voxel placement and quaternion order are VGN's (its simulation is VGN's); its width is
a fraction of the workspace's edge (converted to voxels here).
"""

from __future__ import annotations

import functools

import numpy as np
import torch

from graspexp.config.planner.giga import GIGA_CHECKPOINTS, GigaConfig
from graspexp.planning.learned import vgn
from graspexp.planning.learned.giga_network import GRID, GigaNet, load_giga, voxel_queries
from graspexp.planning.request import PlanRequest, PlanResult
from graspexp.planning.scene import SceneRequest, SceneResult


@functools.cache
def network(checkpoint: str = "giga_pile") -> GigaNet:
    """The network with the weights ``checkpoint`` names (``planner.checkpoint``), read and verified once
    per process."""
    return load_giga(GIGA_CHECKPOINTS[checkpoint])


def infer(net: GigaNet, grid: np.ndarray, threads: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One forward pass on a (40, 40, 40) float32 TSDF, queried at every voxel: quality (40, 40, 40),
    quaternions (4, 40, 40, 40) (x, y, z, w), widths (40, 40, 40) in voxels (float64: the network's width,
    a fraction of the workspace's edge, times :data:`GRID`); float32 otherwise."""
    with vgn.torch_threads(threads):
        tsdf = torch.from_numpy(np.ascontiguousarray(grid, np.float32))[None]
        q, r, w = net(tsdf, voxel_queries(GRID))
    shape = (GRID, GRID, GRID)
    quality = q[0].numpy().reshape(shape)
    rotation = np.moveaxis(r[0].numpy().reshape((*shape, 4)), -1, 0)
    return quality, rotation, w[0].numpy().reshape(shape).astype(np.float64) * GRID


def giga_outputs(grid: np.ndarray, cfg: GigaConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """GIGA's forward pass with the weights of ``cfg.checkpoint`` on ``cfg.threads`` threads (:func:`infer`):
    VGN's outputs (:data:`graspexp.planning.learned.vgn.Outputs`)."""
    return infer(network(cfg.checkpoint), grid, cfg.threads)


def plan_giga(req: PlanRequest) -> PlanResult:
    """The grasp GIGA detects on the target in the request's camera observation, in a volume centred on the
    target's observed points (VGN's, :func:`graspexp.planning.learned.vgn.plan_in_volume`); NoFeasibleGrasp
    (one line) when the request has no observation, the camera saw no target point, or no candidate holds
    it."""
    return vgn.plan_in_volume(req, giga_outputs)


def plan_giga_scene(req: SceneRequest) -> SceneResult:
    """GIGA's clutter removal (VGN's: :func:`graspexp.planning.learned.vgn.plan_scene_in_volume`): one fixed
    volume on the mode's workspace, fused and inferred once for the scene, each candidate assigned to the
    object it holds."""
    return vgn.plan_scene_in_volume(req, giga_outputs)
