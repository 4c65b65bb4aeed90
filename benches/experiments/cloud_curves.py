"""Is a 3D cloud a curve or a surface? The spread that ``from_points`` reads to refuse curves.

Usage::

    .venv/bin/python benches/experiments/cloud_curves.py

For clouds of curves (a circle and a helix of 3000 samples, the circle with noise of 0.6% of its
radius) and of surfaces (a sphere, a hemisphere, a strip 20 times longer than wide, a sphere
sampled in latitude rings 13 sample spacings apart), prints
``surfaces._cloud_analysis.curve_spread`` over the default 20 neighbours: the median of the second
over the largest eigenvalue of the covariance of each sample's 80 nearest samples. ``from_points``
refuses a cloud under ``CURVE_SPREAD``.
"""

from __future__ import annotations

import numpy as np

from tubesweep.surfaces._cloud_analysis import CURVE_SPREAD, analyse_own, curve_spread


def clouds() -> dict:
    rng = np.random.default_rng(0)
    t = rng.uniform(0, 2 * np.pi, 3000)
    circle = np.c_[0.5 * np.cos(t), 0.5 * np.sin(t), 0 * t]
    x = rng.normal(size=(20000, 3))
    sphere = 0.5 * x / np.linalg.norm(x, axis=1, keepdims=True)
    u = rng.uniform(0, 1, (6000, 2))
    rings = []
    for lat in np.linspace(0.05, np.pi - 0.05, 60):
        phi = np.linspace(0, 2 * np.pi, int(2 * np.pi * 0.5 * np.sin(lat) / 0.002), endpoint=False)
        rings.append(0.5 * np.c_[np.sin(lat) * np.cos(phi), np.sin(lat) * np.sin(phi), np.cos(lat) + 0 * phi])
    return {
        "circle": circle,
        "helix": circle + np.c_[0 * t, 0 * t, 0.1 * t],
        "circle, noise 0.6% of r": circle + 0.003 * rng.normal(size=(3000, 3)),
        "sphere": sphere,
        "hemisphere": sphere[sphere[:, 2] > 0],
        "strip 20 x 1": np.c_[u[:, 0], 0.05 * u[:, 1], 0 * u[:, 0]],
        "sphere in latitude rings": np.concatenate(rings),
    }


def main() -> int:
    print(f"curve_spread over 20 neighbours (from_points refuses below {CURVE_SPREAD:g})")
    for name, p in clouds().items():
        p = np.ascontiguousarray(p)
        spread = curve_spread(analyse_own(p, 20).cloud, p, 20)
        print(f"  {name:28s} {len(p):6d} samples  {spread:.2g}  {'curve' if spread < CURVE_SPREAD else 'surface'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
