"""A pinhole depth camera rendered by CPU ray casting: exact depth, per-pixel object ids and incidence
angles of the scene's actual geometry (the posed object meshes and the axis-aligned support boxes).

Why a ray caster: SAPIEN's camera needs a Vulkan device, which these CPU-only machines lack (Debian 12's
Mesa lavapipe is too old for SAPIEN 3's renderer); Embree (Intel's ray tracing kernels, through the
``embreex`` package's scene API) runs everywhere. Where a GPU with Vulkan exists SAPIEN's renderer could
be used instead; this module does not need one.

Only the rays inside a mesh's projected bounding box are cast at it (in the mesh's own frame, so its
Embree BVH is built once per mesh, not per trial); the support boxes are intersected analytically (slab
test). Both are exact: a ray outside the projection of a body's bounding box cannot meet the body.
Embree (single precision) finds the triangle each ray meets first; the hit point is that triangle's plane
met in double precision (:func:`first_hits`, the numbers trimesh's ``RayMeshIntersector`` gives, without
its bookkeeping for multiple hits).
"""

import functools
import weakref
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import trimesh

from graspexp.config.perception import CameraConfig
from graspexp.perception.imports import import_optional


@dataclass(frozen=True)
class MeshBody:
    """A mesh placed in the scene: ``mesh`` in its own frame (m), ``pose`` (4, 4) world from mesh frame,
    ``body_id`` the id its pixels get (0: support or background)."""

    mesh: trimesh.Trimesh
    pose: np.ndarray
    body_id: int


@dataclass(frozen=True)
class BoxBody:
    """An axis-aligned box in the world: corners ``lo`` and ``hi`` (3,) m, id ``body_id``."""

    lo: np.ndarray
    hi: np.ndarray
    body_id: int = 0


@dataclass(frozen=True)
class RenderedView:
    """Exact ray-cast frame. depth (H, W) float64 m along the optical axis (0: no hit); ids (H, W) int32;
    cos_incidence (H, W) float64 |cos| of the angle between each ray and the surface normal (0: no hit)."""

    depth: np.ndarray
    ids: np.ndarray
    cos_incidence: np.ndarray


def intrinsics(cam: CameraConfig) -> np.ndarray:
    """(3, 3) pinhole matrix K of ``cam``, px."""
    return np.array([[cam.fx_px, 0.0, cam.cx_px], [0.0, cam.fy_px, cam.cy_px], [0.0, 0.0, 1.0]])


def look_at(eye: np.ndarray, target: np.ndarray) -> np.ndarray:
    """(4, 4) world-from-camera pose of a camera at ``eye`` looking at ``target`` (world, m), OpenCV
    convention (+Z forward, +X right, +Y down), image rows parallel to the horizon."""
    z = np.asarray(target, float) - np.asarray(eye, float)
    z /= np.linalg.norm(z)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    pose = np.eye(4)
    pose[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)
    pose[:3, 3] = eye
    return pose


def view_poses(cam: CameraConfig, table_z: float) -> list[np.ndarray]:
    """World-from-camera poses (4, 4) of the views of ``cam`` over a support whose top centre is at
    (0, 0, ``table_z``): one per ``azimuths_deg``, ``distance_m`` from the look-at point, looking down at
    ``elevation_deg``."""
    target = np.array([0.0, 0.0, table_z + cam.look_at_height_m])
    el = np.radians(cam.elevation_deg)
    out = []
    for az in np.radians(np.asarray(cam.azimuths_deg, dtype=float)):
        offset = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        out.append(look_at(target + cam.distance_m * offset, target))
    return out


def pixel_rays(cam: CameraConfig) -> np.ndarray:
    """(H * W, 3) ray directions in the camera frame, row-major pixels, scaled to unit z (a hit at ray
    parameter t has depth t). Cached per intrinsics (read-only)."""
    return _pixel_rays(cam.width_px, cam.height_px, cam.fx_px, cam.fy_px, cam.cx_px, cam.cy_px)


@functools.lru_cache(maxsize=8)
def _pixel_rays(w: int, h: int, fx: float, fy: float, cx: float, cy: float) -> np.ndarray:
    v, u = np.divmod(np.arange(h * w), w)
    rays = np.stack([(u - cx) / fx, (v - cy) / fy, np.ones(h * w)], axis=1)
    rays.flags.writeable = False
    return rays


@functools.lru_cache(maxsize=8)
def _ray_lengths(w: int, h: int, fx: float, fy: float, cx: float, cy: float) -> np.ndarray:
    """(H * W,) lengths of :func:`pixel_rays` (a rotation keeps them)."""
    n = np.linalg.norm(_pixel_rays(w, h, fx, fy, cx, cy), axis=1)
    n.flags.writeable = False
    return n


def _require_embree() -> None:
    import_optional("embreex", "embreex", "the depth camera")


@dataclass(frozen=True)
class _Bvh:
    """What the ray caster keeps of a mesh (its own frame): the Embree scene, built on the vertices
    shifted by ``origin`` and scaled by ``scale`` to a box of about 100 units (single precision keeps
    about 1e-5 of that: micrometres on a 10 cm object); each triangle's first vertex (F, 3) and unit
    normal (F, 3), m; the corners (8, 3) of the bounding box, m. Copies, read without trimesh's cache
    checks (each hashes the mesh: milliseconds per frame)."""

    mesh: "weakref.ref[trimesh.Trimesh]"
    scene: object
    origin: np.ndarray
    scale: float
    plane_origins: np.ndarray
    face_normals: np.ndarray
    corners: np.ndarray


_BVHS: dict[int, _Bvh] = {}
"""Each mesh's :class:`_Bvh` by ``id``, built at its first frame, dropped with the mesh."""


def _bvh(mesh: trimesh.Trimesh) -> _Bvh:
    bvh = _BVHS.get(id(mesh))
    if bvh is None or bvh.mesh() is not mesh:
        from embreex import mesh_construction, rtcore_scene

        vertices = np.asarray(mesh.vertices, dtype=np.float64)
        faces = np.asarray(mesh.faces)
        origin, scale = vertices.min(axis=0), 100.0 / float(mesh.scale)
        scene = rtcore_scene.EmbreeScene()
        mesh_construction.TriangleMesh(
            scene=scene,
            vertices=((vertices - origin) * scale).astype(np.float32),
            indices=faces.astype(np.int32),
        )
        key = id(mesh)
        bvh = _BVHS[key] = _Bvh(
            weakref.ref(mesh, lambda _: _BVHS.pop(key, None)),
            scene,
            origin,
            scale,
            vertices[faces[:, 0]],
            np.array(mesh.face_normals, dtype=np.float64),
            trimesh.bounds.corners(mesh.bounds),
        )
    return bvh


def first_hits(
    mesh: trimesh.Trimesh, origin: np.ndarray, dirs: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The first hit of each ray ``origin + t dirs`` (origin (3,), dirs (R, 3), the mesh's frame, m) on
    ``mesh``: (index_ray (H,) of the rays that hit, ascending; index_tri (H,) the triangle each meets;
    locations (H, 3) the hit points, m). Rays within 1e-5 of parallel to their triangle's plane count as
    misses."""
    bvh = _bvh(mesh)
    unit = trimesh.util.unitize(np.asarray(dirs, dtype=np.float64))
    origins = np.repeat(np.asarray(origin, dtype=np.float64)[None, :], len(unit), axis=0)
    tri = bvh.scene.run(((origins - bvh.origin) * bvh.scale).astype(np.float32), unit.astype(np.float32))
    ray = np.flatnonzero(tri != -1)
    tri = tri[ray].astype(np.int64)
    locations, valid = trimesh.intersections.planes_lines(
        bvh.plane_origins[tri], bvh.face_normals[tri], origins[ray], unit[ray]
    )
    return ray[valid], tri[valid], locations


def _box_hits(origin: np.ndarray, dirs: np.ndarray, box: BoxBody) -> tuple[np.ndarray, np.ndarray]:
    """Rays ``origin + t dirs`` (dirs (R, 3)) against an axis-aligned box seen from outside: each ray
    enters through one of the (at most 3) faces turned towards ``origin``. Returns (t (R,), inf where
    missed; the entry face's axis (R,) 0-2)."""
    t_hit = np.full(len(dirs), np.inf)
    axis = np.zeros(len(dirs), dtype=np.int64)
    for k in range(3):
        if box.lo[k] <= origin[k] <= box.hi[k]:
            continue  # neither face of this axis is turned towards the camera
        plane = box.lo[k] if origin[k] < box.lo[k] else box.hi[k]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (plane - origin[k]) / dirs[:, k]
        hit = t > 0
        for j in {0, 1, 2} - {k}:
            c = origin[j] + t * dirs[:, j]
            hit &= (c >= box.lo[j]) & (c <= box.hi[j])
        t_hit[hit], axis[hit] = t[hit], k
    return t_hit, axis


def _mesh_rect(body: MeshBody, camera_from_world: np.ndarray, cam: CameraConfig) -> tuple[int, int, int, int]:
    """Pixel rectangle (u0, u1, v0, v1), half-open, covering the projection of the mesh's bounding box;
    the whole image if a corner is behind the camera."""
    corners = _bvh(body.mesh).corners
    world = corners @ body.pose[:3, :3].T + body.pose[:3, 3]
    c = world @ camera_from_world[:3, :3].T + camera_from_world[:3, 3]
    if (c[:, 2] <= 1e-6).any():
        return 0, cam.width_px, 0, cam.height_px
    u = cam.fx_px * c[:, 0] / c[:, 2] + cam.cx_px
    v = cam.fy_px * c[:, 1] / c[:, 2] + cam.cy_px
    u0, u1 = max(0, int(np.floor(u.min()))), min(cam.width_px, int(np.ceil(u.max())) + 1)
    v0, v1 = max(0, int(np.floor(v.min()))), min(cam.height_px, int(np.ceil(v.max())) + 1)
    return u0, u1, v0, v1


def render(
    cam: CameraConfig,
    world_from_camera: np.ndarray,
    meshes: Sequence[MeshBody],
    boxes: Sequence[BoxBody] = (),
) -> RenderedView:
    """Ray-cast one exact depth frame of the scene (module doc). Depth outside
    [``min_range_m``, ``max_range_m``] is 0 (no return)."""
    _require_embree()
    h, w = cam.height_px, cam.width_px
    rays_cam = pixel_rays(cam)
    R, eye = world_from_camera[:3, :3], world_from_camera[:3, 3]
    dirs = rays_cam @ R.T  # world directions, camera z-component 1
    best = np.full(h * w, np.inf)
    ids = np.zeros(h * w, dtype=np.int32)
    cos = np.zeros(h * w)
    norm = _ray_lengths(cam.width_px, cam.height_px, cam.fx_px, cam.fy_px, cam.cx_px, cam.cy_px)
    for box in boxes:
        t, axis = _box_hits(eye, dirs, box)
        closer = np.flatnonzero(t < best)
        best[closer], ids[closer] = t[closer], box.body_id
        cos[closer] = np.abs(dirs[closer, axis[closer]]) / norm[closer]
    camera_from_world = np.linalg.inv(world_from_camera)
    for body in meshes:
        u0, u1, v0, v1 = _mesh_rect(body, camera_from_world, cam)
        if u0 >= u1 or v0 >= v1:
            continue
        pix = (np.arange(v0, v1)[:, None] * w + np.arange(u0, u1)[None, :]).ravel()
        Rb, tb = body.pose[:3, :3], body.pose[:3, 3]
        origin_b = (eye - tb) @ Rb  # the rays in the mesh's frame
        dirs_b = dirs[pix] @ Rb
        index_ray, index_tri, locations = first_hits(body.mesh, origin_b, dirs_b)
        if len(index_ray) == 0:
            continue
        d = dirs_b[index_ray]
        t = np.einsum("ij,ij->i", locations - origin_b, d) / np.einsum("ij,ij->i", d, d)
        p = pix[index_ray]
        closer = (t > 0) & (t < best[p])
        p, t = p[closer], t[closer]
        best[p], ids[p] = t, body.body_id
        n = _bvh(body.mesh).face_normals[index_tri[closer]]
        cos[p] = np.abs(np.einsum("ij,ij->i", n, d[closer]) / np.linalg.norm(d[closer], axis=1))
    valid = np.isfinite(best) & (best >= cam.min_range_m) & (best <= cam.max_range_m)
    depth = np.where(valid, best, 0.0)
    return RenderedView(
        depth=depth.reshape(h, w),
        ids=np.where(valid, ids, 0).astype(np.int32).reshape(h, w),
        cos_incidence=np.where(valid, cos, 0.0).reshape(h, w),
    )


def back_project(
    depth: np.ndarray, cam: CameraConfig, world_from_camera: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """World points (M, 3) of the pixels of ``depth`` (H, W) with a return (> 0), and their flat pixel
    indices (M,)."""
    flat = np.flatnonzero(depth.ravel() > 0)
    cam_pts = pixel_rays(cam)[flat] * depth.ravel()[flat, None].astype(np.float64)
    return cam_pts @ world_from_camera[:3, :3].T + world_from_camera[:3, 3], flat
