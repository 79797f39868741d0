"""One Open3D screened Poisson reconstruction, run in its own process by compare.py so that its wall time
and peak memory are measured alone (/usr/bin/time -v around this script).

Usage: /usr/bin/python3 poisson_run.py POINTS.ply DEPTH OUT.ply
Reads oriented points (PLY with normals), calls create_from_point_cloud_poisson with the given depth and
Open3D's defaults otherwise (width 0, scale 1.1, linear_fit False, all threads), keeps the whole output
(no density trimming: Open3D returns per-vertex densities and removes nothing itself), writes the mesh as
binary PLY and prints one line `poisson_s=<seconds of the reconstruction call> vertices=<n>`."""
import sys
import time

import open3d as o3d


def main():
    points, depth, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    cloud = o3d.io.read_point_cloud(points)
    if not cloud.has_normals() or len(cloud.points) == 0:
        sys.exit(f"poisson_run: {points} holds no oriented points")
    start = time.perf_counter()
    mesh, _densities = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(cloud, depth=depth)
    seconds = time.perf_counter() - start
    if not o3d.io.write_triangle_mesh(out, mesh, write_ascii=False, write_vertex_normals=False,
                                      write_vertex_colors=False):
        sys.exit(f"poisson_run: could not write {out}")
    print(f"poisson_s={seconds:.3f} vertices={len(mesh.vertices)}")


if __name__ == "__main__":
    main()
