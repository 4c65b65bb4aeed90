"""The bundled example meshes (tubesweep.data) and the rule that nothing a user runs needs a folder
beside the repository."""

import gzip
import re
from pathlib import Path

import numpy as np
import pytest

import tubesweep as ts

REPO = Path(__file__).resolve().parents[1]


def test_bundled_meshes_load_with_their_known_sizes_and_topology():
    v, f = ts.data.load("bunny")
    assert v.shape == (35947, 3) and f.shape == (69451, 3)
    assert f.min() == 0 and f.max() == len(v) - 1
    # the bunny is about 0.155 wide (the file's own units), y up
    assert np.allclose(v.max(0) - v.min(0), [0.1557, 0.1543, 0.1207], atol=2e-4)
    v, f = ts.data.load("spot")
    assert v.shape == (2930, 3) and f.shape == (5856, 3)
    spot = ts.surfaces.from_mesh(ts.data.spot())
    assert spot.closed and spot.name == "spot"
    # closed genus-0: V - E + F = 2
    edges = np.unique(np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1), axis=0)
    assert len(v) - len(edges) + len(f) == 2
    bunny = ts.surfaces.from_mesh(ts.data.bunny())
    assert not bunny.closed and bunny.name == "stanford-bunny"


def test_the_numpy_reader_agrees_with_trimesh_vertex_for_vertex(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    for name in ("spot", "bunny"):
        plain = tmp_path / f"{name}.obj"
        plain.write_bytes(gzip.decompress(ts.data.path(name).read_bytes()))
        m = trimesh.load(str(plain), force="mesh", process=False, maintain_order=True)
        v, f = ts.data.load(name)
        assert np.array_equal(np.asarray(m.vertices), v)
        assert np.array_equal(np.asarray(m.faces), f)


def test_data_errors_name_the_choices(tmp_path):
    with pytest.raises(ValueError, match=r"\['bunny', 'spot'\]"):
        ts.data.path("dragon")
    empty = tmp_path / "empty.obj"
    empty.write_text("# nothing\n")
    with pytest.raises(ValueError, match="no vertices"):
        ts.data.read_obj(empty)
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nf 1 2 3\n")
    with pytest.raises(ValueError, match="does not exist"):
        ts.data.read_obj(bad)


@pytest.mark.filterwarnings("default::RuntimeWarning")  # the CLI prints what a user sees: the default filter
def test_the_command_line_names_the_bundled_meshes(tmp_path, capsys):
    from tubesweep.cli import main

    assert main(["solve", "--mesh", "spot", "--n", "40", "--quiet", "--out", str(tmp_path)]) == 0
    assert "spot: grid" in capsys.readouterr().out


# the parent folder's name, split so that this file does not match its own pattern
_SIBLING = re.compile(r"\.\./" + "shared" + r"|[\"']" + "shared" + r"[\"']\s*/|parent\s*/\s*[\"']" + "shared")


def _user_files():
    for top in ("README.md", "Makefile", "pyproject.toml"):
        yield REPO / top
    for folder in ("docs", "python", "tests", "examples", "benches", ".github"):
        for p in sorted((REPO / folder).rglob("*")):
            if p.is_file() and p.suffix in {".md", ".py", ".pyi", ".toml", ".yml", ".yaml", ".txt", ".cfg", ""}:
                yield p


def test_nothing_a_user_runs_refers_to_a_folder_beside_the_repository():
    offenders = []
    for p in _user_files():
        if not p.is_file():
            continue
        for k, line in enumerate(p.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
            if _SIBLING.search(line):
                offenders.append(f"{p.relative_to(REPO)}:{k}: {line.strip()}")
    assert not offenders, "use ts.data.bunny() / ts.data.spot() instead:\n" + "\n".join(offenders)


def test_the_pattern_catches_the_ways_the_path_was_written():
    s = "sha" + "red"
    for line in (
        f"--mesh ../{s}/data/spot.obj",
        f'parents[1] / ".." / "{s}" / "data"',
        f'REPO.parent / "{s}" / "data"',
    ):
        assert _SIBLING.search(line), line
    assert not _SIBLING.search("a shared machine; shared by two faces")
