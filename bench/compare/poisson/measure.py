"""Measures one output mesh against its true model, in its own process so that a crash inside a library
(Debian's Open3D aborts on some inputs) becomes a failed row of compare.py, not the end of the sweep.

Usage: /usr/bin/python3 measure.py MODEL.off REFERENCE.npy MESH OUTPUT_SAMPLES SEED
REFERENCE.npy: the dense samples of the model (compare.py writes them). Prints one JSON object: the
output's topology (geometry.topology) and its two-sided distance to the model (relative to the model's
diagonal), or exits non-zero with a message."""
import json
import sys

import numpy as np

import geometry as geo


def main():
    model_path, reference_path, mesh_path = sys.argv[1:4]
    samples, seed = int(sys.argv[4]), int(sys.argv[5])
    model = geo.read_closed_model(model_path)
    V, F = geo.read_mesh(mesh_path)
    if len(F) == 0:
        sys.exit(f"measure: {mesh_path} has no triangles")
    frame = geo.Normalized(model[0])
    result = geo.topology(V, F, frame.diag)
    result.update(geo.two_sided_distance(frame, model, np.load(reference_path), (V, F), samples, seed))
    print(json.dumps(result))


if __name__ == "__main__":
    main()
