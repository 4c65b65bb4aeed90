import numpy as np
import pytest


def fit_order(hs, errs):
    """Least-squares slope of log(err) against log(h)."""
    return float(np.polyfit(np.log(hs), np.log(errs), 1)[0])


@pytest.fixture
def order():
    return fit_order
