"""An interactive edit loop: a surface through constraints, edited one constraint at a time, the mesh
kept up to date by deltas (what a viewer would redraw), written at the end.

    python3 python/examples/edit_loop.py [OUT.obj]
"""
import sys

import numpy as np

import vitri

# A sphere's constraints: f = 0 on the surface, +-0.1 off it.
n = 200
i = np.arange(n) + 0.5
phi, theta = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
p = np.stack([np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)], axis=1)
points = np.concatenate([p, 1.1 * p, 0.9 * p])
values = np.concatenate([np.zeros(n), np.full(n, 0.1), np.full(n, -0.1)])

mesher = vitri.Mesher(points, values)
mesher.refine(0.05, relative=True)
delta = mesher.update_surface()  # the first delta holds the whole mesh
print(f"start: {len(delta['added_triangles'])} triangles")

# The topmost surface point: its constraints are top (f = 0), top + n (outside) and top + 2n (inside).
top = int(np.argmax(p[:, 2]))
for step in range(5):  # drag the three up together, one step at a time
    lift = np.array([0.0, 0.0, 0.06 * (step + 1)])
    for k in (top, top + n, top + 2 * n):
        mesher.move(k, points[k] + lift)
    d = mesher.update_surface()
    print(f"step {step}: {len(d['removed_triangles'])} triangles removed, {len(d['added_triangles'])} added, "
          f"{mesher.stats()['edit_seconds'] * 1e3:.1f} ms")
bump = mesher.add([0.0, 0.0, -0.95], -0.1)  # a new constraint: inside, near the bottom
mesher.update_surface()
print(f"added constraint {bump}; {len(mesher)} constraints")

mesh = mesher.mesh()
if len(sys.argv) > 1:
    vitri.write(sys.argv[1], mesh)
print(f"final: {len(mesh.vertices)} vertices, {len(mesh.faces)} triangles, top at z = {mesh.vertices[:, 2].max():.3f}")
