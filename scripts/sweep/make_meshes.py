"""Meshes not in ../shared for sweeping `conemap quads` (session 37): CSG parts
made with manifold3d, their isotropic remeshes (pymeshlab), cut, stretched
and jittered variants, two parts in one file, spot subdivided to 94 k faces.
A bench-side tool, not a dependency:
    python3 -m venv /tmp/venv && /tmp/venv/bin/pip install manifold3d trimesh pymeshlab numpy
    /tmp/venv/bin/python scripts/sweep/make_meshes.py OUT_DIR [SHARED_MESHES_DIR]
"""
import os, sys
import numpy as np, trimesh, manifold3d as m3, pymeshlab
from trimesh.intersections import slice_faces_plane
OUT = sys.argv[1]; os.makedirs(OUT, exist_ok=True)
SHARED = sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(__file__), "../../../shared/meshes")
def save(t, name):
    t.export(f"{OUT}/{name}.obj"); print(name, len(t.faces))
rng = np.random.default_rng(37)
def man2tri(m):
    mg = m.to_mesh(); return trimesh.Trimesh(np.asarray(mg.vert_properties)[:, :3], np.asarray(mg.tri_verts), process=True)
def remesh(name, pct=1.0):
    ms = pymeshlab.MeshSet(); ms.load_new_mesh(f"{OUT}/{name}.obj")
    ms.meshing_isotropic_explicit_remeshing(iterations=6, targetlen=pymeshlab.PercentageValue(pct), featuredeg=30)
    ms.save_current_mesh(f"{OUT}/{name}_remesh.obj", save_vertex_normal=False, save_textures=False)
    print(name + "_remesh", ms.current_mesh().face_number())
S = 48  # circular segments
# 1 box minus cylinder (through hole)
a = m3.Manifold.cube([4, 3, 2], center=True) - m3.Manifold.cylinder(3, 0.8, 0.8, S, center=True)
save(man2tri(a), "cad_boxhole")
# 2 L-bracket with a hole in each leg
L = m3.Manifold.cube([4, 1.5, 0.4]) + m3.Manifold.cube([0.4, 1.5, 3])
L = L - m3.Manifold.cylinder(1, 0.35, 0.35, S).translate([2.4, 0.75, -0.3])
L = L - m3.Manifold.cylinder(1, 0.3, 0.3, S).rotate([0, 90, 0]).translate([-0.3, 0.75, 1.9])
save(man2tri(L), "cad_lbracket")
# 3 union of box and cylinder (boss on a plate)
U = m3.Manifold.cube([4, 4, 1], center=True) + m3.Manifold.cylinder(2, 1.0, 1.0, S).translate([0.5, 0.3, 0])
save(man2tri(U), "cad_boxcyl")
# 4 rounded box: hull of 8 spheres
sph = [m3.Manifold.sphere(0.5, S).translate([x, y, z]) for x in (-1.5, 1.5) for y in (-1, 1) for z in (-0.5, 0.5)]
H = m3.Manifold.batch_hull(sph)
save(man2tri(H), "cad_roundbox")
for n in ("cad_boxhole", "cad_lbracket", "cad_boxcyl", "cad_roundbox"):
    remesh(n, 1.0)
# 5 spot loop-subdivided twice (~94k faces)
ms = pymeshlab.MeshSet(); ms.load_new_mesh(f"{SHARED}/spot.obj")
ms.meshing_surface_subdivision_loop(iterations=2, threshold=pymeshlab.PercentageValue(0))
ms.save_current_mesh(f"{OUT}/spot_loop2.obj", save_vertex_normal=False, save_textures=False, save_wedge_texcoord=False)
print("spot_loop2", ms.current_mesh().face_number())
# 6 fandisk scaled 3x1x0.5 and jittered by 10% of mean edge length
t = trimesh.load(f"{SHARED}/fandisk.obj", process=False)
e = t.edges_unique_length.mean()
v = t.vertices + rng.normal(size=t.vertices.shape) * 0.1 * e / np.sqrt(3)
v = v * np.array([3, 1, 0.5])
save(trimesh.Trimesh(v, t.faces, process=False), "fandisk_aniso_jitter")
# 7 boundary: remeshed box-with-hole cut by a plane (open, no cap) -> boundary loops
t = trimesh.load(f"{OUT}/cad_boxhole_remesh.obj", process=True)
vv, ff = slice_faces_plane(t.vertices, t.faces, plane_normal=np.array([0, 0, -1.0]), plane_origin=np.array([0, 0, 0.3]))[:2]
c = trimesh.Trimesh(vv, ff, process=True)
c.remove_unreferenced_vertices()
save(c, "cad_boxhole_cut")
# 8 two disjoint meshes in one OBJ: spot + a jittered torus beside it
sp = trimesh.load(f"{SHARED}/spot.obj", process=True)
tor = trimesh.creation.torus(0.5, 0.15, major_sections=64, minor_sections=24)
tor.apply_translation([sp.bounds[1][0] + 0.8, 0, 0])
save(trimesh.util.concatenate([sp, tor]), "spot_plus_torus")

# Variants
# fandisk: anisotropic only / jitter only (isolates the sharp-20 failure of fandisk_aniso_jitter)
rng = np.random.default_rng(37)
t = trimesh.load(f"{SHARED}/fandisk.obj", process=False)
e = t.edges_unique_length.mean()
save(trimesh.Trimesh(t.vertices * np.array([3, 1, 0.5]), t.faces, process=False), "fandisk_aniso")
save(trimesh.Trimesh(t.vertices + rng.normal(size=t.vertices.shape) * 0.1 * e / np.sqrt(3), t.faces, process=False), "fandisk_jitter")
# organic part with boundary: spot loop-subdivided once cut by an oblique plane (no cap), largest piece
ms = pymeshlab.MeshSet(); ms.load_new_mesh(f"{SHARED}/spot.obj")
ms.meshing_surface_subdivision_loop(iterations=1, threshold=pymeshlab.PercentageValue(0))
ms.save_current_mesh(f"{OUT}/_tmp_spot1.obj", save_vertex_normal=False, save_textures=False, save_wedge_texcoord=False)
s = trimesh.load(f"{OUT}/_tmp_spot1.obj", process=True); os.remove(f"{OUT}/_tmp_spot1.obj")
c0 = s.bounds.mean(axis=0)
vv, ff = slice_faces_plane(s.vertices, s.faces, plane_normal=np.array([0.3, -1.0, 0.2]), plane_origin=c0)[:2]
c = trimesh.Trimesh(vv, ff, process=True)
lab = trimesh.graph.connected_component_labels(c.face_adjacency, node_count=len(c.faces))
big = np.bincount(lab).argmax()
c = trimesh.Trimesh(c.vertices, c.faces[lab == big], process=True); c.remove_unreferenced_vertices()
save(c, "spot_cut")
# raw L-bracket scaled 3 x 1 x 0.5 (anisotropic low-poly CAD)
t = trimesh.load(f"{OUT}/cad_lbracket.obj", process=False)
save(trimesh.Trimesh(t.vertices * np.array([3, 1, 0.5]), t.faces, process=False), "cad_lbracket_aniso")

rng = np.random.default_rng(38)
# remeshed box+cylinder jittered by 10% of mean edge length (scan-like noise on a CAD part)
t = trimesh.load(f"{OUT}/cad_boxcyl_remesh.obj", process=False)
e = t.edges_unique_length.mean()
save(trimesh.Trimesh(t.vertices + rng.normal(size=t.vertices.shape) * 0.1 * e / np.sqrt(3), t.faces, process=False), "cad_boxcyl_remesh_jitter")
# two disjoint remeshed CAD parts in one OBJ: box-with-hole + L-bracket (chi 0 + -2)
a = trimesh.load(f"{OUT}/cad_boxhole_remesh.obj", process=False)
b = trimesh.load(f"{OUT}/cad_lbracket_remesh.obj", process=False)
b.apply_translation([a.bounds[1][0] + 1.0 - b.bounds[0][0], 0, 0])
save(trimesh.util.concatenate([a, b]), "cad_two_parts")
