"""The convolutional Volumetric Grasping Network (Breyer et al., CoRL 2020, Sec. III-C), written here with
parameter names that match the published ``vgn_conv.pth`` state dict, and its loading.

Input: (B, 1, 40, 40, 40) float32 TSDF grid, axes (x, y, z) of the workspace frame. Output per voxel:
grasp quality (B, 1, 40, 40, 40) in [0, 1], orientation (B, 4, 40, 40, 40) unit quaternion (x, y, z, w) of
the grasp frame in the workspace frame, opening width (B, 1, 40, 40, 40) in voxels.
"""

from __future__ import annotations

import io

import torch
from torch import nn
from torch.nn import functional as F

from graspexp.core.checkpoints import VGN, Checkpoint, read_verified

GRID = 40
"""Voxels per side of the input grid (the network's strides and up-sampling sizes assume it)."""


def _conv(c_in: int, c_out: int, k: int, stride: int = 1) -> nn.Conv3d:
    """A 3-D convolution that keeps the size (stride 1) or halves it (stride 2): padding k // 2."""
    return nn.Conv3d(c_in, c_out, k, stride=stride, padding=k // 2)


class _Encoder(nn.Module):
    """Three stride-2 convolutions with ReLU: 40^3 -> 5^3, 1 -> 16 -> 32 -> 64 channels."""

    def __init__(self) -> None:
        super().__init__()
        self.conv1 = _conv(1, 16, 5, 2)
        self.conv2 = _conv(16, 32, 3, 2)
        self.conv3 = _conv(32, 64, 3, 2)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        for conv in (self.conv1, self.conv2, self.conv3):
            x = F.relu(conv(x))
        return x


class _Decoder(nn.Module):
    """Three convolutions with ReLU, each followed by nearest up-sampling: 5^3 -> 10^3 -> 20^3 -> 40^3."""

    def __init__(self) -> None:
        super().__init__()
        self.conv1 = _conv(64, 64, 3)
        self.conv2 = _conv(64, 32, 3)
        self.conv3 = _conv(32, 16, 5)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        for conv, size in ((self.conv1, 10), (self.conv2, 20), (self.conv3, 40)):
            x = F.interpolate(F.relu(conv(x)), size=size, mode="nearest")
        return x


class VgnNet(nn.Module):
    """Encoder, decoder and three 5^3 output heads (quality: sigmoid; orientation: normalised; width)."""

    def __init__(self) -> None:
        super().__init__()
        self.encoder = _Encoder()
        self.decoder = _Decoder()
        self.conv_qual = _conv(16, 1, 5)
        self.conv_rot = _conv(16, 4, 5)
        self.conv_width = _conv(16, 1, 5)

    def forward(self, tsdf: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        x = self.decoder(self.encoder(tsdf))
        quality = torch.sigmoid(self.conv_qual(x))
        rotation = F.normalize(self.conv_rot(x), dim=1)
        return quality, rotation, self.conv_width(x)


def load_vgn(ckpt: Checkpoint = VGN) -> VgnNet:
    """The network with the published weights ``ckpt`` (VGN's ``vgn_conv.pth``, or a retraining with the same
    tensors: ``vgn_pile``, ``vgn_packed``), in eval mode on the CPU. The file's SHA-256 is checked on
    the bytes that are loaded (:func:`graspexp.core.checkpoints.read_verified`); every tensor must match a
    parameter and every parameter must be in the file (``strict=True``)."""
    state = torch.load(io.BytesIO(read_verified(ckpt)), map_location="cpu", weights_only=True)
    net = VgnNet()
    net.load_state_dict(state, strict=True)
    return net.eval()
