"""Schema of ``perception``: what the planner is told about the object (the exact pose, or a pose
registered from a simulated depth camera) and the camera itself (``perception/camera`` group, preset
``d435``), its depth noise model and the registration. A camera preset sets ``perception.camera`` and,
when the sensor has its own, ``perception.depth_noise``: a new camera is one YAML file.

The camera is a CPU ray caster (trimesh + Embree through the ``embreex`` package): SAPIEN's own camera
needs a Vulkan device, which the CPU-only machines this project runs on lack (Debian 12's Mesa lavapipe
is too old for SAPIEN 3's renderer). Registration uses Open3D. Both come with the ``camera`` extra
(``pip install 'graspexp[camera]'``); :func:`missing_camera_extra` names what is absent.
"""

import importlib.util
from dataclasses import dataclass, field

from graspexp.config.constraints import BOOL, TEXT, Interval, Options, Vector

SOURCES = ("truth", "depth")
"""Values of ``perception.source``."""
PRIORS = ("noisy_truth", "none")
"""Values of ``perception.registration.prior``."""
DEPTH_NOISE_MODELS = ("nguyen", "dex")
"""Values of ``perception.depth_noise.model``: the noise models the perception stage implements, each a
function registered under its name (:data:`graspexp.perception.depth_noise.NOISE_MODELS`)."""
CAMERA_EXTRA = "pip install 'graspexp[camera]'"
"""The command that installs the camera's packages (embreex, open3d-cpu)."""
CAMERA_MODULES = {"embreex": "embreex", "open3d": "open3d-cpu"}
"""Importable module -> the package that provides it."""


def missing_camera_extra() -> list[str]:
    """The camera extra's packages that are not installed ([] when all are)."""
    return [pkg for mod, pkg in CAMERA_MODULES.items() if importlib.util.find_spec(mod) is None]


@dataclass
class PoseNoiseConfig:
    trans_mm: float = 0.0
    """Std-dev of the Gaussian translation error added to the pose the planner sees, mm. With
    ``perception.source=depth`` it perturbs the prior the registration starts from (a learned estimator's
    output, refined by ICP) instead."""
    rot_deg: float = 0.0
    """Std-dev of the rotation-angle error (random axis) added to that pose, degrees (the prior's too, as
    ``trans_mm``)."""


@dataclass
class CameraConfig:
    """A pinhole depth camera looking at the support from one or more placements."""

    name: str = "d435"
    """The sensor the preset models (``d435``: Intel RealSense D435). The schema's defaults are that
    preset's values (a log written before the key existed reads back with them)."""
    width_px: int = 424
    """Image width, px (424 x 240 is one of the D435's depth modes; 1280 x 720 is its largest)."""
    height_px: int = 240
    """Image height, px."""
    fx_px: float = 223.4
    """Focal length along x, px: (width / 2) / tan(87 deg / 2), the D435's depth field of view of
    87 x 58 deg (+-3 deg) in Intel's RealSense D400 series datasheet."""
    fy_px: float = 223.4
    """Focal length along y, px (square pixels: a vertical field of view of 56.5 deg, inside the
    datasheet's 58 +- 3 deg)."""
    cx_px: float = 211.5
    """Principal point x, px (pixel centres at integer coordinates, OpenCV convention: the image
    centre)."""
    cy_px: float = 119.5
    """Principal point y, px."""
    min_range_m: float = 0.1
    """Nearest depth the sensor returns, m (the datasheet's Min-Z is 0.28 m at 1280 x 720 and shrinks
    with the resolution)."""
    max_range_m: float = 3.0
    """Farthest depth the sensor returns, m (the datasheet's ideal range ends at 3 m)."""
    distance_m: float = 0.6
    """Distance from the camera to the point it looks at, m (the issue's 0.5-0.7 m for a D435 over a
    table)."""
    elevation_deg: float = 45.0
    """Angle of the line of sight below the horizontal, degrees (90: straight down is excluded, the
    camera's up direction would be undefined)."""
    azimuths_deg: list[float] = field(default_factory=lambda: [0.0])
    """One view per entry: the camera's direction from the look-at point about world +Z, degrees
    (``[0, 180]``: two views from opposite sides)."""
    look_at_height_m: float = 0.05
    """Height of the look-at point above the centre of the support top, m."""
    workspace_half_m: float = 0.15
    """The observed cloud keeps the points within this of the look-at point in x and y, m (a 30 cm
    workspace, as VGN's; the depth images keep every pixel)."""
    workspace_top_m: float = 0.35
    """... and below this height above the support top, m."""


@dataclass
class DepthNoiseConfig:
    """The camera's depth noise: a model by name (``model``) and its coefficients. A camera preset
    (``conf/perception/camera/<name>.yaml``) may carry its own under ``depth_noise:``.

    ``nguyen``: Nguyen, Izadi & Lovell, "Modeling Kinect Sensor Noise for Improved 3D
    Reconstruction and Tracking", 3DIMPVT 2012, Eq. (1)-(2): axial
    ``sigma_z(z, theta) = a + b (z - z0)^2 + c / sqrt(z) * theta^2 / (pi/2 - theta)^2`` m and lateral
    ``sigma_L(theta) = l0 + l1 * theta / (pi/2 - theta)`` px (z depth in m, theta the angle between the ray
    and the surface normal, rad). Their coefficients are the defaults; a structured-light Kinect's noise
    grows with z^2 as a stereo D435's does (its RMS error is about 2 % of the depth at 2 m in Intel's
    datasheet). Missing pixels: beyond ``max_incidence_deg`` and at depth edges.

    ``dex``: the depth noise of GIGA's simulated benchmark (Jiang et al., "Synergies Between Affordance and
    Geometry: 6-DoF Grasp Detection via Implicit Representations", RSS 2021; ``apply_dex_noise`` in
    supersglzc/GIGA ``src/vgn/utils/misc.py``, after Dex-Net's depth noise): the frame's depth times one
    Gamma(k, theta) factor, then, with probability ``dex_gp_probability``, plus a Gaussian field of std
    ``dex_gp_sigma_m`` drawn on a grid ``dex_gp_downsample`` times coarser than the image and bilinearly
    upsampled (zero beyond the grid's edge). No pixel goes missing."""

    enabled: bool = True
    """False: exact depth (no noise, no missing pixels but out-of-range ones)."""
    model: str = "nguyen"
    """The noise model (:mod:`graspexp.perception.depth_noise`): ``nguyen``, Nguyen et al. 2012's axial and
    lateral noise with the coefficients below; ``dex``, GIGA's (the ``dex_*`` coefficients)."""
    axial_a_m: float = 0.0012
    """a, m (Nguyen et al. 2012)."""
    axial_b_m: float = 0.0019
    """b, 1/m (m of noise per m^2 of depth offset)."""
    axial_z0_m: float = 0.4
    """z0, m."""
    axial_c_m: float = 0.0001
    """c, m^1.5 (the incidence term)."""
    lateral_px: float = 0.8
    """l0, px: each pixel takes the depth of a neighbour drawn from N(0, sigma_L^2) in u and v."""
    lateral_angle_px: float = 0.035
    """l1, px."""
    max_incidence_deg: float = 80.0
    """Pixels whose ray meets the surface at more than this from its normal return nothing (grazing
    angles: Nguyen et al. fit their model up to 70-80 degrees), degrees."""
    edge_jump_m: float = 0.02
    """A pixel whose 4-neighbour depth differs by more than this returns nothing (stereo matching fails
    at depth discontinuities), m."""
    dex_gamma_shape: float = 1000.0
    """``dex``: shape k of the Gamma distribution of the frame's multiplicative depth factor (GIGA's
    ``gamma_shape``: mean k theta = 1, std sqrt(k) theta = 3.2 %)."""
    dex_gamma_scale: float = 0.001
    """``dex``: scale theta of that Gamma distribution (GIGA's ``gamma_scale``)."""
    dex_gp_sigma_m: float = 0.005
    """``dex``: std of the additive Gaussian field at its grid nodes, m (GIGA's ``gp_sigma``; between the
    nodes the bilinear upsampling averages them: 0.53-0.78 of this per pixel)."""
    dex_gp_downsample: float = 4.0
    """``dex``: the field's grid has int(H / this) x int(W / this) nodes (GIGA's ``gp_scale``: 120 x 160 for
    640 x 480)."""
    dex_gp_probability: float = 0.5
    """``dex``: probability that a frame gets the additive field (GIGA's ``gp_rate``; the multiplicative
    factor applies to every frame)."""


@dataclass
class RegistrationConfig:
    """Pose registration with Open3D (point-to-plane ICP; FPFH + RANSAC without a prior)."""

    prior: str = "noisy_truth"
    """``noisy_truth``: ICP from the true pose perturbed by ``perception.noise.*`` (a learned estimator's
    output, refined); ``none``: global registration (FPFH features + RANSAC) then ICP."""
    model_points: int = 400
    """Model points ICP aligns (drawn from the object's cloud, seeded); fewer is faster."""
    visible_only: bool = True
    """With a prior: only model points whose normal faces a camera at the prior pose (the far side
    cannot match anything the camera saw)."""
    max_correspondence_m: float = 0.015
    """ICP's correspondence distance, m (larger than the prior's error at the object's surface)."""
    max_iterations: int = 30
    """Most ICP iterations (Open3D's default; ICP stops earlier once fitness and RMSE change by less than
    1e-6, relative). Not lowered for speed: ICP is a few ms of the per-plan cost (``bench.registration``),
    the depth frame most of it."""
    normal_neighbours: int = 20
    """Neighbours of each observed point used to estimate its normal."""
    normal_radius_m: float = 0.01
    """... within this radius, m."""
    global_voxel_m: float = 0.005
    """Voxel size of the clouds FPFH features are computed on, m (global registration)."""
    ransac_iterations: int = 100_000
    """RANSAC iterations of the global registration."""
    min_target_points: int = 6
    """Fewest points of the target the camera must see (after the workspace crop) for a registration to be
    tried; fewer: the trial (or the clutter object) ends ``registration_failed``. 6: point-to-plane ICP
    solves for six unknowns (three of rotation, three of translation) from one equation per point, so fewer
    points leave the pose undetermined (global registration's RANSAC draws 3)."""
    min_inliers: int = 6
    """Fewest model points ICP's result aligns with an observed point within ``max_correspondence_m``
    (fitness x the model points ICP used); fewer: ``registration_failed``. 6, as ``min_target_points``: ICP's
    last step solved for the pose from these correspondences alone. At least 1: a fitness of 0 (no
    correspondence at all: nothing the camera saw is where the registered model is) always fails."""
    min_fitness: float = 0.0
    """Lowest share of the model points ICP used that found a correspondence (Open3D's fitness, in [0, 1]);
    below: ``registration_failed``. 0: no share is asked beyond ``min_inliers``, because a correct pose's
    share falls with what hides the object from the camera (its own parts; neighbours in a clutter pile),
    which says nothing of the pose; raise it to refuse poses fitted to a sliver of the object."""
    centroid_margin_m: float = 0.015
    """The registered pose fails (``registration_failed``) when the centroid of the target's observed points
    lies farther from the registered model's centroid than the model's radius (its farthest point from its
    centroid) plus this, m. Every point the camera sees of a correctly posed object lies on its surface, hence
    within that radius of its centroid, and so does their mean: a correct pose never fails; a pose that left
    the observed points behind (global registration or ICP converged on nothing, the identity) does. The
    margin covers the depth noise and a correspondence's residual: ``max_correspondence_m``'s default."""


@dataclass
class PerceptionConfig:
    source: str = "truth"
    """``truth``: the planner gets the exact pose plus ``noise`` (the paper's experiments); ``depth``: the
    pose registered from the simulated depth camera's view."""
    noise: PoseNoiseConfig = field(default_factory=PoseNoiseConfig)
    camera: CameraConfig = field(default_factory=CameraConfig)
    """The camera: a ``perception/camera`` option (``d435``), which sets ``camera`` and may set
    ``depth_noise``."""
    depth_noise: DepthNoiseConfig = field(default_factory=DepthNoiseConfig)
    """The camera's depth noise: its preset's, else the schema's defaults (the ``nguyen`` model)."""
    registration: RegistrationConfig = field(default_factory=RegistrationConfig)


POSE_NOISE_CONSTRAINTS = {
    "trans_mm": [Interval(0, 1000, unit="mm")],
    "rot_deg": [Interval(0, 180, unit="deg")],
}
"""Allowed values of every ``perception.noise`` key (see :mod:`graspexp.config.constraints`)."""

CAMERA_CONSTRAINTS = {
    "name": TEXT,
    "width_px": [Interval(8, 4096, integer=True)],
    "height_px": [Interval(8, 4096, integer=True)],
    "fx_px": [Interval(0, 100_000, "neither", "px")],
    "fy_px": [Interval(0, 100_000, "neither", "px")],
    "cx_px": [Interval(-10_000, 10_000, unit="px")],
    "cy_px": [Interval(-10_000, 10_000, unit="px")],
    "min_range_m": [Interval(0, 100, unit="m")],
    "max_range_m": [Interval(0, 100, "right", "m")],
    "distance_m": [Interval(0, 10, "right", "m")],
    "elevation_deg": [Interval(0, 90, "right", "deg")],
    "azimuths_deg": [Vector(None, Interval(-360, 360, unit="deg"))],
    "look_at_height_m": [Interval(-1, 2, unit="m")],
    "workspace_half_m": [Interval(0, 5, "right", "m")],
    "workspace_top_m": [Interval(0, 5, "right", "m")],
}
DEPTH_NOISE_CONSTRAINTS = {
    "enabled": BOOL,
    "model": [Options(DEPTH_NOISE_MODELS)],
    "axial_a_m": [Interval(0, 1, unit="m")],
    "axial_b_m": [Interval(0, 1)],
    "axial_z0_m": [Interval(0, 10, unit="m")],
    "axial_c_m": [Interval(0, 1)],
    "lateral_px": [Interval(0, 20, unit="px")],
    "lateral_angle_px": [Interval(0, 20, unit="px")],
    "max_incidence_deg": [Interval(0, 90, unit="deg")],
    "edge_jump_m": [Interval(0, 10, "right", "m")],
    "dex_gamma_shape": [Interval(0, None, "neither")],
    "dex_gamma_scale": [Interval(0, None, "neither")],
    "dex_gp_sigma_m": [Interval(0, 1, unit="m")],
    "dex_gp_downsample": [Interval(1, 1000)],
    "dex_gp_probability": [Interval(0, 1)],
}
REGISTRATION_CONSTRAINTS = {
    "prior": [Options(PRIORS)],
    "model_points": [Interval(10, 1_000_000, integer=True)],
    "visible_only": BOOL,
    "max_correspondence_m": [Interval(0, 1, "right", "m")],
    "max_iterations": [Interval(1, 10_000, integer=True)],
    "normal_neighbours": [Interval(3, 1000, integer=True)],
    "normal_radius_m": [Interval(0, 1, "right", "m")],
    "global_voxel_m": [Interval(0, 1, "right", "m")],
    "ransac_iterations": [Interval(1, 100_000_000, integer=True)],
    "min_target_points": [Interval(3, None, integer=True)],
    "min_inliers": [Interval(1, None, integer=True)],
    "min_fitness": [Interval(0, 1)],
    "centroid_margin_m": [Interval(0, 10, unit="m")],
}
PERCEPTION_CONSTRAINTS = {"source": [Options(SOURCES)]}
"""Allowed values of every ``perception`` key (see :mod:`graspexp.config.constraints`)."""
