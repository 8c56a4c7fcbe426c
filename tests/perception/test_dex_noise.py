"""The ``dex`` depth noise model (GIGA's ``apply_dex_noise``, Jiang et al. RSS 2021): its draws match the
formula's moments (a Gamma(k, theta) factor of mean k theta = 1 and variance k theta^2; a Gaussian field of
std sigma on the grid nodes, bilinearly upsampled, so sigma times a known weight between them; added to a
share ``dex_gp_probability`` of the frames), it is a named option that the ``giga_side`` camera carries, and it
repeats for one seed."""

import dataclasses

import numpy as np
import pytest
from helpers.config import compose_cfg

from graspexp.config.perception import DEPTH_NOISE_MODELS, DepthNoiseConfig
from graspexp.perception.depth_noise import NOISE_MODELS, noisy_depth, upsample_bilinear

DEX = DepthNoiseConfig(model="dex")
DEPTH_M = 0.6
"""The exact depth of every pixel of the test frames, m (the protocol's camera distance)."""


def frames(cfg: DepthNoiseConfig, n: int, shape: tuple[int, int], seed: int = 0) -> np.ndarray:
    """(n, H, W) noisy frames of a flat exact frame at :data:`DEPTH_M`, one generator for all."""
    rng = np.random.default_rng(seed)
    depth = np.full(shape, DEPTH_M)
    ids, cos = np.ones(shape, dtype=np.int32), np.ones(shape)
    return np.stack([noisy_depth(cfg, depth, ids, cos, rng=rng)[0] for _ in range(n)]).astype(np.float64)


def test_dex_is_a_named_model_that_the_giga_side_camera_carries():
    assert "dex" in DEPTH_NOISE_MODELS and "dex" in NOISE_MODELS
    cfg = compose_cfg("perception/camera=giga_side")
    assert cfg.perception.depth_noise.model == "dex" and cfg.perception.depth_noise.enabled
    assert (DEX.dex_gamma_shape, DEX.dex_gamma_scale, DEX.dex_gp_sigma_m) == (1000.0, 0.001, 0.005)
    assert (DEX.dex_gp_downsample, DEX.dex_gp_probability) == (4.0, 0.5)  # GIGA's gp_scale, gp_rate


def test_the_multiplicative_factor_has_the_gamma_moments():
    cfg = dataclasses.replace(DEX, dex_gp_probability=0.0)
    out = frames(cfg, 4000, (4, 4))
    factor = out[:, 0, 0] / DEPTH_M
    assert np.allclose(out / DEPTH_M, factor[:, None, None], rtol=1e-6)  # one factor per frame
    k, theta = cfg.dex_gamma_shape, cfg.dex_gamma_scale
    mean, var = k * theta, k * theta**2  # 1 and 0.001
    assert abs(factor.mean() - mean) < 4 * np.sqrt(var / len(factor))
    assert factor.var() == pytest.approx(var, rel=0.1)


def test_the_additive_field_has_std_sigma_at_the_nodes_and_the_bilinear_weights_between():
    # a factor of 1 (k theta = 1, variance 1e-12) leaves the field alone; every frame gets it
    cfg = dataclasses.replace(DEX, dex_gamma_shape=1e12, dex_gamma_scale=1e-12, dex_gp_probability=1.0)
    noise = frames(cfg, 600, (48, 64)) - DEPTH_M  # a 12 x 16 grid
    assert abs(noise.mean()) < 2e-4
    # downsample 4: output pixel i lies at grid coordinate (i + 0.5) / 4 - 0.5, so between two nodes at
    # fractions 0.125 / 0.875 (weights^2 sum 0.78125) or 0.375 / 0.625 (0.53125); the border rows and
    # columns lean on the zero beyond the grid. Interior pixels: std = sigma * sqrt(a_row * a_col).
    a = np.array([0.78125 if (i % 4) in (1, 2) else 0.53125 for i in range(64)])
    expected = cfg.dex_gp_sigma_m * np.sqrt(np.outer(a[:48], a))
    inner = (slice(2, 46), slice(2, 62))
    ratio = noise.std(axis=0)[inner] / expected[inner]
    assert ratio.mean() == pytest.approx(1.0, abs=0.02) and np.abs(ratio - 1).max() < 0.2
    # the grid itself, solved back from each frame through the bilinear weights: std sigma, mean 0
    ay, ax = bilinear_weights(48, 12), bilinear_weights(64, 16)
    grids = np.linalg.pinv(ay) @ noise @ np.linalg.pinv(ax).T
    assert np.abs(ay @ grids @ ax.T - noise).max() < 1e-6  # the field is that grid, upsampled
    assert grids.std() == pytest.approx(cfg.dex_gp_sigma_m, rel=0.02) and abs(grids.mean()) < 1e-4


def bilinear_weights(n_out: int, n_in: int) -> np.ndarray:
    """(n_out, n_in) weights of 1-D linear interpolation between pixel centres, zero beyond the ends: output
    pixel i at input coordinate (i + 0.5) n_in / n_out - 0.5."""
    w = np.zeros((n_out, n_in))
    for i in range(n_out):
        x = (i + 0.5) * n_in / n_out - 0.5
        x0 = int(np.floor(x))
        for j, weight in ((x0, 1 - (x - x0)), (x0 + 1, x - x0)):
            if 0 <= j < n_in:
                w[i, j] = weight
    return w


def test_the_field_is_added_to_its_share_of_the_frames():
    cfg = dataclasses.replace(DEX, dex_gamma_shape=1e12, dex_gamma_scale=1e-12)
    out = frames(cfg, 2000, (8, 8))
    with_field = np.abs(out - DEPTH_M).max(axis=(1, 2)) > 1e-5
    assert with_field.mean() == pytest.approx(cfg.dex_gp_probability, abs=0.05)


def test_pixels_without_a_return_stay_without_and_the_frame_repeats_for_one_seed():
    depth = np.full((40, 40), DEPTH_M)
    depth[:, :10] = 0.0
    ids, cos = np.full((40, 40), 3, dtype=np.int32), np.ones((40, 40))
    a = noisy_depth(DEX, depth, ids, cos, rng=np.random.default_rng(7))
    b = noisy_depth(DEX, depth, ids, cos, rng=np.random.default_rng(7))
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    assert a[0].dtype == np.float32 and a[1].dtype == np.int32
    assert np.all(a[0][:, :10] == 0) and np.all(a[1][:, :10] == 0)
    assert np.all(a[0][:, 10:] > 0) and np.all(a[1][:, 10:] == 3)


def test_the_upsampling_is_bilinear_between_pixel_centres_with_zero_beyond_the_grid():
    grid = np.random.default_rng(0).standard_normal((3, 5))
    out = upsample_bilinear(grid, (12, 20))
    padded = np.pad(grid, 1)

    def at(y: float, x: float) -> float:
        y0, x0 = int(np.floor(y)), int(np.floor(x))
        fy, fx = y - y0, x - x0
        v = padded[y0 + 1 : y0 + 3, x0 + 1 : x0 + 3]
        return (1 - fy) * ((1 - fx) * v[0, 0] + fx * v[0, 1]) + fy * ((1 - fx) * v[1, 0] + fx * v[1, 1])

    want = [[at((i + 0.5) * 3 / 12 - 0.5, (j + 0.5) * 5 / 20 - 0.5) for j in range(20)] for i in range(12)]
    assert np.allclose(out, want, atol=1e-12)
