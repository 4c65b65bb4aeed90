"""The API reference: every public function, class and method has a numpydoc docstring (Parameters,
Returns, Examples; Raises where it raises), its examples run, and the documentation site builds in
strict mode (a broken reference fails)."""

import doctest
import importlib
import inspect
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import tubesweep as ts

REPO = Path(__file__).resolve().parents[1]

MODULES = [
    "tubesweep.solve", "tubesweep.tube", "tubesweep.stats", "tubesweep.grid", "tubesweep.surface",
    "tubesweep.closest_point", "tubesweep.euclidean", "tubesweep.output", "tubesweep._plot", "tubesweep.data",
    "tubesweep.flows", "tubesweep.hamiltonians", "tubesweep.surfaces.analytic", "tubesweep.surfaces.closed",
    "tubesweep.surfaces.curves", "tubesweep.surfaces.open", "tubesweep.surfaces.mesh", "tubesweep.distances",
    "tubesweep.solution", "tubesweep.band", "tubesweep._triangulate",
    "tubesweep.box_solution",
]  # fmt: skip


def public_objects():
    """ts's public names, the library's surfaces, flows, Hamiltonians and data, with their public methods."""
    objs = {}
    for name in ts.__all__:
        o = getattr(ts, name)
        if not inspect.ismodule(o) and not name.startswith("__"):
            objs[f"ts.{name}"] = o
    for mod, names in ((ts.surfaces, [n for n in ts.surfaces.__all__ if n != "REGISTRY"]), (ts.data, ts.data.__all__),
                       (ts.flows, ["point_vortices", "solid_body_rotation", "rotation_travel_time_circle",
                                   "rotation_travel_time_sphere"]),
                       (ts.hamiltonians, ["Hamiltonian", "Isotropic", "MovingMedium", "Metric"])):  # fmt: skip
        for n in names:
            o = getattr(mod, n)
            if inspect.isfunction(o) or inspect.isclass(o):
                objs[f"{mod.__name__}.{n}"] = o
    for key, o in list(objs.items()):
        if inspect.isclass(o) and o.__module__.startswith("tubesweep"):
            for m, f in vars(o).items():
                if (not m.startswith("_") or m == "__call__") and inspect.isfunction(f):
                    objs[f"{key}.{m}"] = f
    return {k: o for k, o in objs.items() if getattr(o, "__module__", "").startswith("tubesweep")}


def test_every_public_object_has_a_numpydoc_docstring():
    missing = []
    for key, o in sorted(public_objects().items()):
        doc = inspect.getdoc(o) or ""
        need = ["Examples"]
        try:
            params = [p for p in inspect.signature(o).parameters if p not in ("self", "cls")]
        except (TypeError, ValueError):
            params = []
        if params:
            # a class the library constructs (Solution, SolveStats) documents its Attributes instead
            need.append("Attributes" if inspect.isclass(o) and "\nAttributes\n" in f"\n{doc}\n" else "Parameters")
        if inspect.isfunction(o):
            ret = inspect.signature(o).return_annotation
            if ret not in (None, "None", inspect.Signature.empty):
                need.append("Returns")
        missing += [f"{key}: {s}" for s in need if f"\n{s}\n" not in f"\n{doc}\n"]
    assert not missing, "\n".join(missing)


@pytest.mark.parametrize("name", MODULES)
def test_the_docstring_examples_run(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # an example that writes a file writes it here
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.failed == 0


@pytest.mark.skipif(shutil.which("mkdocs", path=os.path.dirname(sys.executable)) is None,
                    reason="mkdocs not installed (make docs installs it)")  # fmt: skip
def test_the_documentation_site_builds_in_strict_mode(tmp_path):
    mkdocs = shutil.which("mkdocs", path=os.path.dirname(sys.executable))
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    done = subprocess.run([mkdocs, "build", "--strict", "-q", "-d", str(tmp_path / "site")], cwd=REPO,
                          capture_output=True, text=True, env=env, timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    api = (tmp_path / "site" / "api" / "solve" / "index.html").read_text()
    assert "Parameters" in api and "Examples" in api and "first-arrival" in api.lower()
