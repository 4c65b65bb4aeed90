"""ts.evolve says each kind of its steps' warnings once, with the steps (_step_warnings.py)."""

import warnings

import numpy as np
import pytest

import tubesweep as ts
from tubesweep._step_warnings import StepWarnings, _ranges


def test_steps_are_said_as_ranges():
    assert _ranges([0, 1, 2, 5, 7, 8]) == "0–2, 5, 7–8"
    assert _ranges([3]) == "3"


def test_warnings_differing_in_their_numbers_are_one_kind_said_once_with_the_last_text():
    said = StepWarnings()
    for step, gap in enumerate([0.5, 0.25, 0.125]):
        with said.step(step):
            warnings.warn(f"a gap of {gap} spacings", RuntimeWarning)
            if step == 1:
                warnings.warn("another kind", UserWarning)
                warnings.warn("another kind", UserWarning)  # twice in one step: the step once
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        said.say()
        said.say()  # forgotten once said
    assert [(w.category, str(w.message)) for w in caught] == [
        (RuntimeWarning, "a gap of 0.125 spacings (evolve: steps 0–2, the last one's figures)"),
        (UserWarning, "another kind (evolve: step 1)"),
    ]


def test_a_shrinking_sphere_s_warnings_come_once_per_kind_with_their_steps():
    # 12 warnings in 8 steps before (a narrow gap across the centre at 4 steps, the first-order
    # fallback from step 1: the sphere of radius 0.3 at step 0 runs second order); now one per
    # kind, said when the evolution stops
    grid = ts.Grid((-1,) * 3, (1,) * 3, (31,) * 3)
    X, Y, Z = grid.meshgrid()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(ts.EvolutionStopped):
            ts.evolve(np.sqrt(X**2 + Y**2 + Z**2) - 0.3, grid, [(0, 0, 0.3)], lambda u: -1 + 0 * u, dt=0.03, steps=20)
    texts = [str(w.message) for w in caught]
    assert len(texts) == 2, texts
    assert texts[0].startswith("order='auto' ran the paper's first-order scheme") and texts[0].endswith(
        "(evolve: steps 1–7, the last one's figures)"
    )
    assert "faces itself across gaps" in texts[1] and "(evolve: steps 4–7" in texts[1]
