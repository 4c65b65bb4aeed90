"""`tubesweep reproduce fig9 --quick` writes its files and reports converging errors."""

import csv

import pytest

pytest.importorskip("matplotlib")


def test_fig9_quick(tmp_path):
    from tubesweep.reproduce import experiments

    run = experiments()["fig9"]
    summary = run(tmp_path, True)
    for name in ("fig9.png", "fig9_convergence.png", "fig9_errors.csv", "fig9.md"):
        assert (tmp_path / name).stat().st_size > 0
    rows = list(csv.DictReader(open(tmp_path / "fig9_errors.csv")))
    assert len(rows) == len(summary["rows"]) == 8
    hemi = {
        int(r["N"]): float(r["max_error"])
        for r in rows
        if r["surface"] == "hemisphere" and r["hamiltonian"] == "godunov"
    }
    assert hemi[81] < hemi[41] / 2 and hemi[81] < 0.05
    assert "| hemisphere | godunov | 81 |" in (tmp_path / "fig9.md").read_text()
