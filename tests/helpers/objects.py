"""Objects and grippers written at test time with trimesh (no third-party file)."""

from pathlib import Path

import numpy as np


def bent_tube(bend_radius: float, radius: float, angle_rad: float, n_bend: int = 24, n_round: int = 16):
    """A closed tube of ``radius`` bent along a circular arc of ``bend_radius`` over ``angle_rad`` in the XY
    plane (a concave shape), capped at both ends; units as given."""
    import numpy as np
    import trimesh

    t = np.linspace(0.0, angle_rad, n_bend)
    phi = np.linspace(0.0, 2 * np.pi, n_round, endpoint=False)
    radial = np.c_[np.cos(t), np.sin(t), np.zeros_like(t)]
    rings = (bend_radius + radius * np.cos(phi))[None, :, None] * radial[:, None, :]
    rings[..., 2] = radius * np.sin(phi)[None, :]
    vertices = np.vstack([rings.reshape(-1, 3), bend_radius * radial[[0, -1]]])
    faces = []
    for i in range(n_bend - 1):
        for j in range(n_round):
            a, b = i * n_round + j, i * n_round + (j + 1) % n_round
            faces += [(a, b, b + n_round), (a, b + n_round, a + n_round)]
    caps = len(vertices) - 2
    for j in range(n_round):
        faces += [(caps, (j + 1) % n_round, j)]
        last = (n_bend - 1) * n_round
        faces += [(caps + 1, last + j, last + (j + 1) % n_round)]
    mesh = trimesh.Trimesh(vertices, np.array(faces), process=True)
    mesh.fix_normals()
    return mesh


def make_object_folder(folder: Path) -> Path:
    """Write the folder dataset of the tests into ``folder`` and return it: 6 objects made here with trimesh
    (no third-party mesh), in 5 file formats and mixed units, some with sidecars and some without.

    can.obj (m, no sidecar), arc.obj (a bent, concave tube in cm; sidecar: units, area), box.ply (mm;
    sidecar: units, mass_kg), cone.stl (m; sidecar: density_kg_m3, friction), ball.glb (m, no sidecar),
    bracket.urdf (an L-shaped, concave bracket: its STL in mm placed by ``<mesh scale>`` and ``<origin>``,
    mass from ``<inertial>``; the STL is not a second object).
    """
    import numpy as np
    import trimesh

    folder.mkdir(parents=True, exist_ok=True)
    trimesh.creation.cylinder(radius=0.03, height=0.1, sections=48).export(folder / "can.obj")
    bent_tube(8.0, 1.6, np.pi / 2).export(folder / "arc.obj")
    (folder / "arc.yaml").write_text(
        "units: cm\narea:\n  note: the middle of the arc\n  ops:\n"
        "    - keep_sphere: {center: [0.0566, 0.0566, 0.0], radius: 0.04}\n"
    )
    trimesh.creation.box(extents=(60.0, 40.0, 90.0)).export(folder / "box.ply")
    (folder / "box.yaml").write_text("units: mm\nmass_kg: 0.2\n")
    trimesh.creation.cone(radius=0.035, height=0.09, sections=48).export(folder / "cone.stl")
    (folder / "cone.yaml").write_text("density_kg_m3: 900\nfriction: 0.8\n")
    trimesh.creation.icosphere(subdivisions=3, radius=0.03).export(folder / "ball.glb")
    profile = np.array([(0, 0), (70, 0), (70, 15), (15, 15), (15, 70), (0, 70)], dtype=float)  # an L, mm
    fan = np.array([(0, 1, 2), (0, 2, 3), (0, 3, 4), (0, 4, 5)])
    trimesh.creation.extrude_triangulation(profile, fan, height=30.0).export(folder / "bracket_link.stl")
    (folder / "bracket.urdf").write_text(
        '<robot name="bracket"><link name="bracket">\n'
        '  <inertial><mass value="0.15"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>\n'
        '  <collision><origin xyz="-0.035 -0.035 0" rpy="0 0 0"/>\n'
        '    <geometry><mesh filename="bracket_link.stl" scale="0.001 0.001 0.001"/></geometry></collision>\n'
        "</link></robot>\n"
    )
    return folder


def write_urdf_gripper(
    folder: Path,
    *,
    palm_size_m: tuple[float, float, float] = (0.045, 0.15, 0.06),
    finger_size_m: tuple[float, float, float] = (0.022, 0.01, 0.08),
    upper_m: float = 0.055,
    curved_tip: bool = True,
) -> Path:
    """A parallel gripper URDF in ``folder`` shaped like the RG2 box model: a palm box (link ``hand``, its
    front face at z = 0), two prismatic fingers (``left_joint`` along +y, ``right_joint`` along -y, limits
    [0, ``upper_m``], pads touching at q = 0) made of a box each, and with ``curved_tip`` a fingertip
    mesh (``tip.stl``: half a cylinder, written with trimesh) at the top of each finger. Returns the file."""
    import trimesh

    px, py, pz = palm_size_m
    fx, ft, fl = finger_size_m
    tip = ""
    if curved_tip:  # a half cylinder along x, radius ft/2, flat face down: a rounded fingertip
        a = np.linspace(0.0, np.pi, 13)
        arc = np.stack([ft / 2 * np.cos(a), ft / 2 * np.sin(a)], axis=1)
        pts = np.concatenate([np.insert(arc, 0, x, axis=1) for x in (-fx / 2, fx / 2)])
        trimesh.convex.convex_hull(pts).export(folder / "tip.stl")
    links, joints = [], []
    for name, sign in (("left", 1.0), ("right", -1.0)):
        if curved_tip:
            tip = (
                f'<collision><origin xyz="0 {sign * ft / 2} {fl}"/>'
                '<geometry><mesh filename="tip.stl"/></geometry></collision>'
            )
        links.append(
            f'<link name="{name}_finger"><collision><origin xyz="0 {sign * ft / 2} {fl / 2}"/>'
            f'<geometry><box size="{fx} {ft} {fl}"/></geometry></collision>{tip}</link>'
        )
        joints.append(
            f'<joint name="{name}_joint" type="prismatic"><parent link="hand"/><child link="{name}_finger"/>'
            f'<axis xyz="0 {sign:g} 0"/><limit lower="0" upper="{upper_m}" effort="100" velocity="1"/></joint>'
        )
    text = (
        '<?xml version="1.0"?><robot name="test_gripper"><link name="world_mount"/>'
        f'<link name="hand"><collision><origin xyz="0 0 {-pz / 2}"/><geometry><box size="{px} {py} {pz}"/>'
        f"</geometry></collision></link>{''.join(links)}{''.join(joints)}</robot>"
    )
    path = folder / "gripper.urdf"
    path.write_text(text)
    return path
