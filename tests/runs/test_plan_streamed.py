"""D_R in a store, built and read a block of layers at a time in this process (docs/model.md §9):
`cfmpa dr|plan --store zarr` (and the default above CFMPA_ZARR_CELLS) build D_R with the fast
kernel a block of layers at a time straight into the temporary dr.zarr (runs/_drdask.py
``build_store`` with workers 0, the code path of --workers K), then check and search it from the
store, never whole: the same dr.zarr byte for byte and the same plan.json (timings aside) as the
whole build. The full contracts' readers of D_R (``dr_shape_failures``, ``dr_postcondition`` at
every cell, ``check_witness``) take a ``spec.Layers`` as they take an ndarray, with the same
verdicts. Seeded faults: the whole build put back, a checker that converts D_R whole.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import factory
from cfmpa.cli import main
from cfmpa.impl import build_dr_fast, search_opt_path_fast
from cfmpa.runs import _drstore, _plan
from cfmpa.runs._selftest import WORKCELLS
from cfmpa.spec import Layers, Variant, _builtdr_post, _triples, _witness, load_scenario, make_grid


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """The small workcell's file, its whole build (modified) and that build's dr.zarr in chunks
    of two layers (written by the whole-array writer)."""
    d = tmp_path_factory.mktemp("streamed")
    toml = d / "small.toml"
    toml.write_text(factory.toml(WORKCELLS["small"]))
    s = load_scenario(toml)
    whole = build_dr_fast(s, Variant.MODIFIED, make_grid(s), progress=False)
    path, sha = _drstore.write_zarr_atomic(d / "whole" / "dr.zarr", whole, layers_per_chunk=2)
    return toml, s, whole, path, sha


@pytest.fixture
def two_layer_chunks(small, monkeypatch):
    g = make_grid(small[1])
    monkeypatch.setattr(_drstore, "CHUNK_BYTES", 2 * g.m * g.n)


def _files(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*"))
            if p.is_file()}


def _doc(folder: Path) -> dict[str, Any]:
    doc = json.loads((folder / "plan.json").read_text())
    del doc["timings_s"]
    return doc


def _no_whole(monkeypatch) -> None:
    """D_R's whole forms made to raise: the whole-array writer, the store's whole read and the
    layers' conversion to an ndarray."""
    def whole(*args: Any, **kw: Any) -> Any:
        raise AssertionError("D_R held whole")

    monkeypatch.setattr(_drstore, "write_zarr_atomic", whole)
    monkeypatch.setattr(_drstore.ZarrDr, "read", whole)
    monkeypatch.setattr(Layers, "__array__", whole)


def test_a_zarr_plan_streams_d_r_and_writes_the_whole_builds_files(small, two_layer_chunks,
                                                                   tmp_path, monkeypatch,
                                                                   capsys):
    toml, _, _, store, sha = small
    npy = tmp_path / "npy"
    assert main(["plan", str(toml), "--out", str(npy), "--store", "npy"]) == 0
    _no_whole(monkeypatch)
    out = tmp_path / "zarr"
    assert main(["plan", str(toml), "--out", str(out), "--store", "zarr"]) == 0
    printed = capsys.readouterr().out
    assert "engine    " not in printed                  # this process: nothing said of Dask
    assert _files(out / "dr.zarr") == _files(store)     # byte for byte the whole build's
    got, want = _doc(out), _doc(npy)
    assert got.pop("dr_store") == "zarr" and want.pop("dr_store") == "npy"
    assert got == want and got["dr_sha256"] == sha
    assert got["contracts"]["mode"] == "full" and not got["contracts"]["violations"]
    assert (out / "traj.csv").read_bytes() == (npy / "traj.csv").read_bytes()
    assert [p.name for p in tmp_path.joinpath("zarr").iterdir()
            if p.name.startswith(".dr.zarr.")] == []


def test_the_default_store_above_the_threshold_streams_too(small, two_layer_chunks, tmp_path,
                                                          monkeypatch, capsys):
    toml, _, _, store, _ = small
    monkeypatch.setenv("CFMPA_ZARR_CELLS", "0")
    _no_whole(monkeypatch)
    out = tmp_path / "out"
    assert main(["plan", str(toml), "--out", str(out), "--contracts", "off"]) == 0
    assert main(["dr", str(toml), "--out", str(tmp_path / "dr")]) == 0
    capsys.readouterr()
    assert _files(out / "dr.zarr") == _files(store)
    assert _files(tmp_path / "dr" / "dr.zarr") == _files(store)


def test_seeded_fault_the_whole_build_put_back_is_caught(small, two_layer_chunks, tmp_path,
                                                        monkeypatch, capsys):
    _no_whole(monkeypatch)
    monkeypatch.setattr(_plan, "_store_engine", lambda *args: None)
    with pytest.raises(AssertionError, match="held whole"):
        main(["plan", str(small[0]), "--out", str(tmp_path / "out"), "--store", "zarr"])
    capsys.readouterr()


@pytest.mark.parametrize("module, name", [(_triples, "layered"), (_witness, "layered"),
                                          (_builtdr_post, "take_cells")])
def test_seeded_fault_a_full_contract_reading_d_r_whole_is_caught(small, two_layer_chunks,
                                                                  tmp_path, monkeypatch,
                                                                  capsys, module, name):
    """Each reader's layer-at-a-time access put back to np.asarray: the zarr plan with full
    contracts then converts the store's layers whole, and the test above would fail."""
    _no_whole(monkeypatch)
    if name == "layered":
        monkeypatch.setattr(module, name, np.asarray)
    else:
        monkeypatch.setattr(module, name, lambda a, k, i, j: np.asarray(a)[k, i, j])
    with pytest.raises(AssertionError, match="held whole"):
        main(["plan", str(small[0]), "--out", str(tmp_path / "out"), "--store", "zarr"])
    capsys.readouterr()


# --- the same verdicts on Layers as on an ndarray --------------------------------------------

def _layers(a: np.ndarray) -> Layers:
    return Layers(a.shape, a.dtype, lambda s: a[s].copy())


def test_the_shape_check_gives_the_same_verdict_on_layers(small):
    _, s, whole, _, _ = small
    g = make_grid(s)
    assert _triples.dr_shape_failures(g, _layers(whole)) == []
    bad = whole.copy()
    bad[3, 1, 2] = 2
    bad[4, 0, 0] = 7
    want = _triples.dr_shape_failures(g, bad)
    assert want and _triples.dr_shape_failures(g, _layers(bad)) == want


def test_every_cell_check_gives_the_same_verdict_on_layers(small):
    _, s, whole, _, _ = small
    g = make_grid(s)
    v = Variant.MODIFIED
    ok = _builtdr_post.dr_postcondition(s, v, g, _layers(whole))
    assert ok.ok and ok == _builtdr_post.dr_postcondition(s, v, g, whole)
    bad = whole.copy()
    bad[2] ^= 1                       # a flipped layer: many cells wrong, the first shown
    want = _builtdr_post.dr_postcondition(s, v, g, bad)
    assert not want.ok and _builtdr_post.dr_postcondition(s, v, g, _layers(bad)) == want
    cells = np.array([[2, 0, 0], [2, 1, 1], [0, 3, 4]])
    assert (_builtdr_post.dr_postcondition(s, v, g, _layers(bad), cells=cells)
            == _builtdr_post.dr_postcondition(s, v, g, bad, cells=cells))


def test_take_cells_reads_each_layer_once_in_any_order(small):
    whole = small[2]
    read: list[int] = []
    a = Layers(whole.shape, whole.dtype, lambda s: read.append(s) or whole[s])
    k = np.array([[3, 0], [3, 1]])
    i = np.array([[1, 2], [0, 0]])
    j = np.array([[4, 1], [2, 3]])
    from cfmpa.spec._layers import take_cells

    got = take_cells(a, k, i, j)
    assert got.shape == (2, 2) and (got == whole[k, i, j]).all()
    assert sorted(read) == [0, 1, 3]
    assert take_cells(a, np.zeros(0, int), np.zeros(0, int), np.zeros(0, int)).shape == (0,)


def test_the_witness_check_gives_the_same_verdict_on_layers(small):
    _, s, whole, _, _ = small
    start, goal = s.right.start_cell, s.right.goal_cell
    r = search_opt_path_fast(whole, start, goal, with_witness=True)
    assert _witness.check_witness(_layers(whole), start, goal, r, r.witness) == []
    bad = whole.copy()
    k, (i, j) = 1, r.path[1]
    bad[k, i, j] = 1                  # the path's second cell blocked: the labels now lie
    want = _witness.check_witness(bad, start, goal, r, r.witness)
    assert want and _witness.check_witness(_layers(bad), start, goal, r, r.witness) == want


@pytest.mark.parametrize("argv, option", [(["--store", "npy"], "--store"),
                                          (["--kernel", "reference"], "--kernel")])
def test_a_whole_d_r_over_its_budget_is_refused_before_any_work(small, tmp_path, monkeypatch,
                                                               capsys, argv, option):
    toml, s, _, _, _ = small
    monkeypatch.setenv("CFMPA_MAX_WHOLE_CELLS", str(s.cells - 1))
    for command in ("plan", "dr"):
        out = tmp_path / command
        assert main([command, str(toml), "--out", str(out), *argv]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "Traceback" not in err
        assert err.startswith(f"error: {option} keeps D_R whole in memory")
        assert f"got {argv[1]!r}" in err and f"its {s.cells:,} cells are over the budget of " \
               f"{s.cells - 1:,} cells for a D_R held whole (CFMPA_MAX_WHOLE_CELLS)" in err
        assert not out.exists()
    # The same grid streamed into dr.zarr by the fast kernel is within the (larger) cell budget.
    assert main(["dr", str(toml), "--out", str(tmp_path / "z"), "--store", "zarr"]) == 0
