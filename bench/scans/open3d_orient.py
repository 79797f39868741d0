"""Open3D's normal estimation and orientation of unoriented points, timed and checked against the true
normals: the Open3D half of the orientation comparison (bench_orient is vitri's half).

Usage: /usr/bin/python3 open3d_orient.py POINTS.xyz [--reference CASE-n.xyz] [--exclude CASE.outliers]
                                         [--viewpoint FILE] [--knn 30]
estimate_normals(KDTreeSearchParamKNN(knn)), then orient_normals_towards_camera_location when a viewpoint is
given, else orient_normals_consistent_tangent_plane(knn). Prints one JSON object with the same fields as
bench_orient: points, seconds (estimate + orient), estimate_s, orient_s, status, and with a reference:
oriented (n . n_true > 0), tangent (|n . n_true| >= cos 25 degrees), flipped_tangent."""
import argparse
import json
import time

import numpy as np
import open3d as o3d


def main():
    p = argparse.ArgumentParser()
    p.add_argument("points")
    p.add_argument("--reference")
    p.add_argument("--exclude")
    p.add_argument("--viewpoint")
    p.add_argument("--knn", type=int, default=30)
    a = p.parse_args()
    xyz = np.loadtxt(a.points, usecols=(0, 1, 2))
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(xyz))
    result = {"points": len(xyz), "status": "ok"}
    start = time.perf_counter()
    try:
        cloud.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(a.knn))
        result["estimate_s"] = time.perf_counter() - start
        mid = time.perf_counter()
        if a.viewpoint:
            with open(a.viewpoint) as f:
                cloud.orient_normals_towards_camera_location(np.array([float(x) for x in f.read().split()[:3]]))
        else:
            cloud.orient_normals_consistent_tangent_plane(a.knn)
        result["orient_s"] = time.perf_counter() - mid
    except Exception as e:  # Open3D raises RuntimeError on some inputs
        result["status"] = f"refused: {e}"
    result["seconds"] = time.perf_counter() - start
    if a.reference and result["status"] == "ok":
        truth = np.loadtxt(a.reference, usecols=(3, 4, 5))
        n = np.asarray(cloud.normals)
        keep = np.ones(len(n), dtype=bool)
        if a.exclude:
            idx = np.loadtxt(a.exclude, dtype=np.int64, ndmin=1)
            keep[idx[idx < len(n)]] = False
        c = np.einsum("ij,ij->i", n, truth) / (np.linalg.norm(n, axis=1) * np.linalg.norm(truth, axis=1))
        c = c[keep]
        cos_tangent = np.cos(np.radians(25.0))
        result.update(counted=int(keep.sum()), oriented=float((c > 0).mean()),
                      tangent=float((np.abs(c) >= cos_tangent).mean()),
                      flipped_tangent=float((c <= -cos_tangent).mean()))
    print(json.dumps(result))


if __name__ == "__main__":
    main()
