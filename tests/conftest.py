import subprocess
import sys

import numpy as np
import pytest


def fit_order(hs, errs):
    """Least-squares slope of log(err) against log(h)."""
    return float(np.polyfit(np.log(hs), np.log(errs), 1)[0])


@pytest.fixture
def order():
    return fit_order


#: The start of the warning of ``order="auto"``'s first-order fallback on a grid that does not
#: resolve the surface (``tubesweep._fallback``).
FIRST_ORDER_SIZE = "order='auto' ran the paper's first-order scheme, whose errors are a few grid spacings"


@pytest.fixture
def first_order_size():
    """``first_order_size(expected)``: a context in which the solves raise no warning but the
    first-order fallback's size warning, asserted to fire ``expected`` times (``True``: once;
    ``None``: any number)."""
    import contextlib
    import warnings

    @contextlib.contextmanager
    def context(expected: "int | None" = 1):
        with warnings.catch_warnings(record=True) as record:
            warnings.simplefilter("always")
            yield record
        messages = [str(w.message) for w in record]
        sized = [m for m in messages if m.startswith(FIRST_ORDER_SIZE)]
        assert expected is None or len(sized) == int(expected), messages
        assert len(messages) == len(sized), messages

    return context


@pytest.fixture
def experiment():
    """``experiment(name)``: the module ``benches/experiments/<name>.py`` (the scenes some tests
    share with the experiments that measured them), loaded from its file."""
    import importlib.util
    from pathlib import Path

    def load(name: str):
        path = Path(__file__).resolve().parents[1] / "benches" / "experiments" / f"{name}.py"
        spec = importlib.util.spec_from_file_location(name, path)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module

    return load


@pytest.fixture
def without_scipy(tmp_path):
    """``without_scipy(body)``: runs ``body`` in a fresh interpreter in which scipy (an optional
    extra) cannot be imported, after ``import numpy as np`` and ``import tubesweep as ts``; asserts
    it exits cleanly and returns its printed words."""

    def run(body: str) -> list:
        script = tmp_path / "no_scipy.py"
        script.write_text(
            "import sys\nsys.modules['scipy'] = None\nimport numpy as np\nimport tubesweep as ts\n" + body
        )
        done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr[-2000:]
        return done.stdout.split()

    return run
