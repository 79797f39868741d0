"""Open3D's screened Poisson reconstruction of one scan, stage by stage, for bench/scans/run_scans.py.

Usage: /usr/bin/python3 open3d_poisson.py IN.xyz OUT.ply [--depth 10] [--viewpoint FILE] [--knn 30]
                                          [--trim 0.05]
Stages (each timed, with the process's peak resident memory after it):
  read     the .xyz (3 columns, or 6 with normals)
  normals  when the file has none: estimate_normals(KDTreeSearchParamKNN(knn))
  orient   when the file has none: orient_normals_towards_camera_location(viewpoint) when a viewpoint is
           given, else orient_normals_consistent_tangent_plane(knn)
  poisson  create_from_point_cloud_poisson(depth) (Open3D's defaults otherwise: width 0, scale 1.1,
           linear_fit False)
  trim     remove_vertices_by_mask(densities < quantile(densities, trim)), Open3D's tutorial recipe
  write    binary PLY
Prints one JSON object on the last line: the stage times (s), peak memory (MB) after each stage, the
point count and the output's vertex and triangle counts."""
import argparse
import json
import resource
import sys
import time

import numpy as np
import open3d as o3d


def peak_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main():
    p = argparse.ArgumentParser()
    p.add_argument("input")
    p.add_argument("output")
    p.add_argument("--depth", type=int, default=10)
    p.add_argument("--viewpoint")
    p.add_argument("--knn", type=int, default=30)
    p.add_argument("--trim", type=float, default=0.05)
    a = p.parse_args()
    result = {"depth": a.depth}
    stage = {"t": time.perf_counter()}

    def done(name):
        now = time.perf_counter()
        result[f"{name}_s"] = round(now - stage["t"], 3)
        result[f"{name}_peak_mb"] = round(peak_mb(), 1)
        stage["t"] = now

    with open(a.input) as f:
        columns = len(f.readline().split())
    cloud = o3d.io.read_point_cloud(a.input, format="xyzn" if columns >= 6 else "xyz")
    result["points"] = len(cloud.points)
    if len(cloud.points) == 0:
        sys.exit(f"open3d_poisson: no points read from {a.input}")
    done("read")
    if columns >= 6:
        result["normals"] = "given"
    else:
        cloud.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(a.knn))
        done("normals")
        if a.viewpoint:
            with open(a.viewpoint) as f:
                eye = np.array([float(x) for x in f.read().split()[:3]])
            cloud.orient_normals_towards_camera_location(eye)
            result["normals"] = "estimated, towards the viewpoint"
        else:
            cloud.orient_normals_consistent_tangent_plane(a.knn)
            result["normals"] = "estimated, consistent tangent plane"
        done("orient")
    mesh, densities = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(cloud, depth=a.depth)
    done("poisson")
    result["untrimmed_vertices"] = len(mesh.vertices)
    if a.trim > 0 and len(mesh.vertices) > 0:
        densities = np.asarray(densities)
        mesh.remove_vertices_by_mask(densities < np.quantile(densities, a.trim))
    done("trim")
    if not o3d.io.write_triangle_mesh(a.output, mesh, write_ascii=False, write_vertex_normals=False,
                                      write_vertex_colors=False):
        sys.exit(f"open3d_poisson: could not write {a.output}")
    done("write")
    result["vertices"] = len(mesh.vertices)
    result["triangles"] = len(mesh.triangles)
    print(json.dumps(result))


if __name__ == "__main__":
    main()
