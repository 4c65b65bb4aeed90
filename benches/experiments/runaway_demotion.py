"""What ``order=2`` gives where its factored sweeps run away (``second_order/demotion.rs``): solved
again with the runaway's nodes at the paper's first-order update and second order elsewhere,
against the paper's scheme (``order=1``), which ``order="auto"`` returned before.

Per case: the order that ran, the inner-tube nodes put at first order (share), and the largest
error against the exact travel times of ``order="auto"`` and of ``order=1``. The circle of radius
0.5 with its right half 1000 times faster (N = 201, 401) from sources on the slow side at
distances from the fast half, and the sphere with its half 100 times faster (N = 41); a source
inside a small region 100 times slower than the rest of the sphere (the first attempt stands: the
paper's scheme)::

    .venv/bin/python benches/experiments/runaway_demotion.py
"""

from __future__ import annotations

import warnings

import numpy as np

import tubesweep as ts

R = 0.5


def arc_time(a0: float, a1: float, contrast: float) -> float:
    """Travel time along the circle from angle a0 to a1 (a1 > a0) with speed ``contrast`` at x > 0."""
    a = np.linspace(a0, a1, 20001)
    slowness = np.where(np.cos(a) > 0, 1.0 / contrast, 1.0)
    return float(np.sum(0.5 * (slowness[:-1] + slowness[1:]) * R * np.diff(a)))


def circle(n: int, source_angle: float, contrast: float = 1000.0) -> dict:
    g = ts.Grid((-1.0, -1.0), (1.0, 1.0), (n, n))
    X = g.meshgrid()
    speed = np.where(X[0] > 0, contrast, 1.0)
    surf = ts.LevelSet(np.sqrt(X[0] ** 2 + X[1] ** 2) - R)
    angles = np.linspace(-np.pi, np.pi, 721)[:-1]
    points = R * np.c_[np.cos(angles), np.sin(angles)]
    exact = np.array(
        [
            min(
                arc_time(source_angle, source_angle + (t - source_angle) % (2 * np.pi), contrast),
                arc_time(source_angle + (t - source_angle) % (2 * np.pi), source_angle + 2 * np.pi, contrast),
            )
            for t in angles
        ]
    )
    src = [tuple(R * np.array([np.cos(source_angle), np.sin(source_angle)]))]
    return compare(surf, g, src, speed, points, exact)


def sphere_half(n: int, contrast: float = 100.0) -> dict:
    g = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
    X = g.meshgrid()
    speed = np.where(X[0] > 0, contrast, 1.0)
    far = np.array([[R, 0.0, 0.0]])
    return compare(
        ts.surfaces.Sphere(R), g, [(-R, 0.0, 0.0)], speed, far, np.array([0.25 * np.pi * (1 + 1 / contrast)])
    )


def slow_bubble(n: int) -> dict:
    g = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
    x = np.stack(g.meshgrid(), -1)
    speed = np.where(np.linalg.norm(x - [R, 0, 0], axis=-1) < 0.15, 1e-2, 1.0)
    rng = np.random.default_rng(0)
    p = rng.normal(size=(400, 3))
    p = R * p / np.linalg.norm(p, axis=1, keepdims=True)
    d = R * np.arccos(np.clip(p[:, 0] / R, -1, 1))
    rb = 2 * R * np.arcsin(0.15 / (2 * R))
    exact = 100 * np.minimum(d, rb) + np.maximum(d - rb, 0)
    return compare(ts.surfaces.Sphere(R), g, [(R, 0.0, 0.0)], speed, p, exact)


def compare(surf, g, src, speed, points, exact) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        auto = ts.solve(surf, g, src, speed=speed)
        paper = ts.solve(surf, g, src, speed=speed, order=1)
    o = auto.stats.order2 or {}
    runaway = o.get("runaway")
    share = runaway["nodes"] / o["inner_nodes"] if runaway else None
    return {
        "order": auto.stats.order,
        "share": share,
        "auto": float(np.max(np.abs(auto(points) - exact))),
        "paper": float(np.max(np.abs(paper(points) - exact))),
    }


def main() -> None:
    rows = []
    for n in (201, 401):
        for label, angle in (
            ("opposite the fast half", np.pi),
            ("15 spacings at N = 201 from it", -np.pi / 2 - 0.3),
            ("on its edge", -np.pi / 2),
        ):
            rows.append((f"circle, source {label}, N = {n}", circle(n, angle)))
    rows.append(("sphere, half 100× faster, antipode, N = 41", sphere_half(41)))
    rows.append(("sphere, source in a region 100× slower, N = 61", slow_bubble(61)))
    print("| case | order | first-order share | max error auto | max error order=1 |")
    print("|---|---|---|---|---|")
    for label, r in rows:
        share = "—" if r["share"] is None else f"{100 * r['share']:.0f}%"
        print(f"| {label} | {r['order']} | {share} | {r['auto']:.2e} | {r['paper']:.2e} |")


if __name__ == "__main__":
    main()
