"""A sweep's table does not depend on its batch cut where rows share an ensemble call (issue 33).

The earlier batch-cut test swept rows that do not depend on the other rows of their call, so a
wrong cut of the ensemble chunks passed. Here rows share their call's setting (the fixture
`shared_call` makes every row's metric depend on the whole call, as an ensemble whose tolerance
or step came from all its particles would), the ensemble is adaptive, the chunks are small, and
Monte Carlo draws put rows out of bounds, rejected before the call: the valid rows of a batch are
then not its rows. The table must still be bitwise the same for any batch size; a cut by position
among a batch's valid rows instead of by the sweep's row (planted) fails here.
"""

import numpy as np
import pytest

from rotframe.app import sweep
from rotframe.app.sweep import batch, execute


def assert_bitwise(a, b):
    """Every column the same bits (NaN rows included, which pyarrow's equals counts as different)."""
    assert a.column_names == b.column_names
    for name in a.column_names:
        x, y = a.column(name).to_numpy(zero_copy_only=False), b.column(name).to_numpy(zero_copy_only=False)
        if x.dtype.kind == "f":
            x, y = x.view(np.int64), y.view(np.int64)
        assert np.array_equal(x, y), name


@pytest.fixture
def small_chunks(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    for module in (batch, execute):  # the chunk that both the batches and the calls are cut by
        monkeypatch.setattr(module, "ENSEMBLE_CHUNK", 4)


@pytest.fixture
def shared_call(monkeypatch):
    """Each row's metrics also carry the sum of the heights in its call: rows that share a call share a setting.

    rotframe's own ensembles keep each particle's numbers its own today, so without this a wrong cut
    of the calls would not change a number; with it, any change of which rows share a call does.
    """
    original = batch._ensemble_call

    def sharing(scene, scn, task, run, values_list, tracks):
        out = original(scene, scn, task, run, values_list, tracks)
        if tracks is None:
            shared = sum(float(v["height"]) for v in values_list)
            for metrics in out:
                metrics["fall_time_s"] = metrics["fall_time_s"] + shared
        return out

    monkeypatch.setattr(batch, "_ensemble_call", sharing)


def test_rows_sharing_an_adaptive_call_do_not_depend_on_the_batch_cut(small_chunks, shared_call):
    spec = sweep.parse_spec("tower-drop", samples=30, vary=["height=normal(60,80)"], seed=2, method="dop853")
    whole = sweep.run_sweep(spec, "whole.parquet", batch_rows=30, plots=False, recording=False)
    table = whole.table.to_pandas()
    rejected = table["error"].astype(bool)
    assert 0 < int(rejected.sum()) < len(table)  # some draws are out of bounds, rejected before the call
    heights = table.loc[~rejected, "height"]
    assert heights.max() / heights.min() > 10  # the calls' scales differ: a row's atol depends on its call
    for rows in (7, 1):
        cut = sweep.run_sweep(spec, f"cut{rows}.parquet", batch_rows=rows, plots=False, recording=False)
        assert_bitwise(cut.table, whole.table)
    assert np.all(np.isfinite(table.loc[~rejected, "east_deflection_m"]))
