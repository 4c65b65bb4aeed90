"""Fingerprints of the re-distanced band (``LevelSet(phi, redistance=True).band(grid, 4Δx)``,
``tubesweep_core::surface::redistance_band``) for nine kinds of sampled φ at N = 81 and 121: the
sphere's quadric |x|² − R², its voxel mask and the mask smoothed (σ = 1.5), the gyroid-like
φ = sin4x·cos4y + sin4y·cos4z + sin4z·cos4x, the sphere's distance with Gaussian noise of 1e-3
(seed 0), two spheres joined by ``min``, a torus quartic, a cube ``max|x| − 0.5`` and a sphere's
distance rounded to float32 and scaled by 3. Printed per case: the band's size and a hash of its
linear indices and signed distances (the same hash: the same bits). ``--save F.npz`` keeps the
bands; ``--against F.npz`` (saved by another build) prints, per case, the nodes only one build has
and the largest difference of the signed distances at the nodes both have, in grid spacings.

Run it on two builds (for instance a ``git worktree`` of an earlier commit with its own
``make build``) to see what a change of the re-distancing does to the band:

    .venv/bin/python benches/experiments/band_fingerprints.py [N ...] [--save F.npz] [--against F.npz]
    # default N: 81 121
"""

from __future__ import annotations

import hashlib
import sys
import warnings

import numpy as np

import tubesweep as ts
from tubesweep.mask import level_set_function_of_mask


def cases(grid: ts.Grid) -> dict:
    X, Y, Z = grid.meshgrid()
    r2 = X**2 + Y**2 + Z**2
    noise = np.random.default_rng(0).standard_normal(X.shape)
    return {
        "quadric": r2 - 0.25,
        "mask": np.where(r2 < 0.25, -0.5, 0.5),
        "smoothed mask": level_set_function_of_mask(r2 < 0.25, grid, 1.5),
        "gyroid-like": np.sin(4 * X) * np.cos(4 * Y) + np.sin(4 * Y) * np.cos(4 * Z) + np.sin(4 * Z) * np.cos(4 * X),
        "noisy sphere": np.sqrt(r2) - 0.5 + 1e-3 * noise,
        "min union": np.minimum(
            np.sqrt((X - 0.3) ** 2 + Y**2 + Z**2) - 0.4, np.sqrt((X + 0.3) ** 2 + Y**2 + Z**2) - 0.4
        ),
        "torus": (np.sqrt(X**2 + Y**2) - 0.6) ** 2 + Z**2 - 0.25**2,
        "cube": np.maximum(np.maximum(abs(X), abs(Y)), abs(Z)) - 0.5,
        "float32 ×3": (np.sqrt(r2) - 0.5).astype(np.float32).astype(np.float64) * 3,
    }


def main(ns, save: str | None, against: str | None) -> None:
    kept: dict = {}
    other = dict(np.load(against)) if against else None
    for n in ns:
        grid = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
        for name, phi in cases(grid).items():
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                band = ts.LevelSet(phi, redistance=True).band(grid, 4 * grid.spacing)
            digest = hashlib.sha256()
            digest.update(np.ascontiguousarray(band.linear, dtype=np.uint64).tobytes())
            digest.update(np.ascontiguousarray(band.signed, dtype=np.float64).tobytes())
            line = f"N={n:4d} {name:14s} band nodes {len(band.linear):8d}  {digest.hexdigest()[:16]}"
            key = f"{n}:{name}"
            kept[key + ":linear"], kept[key + ":signed"] = np.asarray(band.linear), np.asarray(band.signed)
            if other is not None and key + ":linear" in other:
                lo, so = other[key + ":linear"], other[key + ":signed"]
                both, here, there = np.intersect1d(band.linear, lo, return_indices=True)
                diff = np.max(np.abs(np.asarray(band.signed)[here] - so[there]), initial=0.0) / grid.spacing
                line += (
                    f"  against: {len(band.linear) - len(both)} / {len(lo) - len(both)} nodes in one only, "
                    f"largest |Δ signed| {diff:.2e} Δx"
                )
            print(line, flush=True)
    if save:
        np.savez(save, **kept)


if __name__ == "__main__":
    args = sys.argv[1:]
    options = {}
    for flag in ("--save", "--against"):
        if flag in args:
            i = args.index(flag)
            options[flag] = args[i + 1]
            args = args[:i] + args[i + 2 :]
    main([int(a) for a in args] or [81, 121], options.get("--save"), options.get("--against"))
