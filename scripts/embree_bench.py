#!/usr/bin/env python3
"""Trace `radiosity bench`'s occlusion rays with Embree, for a side-by-side figure.

    pip install embreex numpy
    radiosity bench --skip-large --dump-rays /tmp/rays.bin --force
    python3 scripts/embree_bench.py /tmp/rays.bin

The file holds the same triangles and segments the bench traces with our BVH (see
`dump_rays` in src/bench_cmd.rs). Each segment is traced as an occlusion ray with the same
end margins as ours (1e-4 of the segment at both ends). embreex traces on one thread, so
compare with the bench's 1-thread figure. It prints Embree's rays/s and its blocked count,
which must match ours to a few rays in a million (edge grazes differ between kernels).
"""

import struct
import sys
import time

import numpy as np
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh


def main() -> int:
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    with open(sys.argv[1], "rb") as f:
        data = f.read()
    ntri, nseg = struct.unpack_from("<II", data, 0)
    off = 8
    tris = np.frombuffer(data, dtype="<f4", count=ntri * 9, offset=off).reshape(ntri, 3, 3)
    off += ntri * 36
    segs = np.frombuffer(data, dtype="<f4", count=nseg * 6, offset=off).reshape(nseg, 2, 3)
    a, b = segs[:, 0, :].astype(np.float32), segs[:, 1, :].astype(np.float32)
    d = (b - a).astype(np.float32)
    margin = np.float32(1e-4)
    origins = (a + d * margin).astype(np.float32)
    dirs = np.ascontiguousarray(d, dtype=np.float32)
    tfar = np.full(nseg, 1.0 - 2.0 * margin, dtype=np.float32)

    t = time.perf_counter()
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(scene, np.ascontiguousarray(tris, dtype=np.float32))
    origins_c = np.ascontiguousarray(origins)
    # The first query commits (builds) the scene: time it apart from tracing.
    scene.run(origins_c[:1], dirs[:1], dists=tfar[:1].copy(), query="OCCLUDED")
    build = time.perf_counter() - t

    best = None
    for _ in range(3):
        t = time.perf_counter()
        hits = scene.run(origins_c, dirs, dists=tfar.copy(), query="OCCLUDED")
        secs = time.perf_counter() - t
        best = secs if best is None else min(best, secs)
    blocked = int(np.count_nonzero(np.asarray(hits) != -1))
    print(
        f"Embree (embreex, 1 thread): {ntri} triangles, build {build:.2f} s, "
        f"{nseg / best / 1e6:.2f} M rays/s, {100.0 * blocked / nseg:.1f} % of {nseg} segments blocked"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
