"""How a point cloud's samples are laid out: samples in lines (a scanner's) farther apart than
along them are named (surfaces/_cloud_analysis.lines_advice), with the cure that works."""

from __future__ import annotations

import numpy as np
import pytest

import tubesweep as ts


def latitude_rings(rings: int = 30, per_unit: float = 2000.0) -> np.ndarray:
    """Samples of the sphere of radius 0.5 on ``rings`` circles of latitude (about the y axis),
    ``per_unit`` samples per unit of a ring's radius: 0.0031 apart along them, 0.052 across."""
    out = []
    for th in np.linspace(0, np.pi, rings + 1)[1:-1]:
        r = 0.5 * np.sin(th)
        t = np.linspace(0, 2 * np.pi, max(int(per_unit * r), 8), endpoint=False)
        out.append(np.c_[r * np.cos(t), np.full_like(t, 0.5 * np.cos(th)), r * np.sin(t)])
    return np.concatenate(out)


def test_samples_in_lines_are_named_and_more_neighbours_cure_them():
    pts = latitude_rings()
    # each fit's 20 nearest samples lie on one ring: more than half the samples looked like a rim
    # (a closed sphere taken for an open surface), with no word
    with pytest.warns(
        RuntimeWarning, match=r"of the 19071 samples \((5\d|[6-9]\d|100)%\) see their neighbours on one side only"
    ):
        cloud = ts.surfaces.from_points(pts)
    assert cloud.report["rim_samples"] > 0.25 * len(pts)
    # the cure named: fits over 100 samples span several rings
    wide = ts.surfaces.from_points(pts, neighbours=100)
    assert wide.report["rim_samples"] == 0
    sol = ts.solve(wide, wide.grid(41), [np.array([0.0, 0.0, 0.5])])
    q = np.random.default_rng(0).normal(size=(2000, 3))
    q = 0.5 * q / np.linalg.norm(q, axis=1, keepdims=True)
    exact = 0.5 * np.arccos(np.clip(q @ [0.0, 0.0, 0.5] / 0.25, -1.0, 1.0))
    assert np.mean(np.abs(sol(q) - exact)) < 5e-4  # 2.8e-4


def test_an_open_cloud_is_not_taken_for_lines():
    # a hemisphere's rim is some 2 % of its samples, a strip 20 times longer than wide some 5 %
    x = np.random.default_rng(0).normal(size=(20000, 3))
    x = 0.5 * x / np.linalg.norm(x, axis=1, keepdims=True)
    strip = np.random.default_rng(1).uniform(0, 1, size=(20000, 3)) * [1.0, 0.05, 0.0]
    for pts in (x[x[:, 2] > 0], strip):
        cloud = ts.surfaces.from_points(pts)  # (the test log fails on any warning)
        assert 0 < cloud.report["rim_samples"] < 0.1 * len(pts)
    # a small patch's rim is a large share of it (here 27%), and no sign of lines
    rng = np.random.default_rng(0)
    r, a = np.sqrt(rng.random(100)) * 0.1, rng.uniform(0, 2 * np.pi, 100)
    patch = ts.surfaces.from_points(np.c_[r * np.cos(a), r * np.sin(a), 0.2 * r**2])
    assert patch.report["rim_samples"] > 0.25 * 100


def sliced_sphere(dz: float = 0.06, ds: float = 0.003) -> np.ndarray:
    """The sphere of radius 0.5 scanned in slices ``dz`` apart (samples ``ds`` apart along them),
    as a CT segmentation's contours are: nothing above the last slice (z = 0.49) nor below the
    first (z = −0.47), caps of radius 0.10 and 0.17 left unsampled."""
    out = []
    for z in np.arange(-0.5 + dz / 2, 0.5, dz):
        r = np.sqrt(0.25 - z * z)
        t = np.arange(max(8, int(2 * np.pi * r / ds))) * 2 * np.pi / max(8, int(2 * np.pi * r / ds))
        out.append(np.c_[r * np.cos(t), r * np.sin(t), np.full_like(t, z)])
    return np.concatenate(out)


def test_a_sliced_scan_with_unsampled_caps_solves_at_second_order():
    # refused before ("cp returned NaN ... samples off their neighbours' surface"): a node on the
    # axis of the last slice saw its ring's samples all at one distance, which weighed nothing,
    # and the feet over the wider cap, 1.25 fits' radii from every sample, were taken as off the
    # samples though the rim test bridged it. The caps are bridged by the fits now
    pts = sliced_sphere()
    cloud = ts.surfaces.from_points(pts, neighbours=100)  # (the test log fails on any warning)
    assert cloud.report["rim_samples"] == 0
    sol = ts.solve(cloud, cloud.grid(41), [(0.0, 0.0, 0.5)])
    assert sol.stats.order == 2 and sol.stats.order_fallback is None
    exact = 0.5 * np.arccos(np.clip(pts[:, 2] / 0.5, -1.0, 1.0))
    err = np.abs(sol(pts) - exact) / sol.grid.spacing
    assert np.mean(err) < 0.03 and np.max(err) < 0.15  # 0.015, 0.089


def sliced_torus(dz: float = 0.04, ds: float = 0.0075) -> np.ndarray:
    """A torus (R = 0.5, r = 0.2) sampled in horizontal slices ``dz`` apart, ``ds`` along each
    slice's two rings: the strips over the tube's top and bottom, between the last slices' rings,
    left unsampled."""
    out = []
    for z in np.arange(-0.2 + dz / 2, 0.2, dz):
        w = np.sqrt(0.04 - z * z)
        for rad in (0.5 - w, 0.5 + w):
            m = int(2 * np.pi * rad / ds)
            t = np.arange(m) * 2 * np.pi / m
            out.append(np.c_[rad * np.cos(t), rad * np.sin(t), np.full(m, z)])
    return np.concatenate(out)


def test_a_noise_free_cloud_s_runaway_is_not_blamed_on_noise():
    # a sliced torus, its strips over the tube's top and bottom unsampled, runs away at second
    # order with fits of 40 samples 0.0075 apart along the rings (at 0.003 apart, 60 neighbours
    # solve at second order and 80–100 run away): the samples lie on their fits (noise ~6e-7),
    # and the message blamed "samples a little off their neighbours' surface", which a larger
    # neighbours= was to smooth out
    cloud = ts.surfaces.from_points(sliced_torus(), neighbours=40)
    assert cloud.noise < 1e-6
    with pytest.warns(RuntimeWarning, match="ran away near") as said:
        sol = ts.solve(cloud, cloud.grid(61), [(0.7, 0.0, 0.0)])
    assert all("a little off" not in str(w.message) for w in said)
    assert any("not noise" in str(w.message) and "another neighbours=" in str(w.message) for w in said)
    # solved again with the nodes where it ran away at first order (about the strips: 51% of the
    # inner tube), second order elsewhere; before, order 1 everywhere
    o = sol.stats.order2
    assert sol.stats.order == 2 and sol.stats.order_fallback is None
    assert 0.4 < o["runaway"]["nodes"] / o["inner_nodes"] < 0.6
    # along the outer equator, the arclength (R + r)·θ: 0.003 spacings (order 1: 0.25)
    theta = np.linspace(0.0, 0.5, 30)
    equator = 0.7 * np.c_[np.cos(theta), np.sin(theta), 0 * theta]
    err = np.abs(sol(equator) - 0.7 * theta) / sol.grid.spacing
    assert np.max(err) < 0.02


def test_a_few_stray_samples_are_named_where_the_sweeps_run_away():
    # five samples 0.02 (0.4 spacings) off a clean sphere's 8,000 pass the outlier test and fold
    # the closest points near them: a third of the inner tube ran first order, and the message
    # blamed the fits over unevenly spread samples (a scan in lines or slices); they are named now
    rng = np.random.default_rng(0)
    x = rng.normal(size=(8000, 3))
    d = rng.normal(size=(5, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    strays = (0.5 + 0.02 * np.array([1, -1, 1, -1, 1]))[:, None] * d
    cloud = ts.surfaces.from_points(np.r_[0.5 * x / np.linalg.norm(x, axis=1, keepdims=True), strays])
    assert cloud.report["outliers"] == 0 and 0 < cloud.report["crease_samples"] < 0.005 * 8005
    with pytest.warns(RuntimeWarning, match="ran away near") as said:
        ts.solve(cloud, ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3), [tuple(0.5 * x[0] / np.linalg.norm(x[0]))])
    ran_away = [str(w.message) for w in said if "ran away near" in str(w.message)]
    assert any("too few for a sharp edge: stray points just off the surface" in m for m in ran_away)
    assert all("cloud.crease_samples lists them" in m for m in ran_away)
