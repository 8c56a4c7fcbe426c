"""GIGA's network (Jiang, Zhu, Wang, Zhu, Chen, Zhou, Bohg, Zhu, "Synergies Between Affordance and Geometry",
RSS 2021, Sec. IV), written here with parameter names that match the published ``giga_pile.pt`` and
``giga_packed.pt`` state dicts (164 tensors), and its loading. Read from the authors' code (UT-Austin-RPL/GIGA
``src/vgn/networks.py`` ``GIGA``, ``src/vgn/ConvONets/``: ``LocalVoxelEncoder``, ``UNet``, ``LocalDecoder``),
not copied; ``torch_scatter.scatter_mean`` is :func:`scatter_mean` here, in plain torch.

Input: (B, 40, 40, 40) float32 TSDF grid (VGN's encoding, axes x, y, z of the workspace frame) and (B, N, 3)
query points in the unit cube's coordinates, [-0.5, 0.5) per axis (a workspace point at ``p`` metres from
the volume's corner is ``p / 0.3 - 0.5``). Output per query point: grasp quality (B, N) in [0, 1], orientation
(B, N, 4) unit quaternion (x, y, z, w) of the grasp frame in the workspace frame, opening width (B, N) in
units of the workspace's edge (0.3 m).

1. Encoder: a 3-D convolution (1 -> 32 channels, ReLU) on the grid; each voxel's feature is averaged onto
   three 40 x 40 feature planes (xz, xy, yz; a voxel's plane cell from its coordinates in [-0.5, 0.5]) and
   each plane goes through one shared 2-D U-Net (depth 3, 32 -> 64 -> 128 channels, transposed-convolution
   up-sampling, skip connections concatenated).
2. Decoders: the planes are sampled bilinearly at each query point (border padding, corners aligned), the
   three 32-channel features concatenated (96); an MLP of five ResNet blocks (32 wide), each fed the point's
   coordinates (``fc_p``) and the feature (``fc_c``), one per head: quality (sigmoid), rotation (normalised),
   width, and the scene's TSDF (trained with the others, unused for grasping).
"""

from __future__ import annotations

import io

import torch
from torch import nn
from torch.nn import functional as F

from graspexp.core.checkpoints import Checkpoint, read_verified

GRID = 40
"""Voxels per side of the input grid, and cells per side of each feature plane."""
FEATURES = 32
"""Channels of the voxel features and of each feature plane (GIGA's ``c_dim``)."""
HIDDEN = 32
"""Width of the decoders' MLP (GIGA's ``hidden_size``)."""
BLOCKS = 5
"""ResNet blocks per decoder (ConvONet's ``LocalDecoder`` default ``n_blocks``)."""
PLANES = ("xz", "xy", "yz")
"""The feature planes, in the order the decoders concatenate them; each keeps two of the axes (x, y, z)."""
AXES = {"xz": (0, 2), "xy": (0, 1), "yz": (1, 2)}
"""Coordinate axes of each plane: (column, row) of its 40 x 40 grid."""
PLANE_EPS = 10e-6
"""ConvONet's ``normalize_coordinate`` (padding 0): a coordinate in [-0.5, 0.5] maps to
``c / (1 + PLANE_EPS) + 0.5``, kept in [0, 1 - PLANE_EPS]."""


def scatter_mean(src: torch.Tensor, index: torch.Tensor, size: int) -> torch.Tensor:
    """(B, C, size): the mean of the columns of ``src`` (B, C, N) that ``index`` (B, N) int64 sends to each
    of ``size`` cells, 0 where none is sent (``torch_scatter.scatter_mean`` into a zero ``out``). Sums in
    index order (``index_add_``): the same inputs give the same bits."""
    b, c, n = src.shape
    total = src.new_zeros(b, c, size)
    count = src.new_zeros(b, 1, size)
    ones = src.new_ones(1, n)
    for i in range(b):
        total[i].index_add_(1, index[i], src[i])
        count[i].index_add_(1, index[i], ones)
    return total / count.clamp(min=1)


def plane_coordinates(p: torch.Tensor, plane: str) -> torch.Tensor:
    """(B, N, 2) the points ``p`` (B, N, 3), unit-cube coordinates, on ``plane`` in [0, 1)."""
    xy = p[:, :, list(AXES[plane])] / (1 + PLANE_EPS) + 0.5
    xy = torch.where(xy >= 1, torch.full_like(xy, 1 - PLANE_EPS), xy)
    return torch.where(xy < 0, torch.zeros_like(xy), xy)


def _conv2d(c_in: int, c_out: int, k: int) -> nn.Conv2d:
    return nn.Conv2d(c_in, c_out, k, padding=k // 2)


class _Down(nn.Module):
    """Two 3 x 3 convolutions with ReLU, then (``pool``) a 2 x 2 max pooling; returns both."""

    def __init__(self, c_in: int, c_out: int, pool: bool) -> None:
        super().__init__()
        self.conv1 = _conv2d(c_in, c_out, 3)
        self.conv2 = _conv2d(c_out, c_out, 3)
        self.pool = pool

    def forward(self, x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        skip = F.relu(self.conv2(F.relu(self.conv1(x))))
        return (F.max_pool2d(skip, 2, 2) if self.pool else skip), skip


class _Up(nn.Module):
    """A 2 x 2 transposed convolution (halves the channels, doubles the size), concatenated with the skip,
    then two 3 x 3 convolutions with ReLU."""

    def __init__(self, c_in: int, c_out: int) -> None:
        super().__init__()
        self.upconv = nn.ConvTranspose2d(c_in, c_out, 2, stride=2)
        self.conv1 = _conv2d(2 * c_out, c_out, 3)
        self.conv2 = _conv2d(c_out, c_out, 3)

    def forward(self, skip: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
        x = torch.cat((self.upconv(x), skip), 1)
        return F.relu(self.conv2(F.relu(self.conv1(x))))


class _UNet(nn.Module):
    """The 2-D U-Net of every feature plane: 32 -> 32 -> 64 -> 128 channels down (40 -> 20 -> 10 cells), up
    again to 32 channels at 40 x 40, a final 1 x 1 convolution (32 channels)."""

    def __init__(self, channels: int = FEATURES, depth: int = 3) -> None:
        super().__init__()
        widths = [channels * 2**i for i in range(depth)]
        ins = [channels, *widths[:-1]]
        self.down_convs = nn.ModuleList(
            _Down(a, b, pool=i < depth - 1) for i, (a, b) in enumerate(zip(ins, widths, strict=True))
        )
        self.up_convs = nn.ModuleList(_Up(w, w // 2) for w in reversed(widths[1:]))
        self.conv_final = nn.Conv2d(channels, channels, 1)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        skips = []
        for down in self.down_convs:
            x, skip = down(x)
            skips.append(skip)
        for up, skip in zip(self.up_convs, reversed(skips[:-1]), strict=True):
            x = up(skip, x)
        return self.conv_final(x)


class _Encoder(nn.Module):
    """The voxel encoder: per-voxel features averaged onto the three planes, each refined by the U-Net."""

    def __init__(self) -> None:
        super().__init__()
        self.conv_in = nn.Conv3d(1, FEATURES, 3, padding=1)
        self.unet = _UNet()

    def forward(self, tsdf: torch.Tensor) -> tuple[torch.Tensor, ...]:
        b, n = tsdf.shape[0], tsdf.shape[1] * tsdf.shape[2] * tsdf.shape[3]
        axes = [torch.linspace(-0.5, 0.5, s) for s in tsdf.shape[1:]]  # the voxels' coordinates
        grid = torch.stack(torch.meshgrid(*axes, indexing="ij"), dim=-1)
        p = grid.reshape(1, n, 3).expand(b, n, 3)
        c = F.relu(self.conv_in(tsdf.unsqueeze(1))).reshape(b, FEATURES, n)
        planes = []
        for plane in PLANES:
            cell = (plane_coordinates(p, plane) * GRID).long()
            index = cell[:, :, 0] + GRID * cell[:, :, 1]
            fea = scatter_mean(c, index, GRID * GRID).reshape(b, FEATURES, GRID, GRID)
            planes.append(self.unet(fea))
        return tuple(planes)


class _ResnetBlock(nn.Module):
    """x + fc_1(relu(fc_0(relu(x))))."""

    def __init__(self, width: int) -> None:
        super().__init__()
        self.fc_0 = nn.Linear(width, width)
        self.fc_1 = nn.Linear(width, width)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return x + self.fc_1(F.relu(self.fc_0(F.relu(x))))


class _Decoder(nn.Module):
    """ConvONet's local decoder: the query point and its sampled plane features through five ResNet blocks."""

    def __init__(self, out_dim: int) -> None:
        super().__init__()
        self.fc_c = nn.ModuleList(nn.Linear(FEATURES * len(PLANES), HIDDEN) for _ in range(BLOCKS))
        self.fc_p = nn.Linear(3, HIDDEN)
        self.blocks = nn.ModuleList(_ResnetBlock(HIDDEN) for _ in range(BLOCKS))
        self.fc_out = nn.Linear(HIDDEN, out_dim)

    def forward(self, p: torch.Tensor, features: torch.Tensor) -> torch.Tensor:
        """(B, N, out_dim) at the points ``p`` (B, N, 3) from their plane ``features`` (B, N, 96)."""
        net = self.fc_p(p)
        for fc_c, block in zip(self.fc_c, self.blocks, strict=True):
            net = block(net + fc_c(features))
        return self.fc_out(F.relu(net))


def sample_planes(p: torch.Tensor, planes: tuple[torch.Tensor, ...]) -> torch.Tensor:
    """(B, N, 96) the three planes (B, 32, 40, 40) sampled bilinearly at the points ``p`` (B, N, 3), unit-cube
    coordinates, concatenated in :data:`PLANES` order."""
    out = []
    for plane, fea in zip(PLANES, planes, strict=True):
        uv = 2.0 * plane_coordinates(p, plane)[:, :, None] - 1.0  # (B, N, 1, 2) in [-1, 1]
        out.append(F.grid_sample(fea, uv, mode="bilinear", padding_mode="border", align_corners=True)[..., 0])
    return torch.cat(out, dim=1).transpose(1, 2)


class GigaNet(nn.Module):
    """Encoder and four decoders; :meth:`forward` runs the three grasp heads (the TSDF head is loaded with the
    weights and left unused, as GIGA's grasp detection does)."""

    def __init__(self) -> None:
        super().__init__()
        self.encoder = _Encoder()
        self.decoder_qual = _Decoder(1)
        self.decoder_rot = _Decoder(4)
        self.decoder_width = _Decoder(1)
        self.decoder_tsdf = _Decoder(1)

    def forward(self, tsdf: torch.Tensor, p: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Quality (B, N), quaternion (B, N, 4) (x, y, z, w), width (B, N) (units of the workspace's edge) at
        the points ``p`` (B, N, 3) of the grids ``tsdf`` (B, 40, 40, 40). The planes are sampled once for the
        three heads (GIGA samples them per head: the same values)."""
        features = sample_planes(p, self.encoder(tsdf))
        quality = torch.sigmoid(self.decoder_qual(p, features)[..., 0])
        rotation = F.normalize(self.decoder_rot(p, features), dim=2)
        return quality, rotation, self.decoder_width(p, features)[..., 0]


def voxel_queries(resolution: int = GRID) -> torch.Tensor:
    """(1, resolution^3, 3) GIGA's query points, one per voxel (i, j, k) in C order: ``(i, j, k) / resolution
    - 0.5`` in unit-cube coordinates, i.e. (i, j, k) voxel lengths from the volume's corner, where VGN places
    the grasp of voxel (i, j, k) (GIGA's ``VGNImplicit.pos``)."""
    axis = torch.linspace(-0.5, 0.5 - 1.0 / resolution, resolution)
    grid = torch.stack(torch.meshgrid(axis, axis, axis, indexing="ij"), dim=-1)
    return grid.reshape(1, resolution**3, 3)


def load_giga(ckpt: Checkpoint) -> GigaNet:
    """The network with the published weights ``ckpt`` (``giga_pile``, ``giga_packed``), in eval mode on the
    CPU. The file's SHA-256 is checked on the bytes that are loaded
    (:func:`graspexp.core.checkpoints.read_verified`); every tensor must match a parameter and every parameter
    must be in the file (``strict=True``)."""
    state = torch.load(io.BytesIO(read_verified(ckpt)), map_location="cpu", weights_only=True)
    net = GigaNet()
    net.load_state_dict(state, strict=True)
    return net.eval()
