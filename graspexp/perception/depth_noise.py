"""Depth noise models, applied to an exact ray-cast frame: :func:`noisy_depth` dispatches by name
(``perception.depth_noise.model``) to a function of :data:`NOISE_MODELS`. A new model is one function
registered with :func:`noise_model` and its name in :data:`graspexp.config.perception.DEPTH_NOISE_MODELS`
(and its coefficients, if new, in :class:`graspexp.config.perception.DepthNoiseConfig`).

``nguyen`` (:func:`nguyen_noise`): the model of Nguyen, Izadi & Lovell, "Modeling Kinect Sensor Noise for
Improved 3D Reconstruction and Tracking" (3DIMPVT 2012), plus missing pixels at grazing angles and depth
edges. Order: (1) pixels beyond ``max_incidence_deg`` lose their return; (2) lateral noise: each pixel takes
the return (depth, id, angle) of the pixel offset by a Gaussian (du, dv) of std ``sigma_L(theta)`` px,
rounded; (3) axial noise: Gaussian of std ``sigma_z(z, theta)`` added to the depth; (4) pixels whose depth
differs from a 4-neighbour's by more than ``edge_jump_m`` (or that border a pixel without return) lose their
return. All draws come from the ``rng`` passed in (seeded per trial).

``dex`` (:func:`dex_noise`): the noise of GIGA's simulated clutter benchmark (Jiang et al., RSS 2021,
``apply_dex_noise`` in supersglzc/GIGA ``src/vgn/utils/misc.py``): the frame's depth times one Gamma factor,
then, in a share of the frames, plus a Gaussian field drawn on a coarse grid and bilinearly upsampled. Draws,
in GIGA's order: the factor, one uniform (whether the field is added), the grid's normals (only when it is).
"""

from collections.abc import Callable

import numpy as np
from scipy import ndimage

from graspexp.config.perception import DepthNoiseConfig

NoiseModel = Callable[..., tuple[np.ndarray, np.ndarray]]
"""``model(cfg, depth_m, ids, cos_incidence, *, rng) -> (depth, ids)``: the sensor's frame from an exact one
(``depth_m`` (H, W) float64 m, 0 = no return; ``ids`` (H, W); ``cos_incidence`` (H, W) cosine of the angle
between ray and surface normal) as :func:`noisy_depth` returns it; every draw from ``rng``."""
NOISE_MODELS: dict[str, NoiseModel] = {}
"""The depth noise models by name (``perception.depth_noise.model``), filled by :func:`noise_model`."""


def noise_model(name: str) -> Callable[[NoiseModel], NoiseModel]:
    """Register the decorated function as the depth noise model ``name``."""

    def register(fn: NoiseModel) -> NoiseModel:
        NOISE_MODELS[name] = fn
        return fn

    return register


def axial_sigma_m(cfg: DepthNoiseConfig, z_m: np.ndarray, theta_rad: np.ndarray) -> np.ndarray:
    """Nguyen et al. 2012 Eq. (1): std of the depth along the ray, m, at depth ``z_m`` (m) and incidence
    ``theta_rad`` (angle between ray and surface normal, rad, < pi/2)."""
    z = np.asarray(z_m, dtype=np.float64)
    th = np.asarray(theta_rad, dtype=np.float64)
    grazing = th**2 / (np.pi / 2 - th) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        angle_term = np.where(z > 0, cfg.axial_c_m / np.sqrt(np.maximum(z, 1e-12)) * grazing, 0.0)
    return cfg.axial_a_m + cfg.axial_b_m * (z - cfg.axial_z0_m) ** 2 + angle_term


def lateral_sigma_px(cfg: DepthNoiseConfig, theta_rad: np.ndarray) -> np.ndarray:
    """Nguyen et al. 2012 Eq. (2): lateral std, px, at incidence ``theta_rad`` (rad, < pi/2)."""
    th = np.asarray(theta_rad, dtype=np.float64)
    return cfg.lateral_px + cfg.lateral_angle_px * th / (np.pi / 2 - th)


def noisy_depth(
    cfg: DepthNoiseConfig,
    depth_m: np.ndarray,
    ids: np.ndarray,
    cos_incidence: np.ndarray,
    *,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray]:
    """The sensor's frame from an exact one through the model ``cfg.model`` (module doc): (depth (H, W)
    float32 m, 0 = no return; ids (H, W) int32, 0 where there is no return). ``cfg.enabled`` False: the
    exact frame as float32."""
    depth = np.asarray(depth_m, dtype=np.float64)
    if not cfg.enabled:
        return depth.astype(np.float32), np.where(depth > 0, ids, 0).astype(np.int32)
    return NOISE_MODELS[cfg.model](cfg, depth, ids, cos_incidence, rng=rng)


@noise_model("nguyen")
def nguyen_noise(
    cfg: DepthNoiseConfig,
    depth: np.ndarray,
    ids: np.ndarray,
    cos_incidence: np.ndarray,
    *,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray]:
    """Nguyen et al. 2012's noise (module doc, steps 1-4) on the exact frame ``depth`` (float64 m)."""
    h, w = depth.shape
    theta = np.arccos(np.clip(cos_incidence, 0.0, 1.0))
    valid = (depth > 0) & (theta <= np.radians(cfg.max_incidence_deg))
    theta = np.where(valid, np.minimum(theta, np.radians(89.9)), 0.0)
    depth = np.where(valid, depth, 0.0)

    sigma_l = lateral_sigma_px(cfg, theta)
    du = np.rint(rng.standard_normal((h, w), dtype=np.float32) * sigma_l).astype(np.int64)
    dv = np.rint(rng.standard_normal((h, w), dtype=np.float32) * sigma_l).astype(np.int64)
    src_v = np.clip(np.arange(h)[:, None] + dv, 0, h - 1)
    src_u = np.clip(np.arange(w)[None, :] + du, 0, w - 1)
    src = (src_v * w + src_u).ravel()
    depth = depth.ravel()[src].reshape(h, w)
    ids = np.asarray(ids).ravel()[src].reshape(h, w)
    theta = theta.ravel()[src].reshape(h, w)

    draw = rng.standard_normal((h, w), dtype=np.float32)
    out = np.zeros((h, w))
    ret = depth > 0
    out[ret] = depth[ret] + draw[ret] * axial_sigma_m(cfg, depth[ret], theta[ret])

    edge = np.zeros((h, w), dtype=bool)
    for a, b in ((out[1:, :], out[:-1, :]), (out[:, 1:], out[:, :-1])):
        jump = np.abs(a - b) > cfg.edge_jump_m
        if a.shape[0] < h:
            edge[1:, :] |= jump
            edge[:-1, :] |= jump
        else:
            edge[:, 1:] |= jump
            edge[:, :-1] |= jump
    out = np.where(edge | (out <= 0), 0.0, out)
    return out.astype(np.float32), np.where(out > 0, ids, 0).astype(np.int32)


def upsample_bilinear(grid: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """``grid`` (h, w) resized to ``shape`` (H, W) by bilinear interpolation between pixel centres, zero beyond
    the grid's edge: what ``skimage.transform.resize(grid, shape, order=1, mode="constant",
    anti_aliasing=False)`` returns (scipy's zoom in grid mode, as scikit-image calls it)."""
    zoom = (shape[0] / grid.shape[0], shape[1] / grid.shape[1])
    out = ndimage.zoom(grid, zoom, order=1, mode="grid-constant", cval=0.0, grid_mode=True)
    if out.shape != tuple(shape):
        raise ValueError(f"upsampling {grid.shape} to {shape} gave {out.shape}")
    return out


@noise_model("dex")
def dex_noise(
    cfg: DepthNoiseConfig,
    depth: np.ndarray,
    ids: np.ndarray,
    cos_incidence: np.ndarray,
    *,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray]:
    """GIGA's dex noise (module doc) on the exact frame ``depth`` (float64 m): ``depth * g`` with ``g ~
    Gamma(dex_gamma_shape, dex_gamma_scale)`` one factor for the frame, then with probability
    ``dex_gp_probability`` plus ``dex_gp_sigma_m`` times a standard normal grid of int(H / d) x int(W / d)
    nodes (``d = dex_gp_downsample``) upsampled bilinearly (:func:`upsample_bilinear`). Pixels without a
    return keep none; a depth pushed to 0 or below returns nothing."""
    h, w = depth.shape
    ret = depth > 0
    out = depth * rng.gamma(cfg.dex_gamma_shape, cfg.dex_gamma_scale)
    if rng.random() < cfg.dex_gp_probability:
        d = float(cfg.dex_gp_downsample)
        grid = rng.standard_normal((max(1, int(h / d)), max(1, int(w / d)))) * cfg.dex_gp_sigma_m
        out = out + upsample_bilinear(grid, (h, w))
    out = np.where(ret & (out > 0), out, 0.0)
    return out.astype(np.float32), np.where(out > 0, ids, 0).astype(np.int32)
