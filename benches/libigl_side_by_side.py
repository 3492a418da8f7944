#!/usr/bin/env python3
"""Clay's ARAP iteration side by side with libigl's, interleaved in one run (not part of CI).

Builds the grid of `clayc bench --arap-grid K` (K x K vertices one unit apart, each square
split along its (i, j)-(i+1, j+1) diagonal, the left column pinned, the right column dragged
by (0.3, 0.5) * K over 30 frames, one iteration per frame) for libigl's `arap_solve` (spokes
energy, prefactored, `max_iter = 1`), and times both in turn, round after round:

    python3 benches/libigl_side_by_side.py --clayc target/release/clayc 100 316

Prints each round's per-iteration medians and their ratio Clay / libigl, then the median
ratio over the rounds. Installs the `libigl` pip package (2.6.3 is the version measured in
docs/performance.md) when it cannot be imported.

Equal work: one iteration is, for both, one local step (rotation fits), one right-hand side
and one solve with a prefactored matrix. Clay's local step also sums the elastic energy its
monotonicity guard reads, and its time per iteration is the whole frame (handle targets, the
rigid-following check) divided by its one iteration; libigl's is the time of the
`arap_solve` call, including the binding's copies of the positions. The two converge to
different shapes: libigl's cotangent weights give the grid's diagonals weight 0 (right
triangles), where Clay weighs every edge 1.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time


def import_igl():
    try:
        import igl  # noqa: F401
    except ImportError:
        subprocess.check_call([sys.executable, "-m", "pip", "install", "libigl==2.6.3"])
    import igl

    return igl


def grid(k, np):
    """Vertices, triangles, pinned and dragged vertex indices of the K x K grid."""
    ij = np.array([(i, j) for j in range(k) for i in range(k)], dtype=np.float64)
    tris = []
    for j in range(k - 1):
        for i in range(k - 1):
            a, b, c, d = j * k + i, j * k + i + 1, (j + 1) * k + i + 1, (j + 1) * k + i
            tris += [(a, b, c), (a, c, d)]
    left = [j * k for j in range(k)]
    right = [j * k + k - 1 for j in range(k)]
    return ij, np.array(tris, dtype=np.int64), left, right


def libigl_round(igl, np, k, frames):
    """Median milliseconds of one `arap_solve` iteration over the drag."""
    v, f, left, right = grid(k, np)
    b = np.array(left + right, dtype=np.int32)
    data = igl.ARAPData()
    data.max_iter = 1
    data.energy = igl.ARAP_ENERGY_TYPE_SPOKES
    igl.arap_precomputation(v, f, 2, b, data)
    u = v.copy()
    offset = np.array([0.3, 0.5]) * k
    times = []
    for frame in range(1, frames + 1):
        bc = v[b].copy()
        bc[len(left):] += offset * (frame / frames)
        t = time.perf_counter()
        u = igl.arap_solve(bc, data, u)
        times.append((time.perf_counter() - t) * 1e3)
    return statistics.median(times[1:])


def clay_round(clayc, k, frames):
    out = subprocess.run(
        [clayc, "bench", "--arap-grid", str(k), "--frames", str(frames), "--json"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return json.loads(out)["iteration_ms"]["median"]


def main():
    default = os.path.join(os.environ.get("CARGO_TARGET_DIR", "target"), "release", "clayc")
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("sizes", nargs="*", type=int, default=[100, 316], help="grid sizes K")
    ap.add_argument("--clayc", default=default, help="the clayc binary (release)")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--frames", type=int, default=30)
    args = ap.parse_args()
    igl = import_igl()
    import numpy as np

    for k in args.sizes:
        print(f"K = {k} ({k * k} vertices), {args.rounds} rounds of {args.frames} frames")
        ratios = []
        for r in range(args.rounds):
            clay = clay_round(args.clayc, k, args.frames)
            ref = libigl_round(igl, np, k, args.frames)
            ratios.append(clay / ref)
            print(f"  round {r + 1}: clay {clay:.3f} ms, libigl {ref:.3f} ms, ratio {clay / ref:.2f}")
        lo, hi = min(ratios), max(ratios)
        print(f"  Clay / libigl per iteration: median {statistics.median(ratios):.2f} ({lo:.2f}-{hi:.2f})")
    print("(equal work: one local step, one right-hand side, one prefactored solve each;")
    print(" see this script's docstring for what each time includes)")


if __name__ == "__main__":
    main()
