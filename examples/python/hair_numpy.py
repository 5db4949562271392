"""Reads the demo's strand file (out/groom_head.npz, `flexkin run examples/groom_head.json`) with
numpy alone, no flexkin, and prints what the hair did (docs/strands.md, "The strand file"):

- how far each point of the strands travelled over the run, from the root (point 0) to the tip,
  against how far it would have travelled had every strand been rigid with the head: the motion
  dies out toward the tips;
- every link's length in the file against its rest length (float32 files round the coordinates
  to 7 digits; the run's own error, in double, is groom.json's report.max_length_error).

    /usr/bin/python3 examples/python/hair_numpy.py [out/groom_head.npz]
"""
import json
import sys

import numpy as np


def main(path):
    with np.load(path) as h:
        points = h["points"].astype(np.float64)  # (F, P, 3)
        offsets, rotation, translation = h["offsets"], h["body_rotation"], h["body_translation"]
        rest = h["link_lengths"]
        info = json.loads(h["groom.json"])
    frames, _, dim = points.shape
    counts = np.diff(offsets)
    if len(set(counts)) != 1:
        sys.exit("this example expects strands of one link count")
    strands, n = len(counts), counts[0]
    s = points.reshape(frames, strands, n, dim)
    # The strands as they were at the first frame, carried rigidly by the body's pose.
    body = np.einsum("ji,snj->sni", rotation[0], s[0] - translation[0])
    rigid = np.einsum("fij,snj->fsni", rotation, body) + translation[:, None, None, :]
    travelled = np.linalg.norm(np.diff(s, axis=0), axis=3).sum(axis=0).mean(axis=0)
    carried = np.linalg.norm(np.diff(rigid, axis=0), axis=3).sum(axis=0).mean(axis=0)
    print(f"{path}: {strands} strands of {n - 1} links, {frames} frames, {info['method']}, "
          f"{info['precision']}")
    print("point along the strand       " + " ".join(f"{j:6d}" for j in range(0, n, 4)))
    print("mean path travelled (m)      " + " ".join(f"{travelled[j]:6.3f}" for j in range(0, n, 4)))
    print("as if rigid with the head (m)" + " ".join(f"{carried[j]:6.3f}" for j in range(0, n, 4)))
    lengths = np.linalg.norm(np.diff(s, axis=2), axis=3).reshape(frames, -1)
    file_error = np.max(np.abs(lengths - rest) / rest)
    print(f"largest relative link-length error: {file_error:.2g} in the file's "
          f"{info['precision']} coordinates, {info['report']['max_length_error']:.2g} in the "
          f"run (double)")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/groom_head.npz")
