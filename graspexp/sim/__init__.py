"""SAPIEN physics-only simulation of the grasp trials."""

import warnings

# Physics-only scenes never render; SAPIEN still looks for a Vulkan loader at import and warns once.
warnings.filterwarnings("ignore", message="Failed to find system libvulkan", category=UserWarning)
