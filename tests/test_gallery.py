"""The gallery (examples/*.py) runs, at small sizes, writes its pictures and prints numbers that
hold: errors against exact answers, within a few grid spacings."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("matplotlib")

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def run(name: str, n: int, out: Path) -> str:
    done = subprocess.run(
        [sys.executable, "-W", "ignore", f"{name}.py", "--n", str(n), "--out", str(out)],
        cwd=EXAMPLES,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


def number(pattern: str, text: str) -> float:
    return float(re.search(pattern, text).group(1))


def test_every_example_is_in_the_gallery_and_the_tests():
    scripts = sorted(p.stem for p in EXAMPLES.glob("*.py") if not p.stem.startswith("_"))
    assert scripts == sorted(CASES)
    gallery = (EXAMPLES.parent / "docs" / "gallery.md").read_text()
    for s in scripts:
        assert f"examples/{s}.py" in gallery, s


CASES = {
    "sphere": (41, ["sphere.png"]),
    "bunny_path": (60, ["bunny_path.png"]),
    "torus_cells": (41, ["torus_cells.png"]),
    "open_surfaces": (41, ["hemisphere.png", "mobius.png"]),
    "moving_medium": (41, ["moving_medium.png"]),
    "layered_travel_time": (101, ["layered_travel_time.png"]),
    "distance_matrix": (31, ["distance_matrix.png"]),
    "point_cloud": (61, ["point_cloud.png"]),
    "pear_growth": (41, ["pear_growth.png"]),
    "mesh_order2": (61, ["mesh_order2.png"]),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_example(name, tmp_path):
    n, pictures = CASES[name]
    out = run(name, n, tmp_path)
    for p in pictures:
        assert (tmp_path / p).stat().st_size > 20_000, p
    h = 2.0 / (n - 1)
    if name == "sphere":
        assert number(r"max ([0-9.]+)", out) < 4 and number(r"mean ([0-9.]+)", out) < 1.5  # grid spacings
    elif name == "open_surfaces":
        assert number(r"max error ([0-9.]+) grid spacings", out) < 4
    elif name == "moving_medium":
        assert number(r"mean ([0-9.]+)", out) < 2 * h and number(r"max ([0-9.]+)", out) < 4 * h
        assert number(r"([0-9.]+) with the flow", out) < number(r"([0-9.]+) in still medium", out)
    elif name == "layered_travel_time":
        assert abs(number(r"time to \(0, -1\): ([0-9.]+)", out) - 0.4) < 2 * h
    elif name == "distance_matrix":
        assert number(r"max error ([0-9.]+)", out) < 4 * h
    elif name == "point_cloud":
        assert "order 2" in out and number(r"outer equator: mean ([0-9.e-]+)", out) < 0.1 * h
    elif name == "mesh_order2":
        smooth = number(r"smooth=True: order 2, mean error ([0-9.e-]+)", out)
        assert smooth < 0.03 * h and number(r"smooth=False: order 1, mean error ([0-9.e-]+)", out) > 20 * smooth
    elif name == "torus_cells":
        shares = [float(x) for x in re.search(r"\[([0-9. ]+)\]", out).group(1).split()]
        assert abs(sum(shares) - 1) < 0.01 and min(shares) > 0.15
    elif name == "pear_growth":
        z, exact = number(r"z = ([0-9.]+)", out), number(r"exact ([0-9.]+)", out)
        assert abs(z - exact) < 0.1 * h and "1 cold" in out
    elif name == "bunny_path":
        length = number(r"length ([0-9.]+)", out)
        assert abs(length - number(r"the distance there: ([0-9.]+)", out)) < 0.1 * length
