"""Shared by the gallery scripts: the command line (grid size, output folder) and saving."""

import argparse
from pathlib import Path

import numpy as np


def options(doc: str, n: int) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=doc.strip().splitlines()[0])
    p.add_argument("--n", type=int, default=n, help=f"grid nodes per axis (default: {n})")
    p.add_argument(
        "--out", type=Path, default=Path("out/gallery"), help="folder for the picture (default: out/gallery)"
    )
    return p.parse_args()


def save(fig, out: Path, name: str) -> Path:
    out.mkdir(parents=True, exist_ok=True)
    path = out / name
    fig.savefig(path, dpi=110, bbox_inches="tight")
    print(f"wrote {path}")
    return path


def sphere_points(n: int, radius: float = 0.5, seed: int = 0, upper: bool = False) -> np.ndarray:
    """``n`` random points on the sphere of ``radius`` about the origin (the upper half only with ``upper``)."""
    x = np.random.default_rng(seed).normal(size=(n, 3))
    if upper:
        x[:, 2] = np.abs(x[:, 2])
    return radius * x / np.linalg.norm(x, axis=1, keepdims=True)
