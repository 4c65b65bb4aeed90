"""Is the narrow-gap warning on the bundled meshes a false alarm? The error of ``order=1`` against
exact polyhedral geodesics (pygeodesic, MMP) at the vertices within 3 grid spacings of a flagged
pair (``sol.narrow_gaps()``) and at the others, for Spot and the bunny (source: the vertex
farthest from the centroid), in grid spacings (u − exact: negative is too short)::

    .venv/bin/python benches/experiments/narrow_gaps_meshes.py          # about a minute

Where the front crossed a gap, the vertices near the pairs would come out shorter than the rest.
"""

from __future__ import annotations

import warnings

import numpy as np
from scipy.spatial import cKDTree

import tubesweep as ts


def main() -> None:
    import pygeodesic.geodesic as geodesic

    warnings.simplefilter("ignore")  # the warning under study
    for name in ("spot", "bunny"):
        m = ts.surfaces.from_mesh(getattr(ts.data, name)())
        V, F = np.asarray(m.vertices, float), np.asarray(m.faces, np.int32)
        src = int(np.argmax(np.linalg.norm(V - V.mean(0), axis=1)))
        exact, _ = geodesic.PyGeodesicAlgorithmExact(V, F).geodesicDistances(np.array([src]), None)
        for n in (60, 120):
            g = m.grid(n)
            sol = ts.solve(m, g, [V[src]], order=1)
            err = (sol.on_mesh(V) - exact) / g.spacing
            mid, _ = sol.narrow_gaps()
            near = cKDTree(mid).query(V)[0] < 3 * g.spacing if len(mid) else np.zeros(len(V), bool)
            ok = np.isfinite(err) & np.isfinite(exact)

            def summary(s: np.ndarray) -> str:
                return f"min {err[s].min():.2f} mean {err[s].mean():.2f} ({s.sum()} vertices)"

            print(f"{name} N={n}: {len(mid)} pairs; near them {summary(ok & near)} | elsewhere {summary(ok & ~near)}")


if __name__ == "__main__":
    main()
