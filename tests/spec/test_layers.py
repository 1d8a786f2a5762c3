"""spec.Layers, LayerSpill, save_npz and npz_layers, and the witness held in layers: what the
searches make and the checker reads on large grids (docs/model.md §11). Small grids here, with
the spill threshold lowered to 0 so that every witness goes through a spill file."""

from __future__ import annotations

import gc
import inspect
import io
import textwrap
import warnings
import zipfile
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cfmpa.spec._layers as layers_module
from cfmpa.impl import _fast_search, _kernel_cache, search_opt_path, search_opt_path_fast
from cfmpa.impl._search import WitnessLabels
from cfmpa.spec import (
    MOVES,
    Layers,
    LayerSpill,
    SearchStatus,
    Witness,
    check_witness,
    load_witness,
    save_npz,
)
from cfmpa.spec._layers import npz_layers
from dr_strategies import random_dr

WAIT = MOVES.index((0, 0))


def as_layers(a: np.ndarray) -> Layers:
    """``a`` through a spill file; the caller closes it (``with``), not the garbage collector."""
    spill = LayerSpill(a.shape, a.dtype)
    for layer in a:
        spill.append(layer)
    return spill.layers()


@pytest.fixture
def spill_everything(monkeypatch):
    monkeypatch.setattr(layers_module, "SPILL_BYTES", 0)


# --- the view -------------------------------------------------------------------------------


def test_layers_index_like_the_array_they_hold():
    a = np.arange(4 * 9 * 3 * 5, dtype=np.uint16).reshape(4, 9, 3, 5)
    with as_layers(a) as v:
        assert (v.shape, v.dtype, v.ndim, len(v), v.nbytes) == (a.shape, a.dtype, 4, 4, a.nbytes)
        for key in (2, -1, np.int64(1), (0, WAIT, 1, 4), (3, slice(None), 2, 0),
                    (1, 4, slice(1, 3), slice(0, 5)), (2, slice(None)), (0, [1, 2], 0, 0)):
            assert np.array_equal(v[key], a[key]), key
        assert np.array_equal(np.asarray(v), a) and np.asarray(v).dtype == a.dtype
        assert all(np.array_equal(x, y) for x, y in zip(v, a))
        with pytest.raises(IndexError):
            v[4]
        with pytest.raises(ValueError, match="read-only"):
            v[1][0, 0, 0] = 7                  # read-only: a checker cannot change a witness
        m = v.map(lambda x: x % 2 == 0, np.bool_)
        assert m.dtype == np.bool_ and np.array_equal(np.asarray(m), a % 2 == 0)
    with pytest.raises(ValueError, match="closed file"):
        v.layer(2)                             # closed where it ends: the file is gone


def test_the_view_reads_again_what_its_cache_let_go():
    reads = []
    a = np.arange(5 * 2).reshape(5, 2)
    v = Layers(a.shape, a.dtype, lambda s: reads.append(s) or a[s])
    for s in (0, 1, 0, 1, 2, 0, 4, 4):
        assert np.array_equal(v[s], a[s])
    assert reads == [0, 1, 2, 0, 4]            # the last two layers are kept, no more


def test_a_spill_refuses_a_wrong_layer_and_an_unfinished_read():
    with LayerSpill((2, 1, 3), np.uint16) as spill:
        with pytest.raises(ValueError, match=r"LayerSpill.append: layer 0 of shape \(4,\)"):
            spill.append(np.zeros(4))
        with pytest.raises(ValueError, match=r"LayerSpill.append: layer 0 of shape \(1, 2\)"):
            spill.append(np.zeros((1, 2)), (0, 1, 2, 4))          # the box leaves the layer
        spill.append(np.array([[1, 65535, 3]]))
        with pytest.raises(ValueError, match="LayerSpill.layers: 1 of 2 written"):
            spill.layers()
        with spill.widened(np.uint32) as wide:
            wide.append(np.array([[70000, 4, 4294967295]]))
            assert np.array_equal(np.asarray(wide.layers()),
                                  [[[1, 4294967295, 3]], [[70000, 4, 4294967295]]])
        spill.append(np.zeros((1, 3)))
        with pytest.raises(ValueError, match="LayerSpill.append: layer 2 .* at most 2 layers"):
            spill.append(np.zeros((1, 3)))


def test_a_spill_stores_the_box_of_what_is_not_fill_and_reads_the_rest_as_fill():
    a = np.full((4, 9, 6, 7), 65535, dtype=np.uint16)
    a[1, 3, 2, 4] = 5
    a[2, :, 1:3, 0:6] = 9
    a[3] = 1                                       # a full layer; layer 0 is all fill
    with LayerSpill(a.shape, a.dtype) as spill:
        spill.append(a[0])
        spill.append(a[1, :, 1:5, 2:7], (1, 5, 2, 7))  # a part, fill around what is given
        spill.append(a[2])
        spill.append(a[3])
        assert [box for _, box in spill._parts] == [(0, 0, 0, 0), (2, 3, 4, 5), (1, 3, 0, 6),
                                                   (0, 6, 0, 7)]
        assert spill._end == 2 * (9 * 1 + 9 * 2 * 6 + 9 * 6 * 7)
        assert np.array_equal(np.asarray(spill.layers()), a)
    with LayerSpill((2, 9, 3, 3), np.bool_) as reach:
        reach.append(np.zeros((9, 3, 3), dtype=bool))
        reach.append(np.eye(3, dtype=bool)[None].repeat(9, axis=0))
        assert np.asarray(reach.layers()).sum() == 27 and reach.fill == 0


# --- npz --------------------------------------------------------------------------------------


def test_save_npz_is_read_by_numpy_and_in_place(tmp_path):
    a = np.arange(3 * 4 * 5, dtype=np.uint32).reshape(3, 4, 5)
    b = np.arange(6, dtype=np.int64).reshape(2, 3) > 2
    f = tmp_path / "w.npz"
    with open(f, "wb") as fh, as_layers(a) as layers:
        save_npz(fh, {"format": np.array("x"), "a": layers, "b": b})
    with np.load(f) as z:
        assert str(z["format"]) == "x"
        assert np.array_equal(z["a"], a) and z["a"].dtype == a.dtype
        assert np.array_equal(z["b"], b)
    for name, want in (("a", a), ("b", b)):
        v = npz_layers(f, name)
        assert v is not None and np.array_equal(np.asarray(v), want) and v.dtype == want.dtype
    assert npz_layers(f, "nope") is None
    # Also np.savez's own files, and not a compressed one (numpy reads that whole).
    g = tmp_path / "s.npz"
    np.savez(g, a=a)
    assert np.array_equal(np.asarray(npz_layers(g, "a")), a)
    np.savez_compressed(g, a=a)
    assert npz_layers(g, "a") is None


def test_npz_layers_refuses_a_truncated_member(tmp_path):
    a = np.arange(4 * 100, dtype=np.uint16).reshape(4, 100)
    buf = io.BytesIO()
    save_npz(buf, {"a": a})
    data = buf.getvalue()
    f = tmp_path / "t.npz"
    f.write_bytes(data[: len(data) // 2])
    assert npz_layers(f, "a") is None


# --- the witness in layers --------------------------------------------------------------------


def cases():
    return random_dr(max_n=5, max_side=7, density=st.sampled_from([0.0, 0.15, 0.3, 0.45]),
                     free_ends=None)


@settings(max_examples=120, deadline=None)
@given(case=cases())
def test_a_spilled_witness_is_the_held_one_and_checks_the_same(case):
    dr, start, goal = case
    for search in (search_opt_path, search_opt_path_fast):
        held = search(dr, start, goal, with_witness=True)
        layers_module.SPILL_BYTES, saved = 0, layers_module.SPILL_BYTES
        try:
            spilled = search(dr, start, goal, with_witness=True)
        finally:
            layers_module.SPILL_BYTES = saved
        with spilled.witness:
            assert (spilled.status, spilled.path, spilled.J1, spilled.J2) == (
                held.status, held.path, held.J1, held.J2)
            assert held.witness.kind == spilled.witness.kind
            for k, a in held.witness.arrays.items():
                b = spilled.witness.arrays[k]
                assert isinstance(b, Layers)
                assert b.dtype == a.dtype and np.array_equal(np.asarray(b), a)
            assert check_witness(dr, start, goal, spilled, spilled.witness) == []


@settings(max_examples=120, deadline=None)
@given(case=random_dr(max_n=5, max_side=7, density=st.sampled_from([0.0, 0.15, 0.3]),
                      free_ends=True), data=st.data())
def test_a_corrupted_witness_in_layers_fails_as_the_array_does(case, data):
    dr, start, goal = case
    r = search_opt_path_fast(dr, start, goal, with_witness=True)
    if r.status is SearchStatus.FOUND:
        j1, j2 = r.witness.j1.copy(), r.witness.j2.copy()
        none = np.iinfo(j1.dtype).max
        states = [tuple(int(v) for v in x) for x in np.argwhere(j1 != none)]
        x = data.draw(st.sampled_from(states))
        j1[x] += data.draw(st.sampled_from([0, 1]))
        j2[x] += 1
        held, layered = Witness.of_labels(j1, j2), Witness.of_labels(as_layers(j1),
                                                                     as_layers(j2))
    else:
        reach = r.witness.reachable.copy()
        states = [tuple(int(v) for v in x) for x in np.argwhere(reach)] or [(0, WAIT, *start)]
        reach[data.draw(st.sampled_from(states))] ^= True
        held, layered = Witness.of_reachable(reach), Witness.of_reachable(as_layers(reach))
    want = check_witness(dr, start, goal, r, held)
    with layered:
        assert check_witness(dr, start, goal, r, layered) == want


def test_a_view_that_reads_the_wrong_layer_is_caught(monkeypatch):
    # Seeded fault in the view: a cache that gives the layer read first, whatever s is asked
    # for. The checker, reading a good witness through it, must reject it. (Not every wrong
    # layer is a fault the checker can see: labels of step s + 1 read for step s still bound
    # every path on a free grid, and the witness conditions are all that optimality needs.)
    dr = np.zeros((5, 6, 6), dtype=np.uint8)
    r = search_opt_path_fast(dr, (0, 0), (5, 3), with_witness=True)
    with Witness.of_labels(as_layers(r.witness.j1), as_layers(r.witness.j2)) as good:
        assert check_witness(dr, (0, 0), (5, 3), r, good) == []
    real = Layers.layer

    def stale(self, s):
        first = getattr(self, "_first", None)
        if first is None:
            first = self._first = real(self, s)
        return first

    monkeypatch.setattr(Layers, "layer", stale)
    with Witness.of_labels(as_layers(r.witness.j1), as_layers(r.witness.j2)) as bad:
        assert [f.condition for f in check_witness(dr, (0, 0), (5, 3), r, bad)] == [
            "witness.edge"]


def test_labels_widened_keep_no_label_as_no_label(spill_everything):
    for spill in (False, True):
        w = WitnessLabels(2, 1, 2, spill=spill)
        keys = np.full((9, 1, 2), np.int64(1) << np.int64(61))
        keys[WAIT, 0, 0] = 0
        w.put(0, keys)
        w.put(1, keys)
        keys[WAIT, 0, 0] = (np.int64(70000) << np.int64(31)) | 5
        w.put(2, keys)
        with w.witness(found=True) as witness:
            j1 = np.asarray(witness.j1)
        assert j1.dtype == np.uint32 and j1[2, WAIT, 0, 0] == 70000 and j1[0, WAIT, 0, 0] == 0
        assert (j1[:, :, 0, 1] == np.iinfo(np.uint32).max).all()   # never labelled


def test_a_start_blocked_witness_in_layers_is_the_empty_set(spill_everything):
    dr = np.zeros((3, 4, 4), dtype=np.uint8)
    dr[0, 0, 0] = 1
    r = search_opt_path_fast(dr, (0, 0), (3, 3), with_witness=True)
    with r.witness:
        assert isinstance(r.witness.reachable, Layers)
        assert not np.asarray(r.witness.reachable).any()
        assert check_witness(dr, (0, 0), (3, 3), r, r.witness) == []


def _left_open(run) -> list[str]:
    """The ResourceWarnings (a file closed by the garbage collector) while ``run()`` runs."""
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        run()
        gc.collect()
    return [str(w.message) for w in seen if issubclass(w.category, ResourceWarning)]


@pytest.mark.parametrize("blocked", [False, True], ids=["found", "no-path"])
def test_a_search_s_spill_files_end_with_its_witness(spill_everything, monkeypatch, blocked):
    # Every spill file of a search (the labels, the widened labels, the no-path set's unused
    # second labels) is closed by Witness.close, none left to the garbage collector.
    dr = np.zeros((4, 5, 5), dtype=np.uint8)
    dr[0, 0, 0] = blocked

    def run() -> None:
        for search in (search_opt_path, search_opt_path_fast):
            r = search(dr, (0, 0), (4, 4), with_witness=True)
            assert (r.witness.kind == "reachable") == blocked
            with r.witness:
                pass

    assert _left_open(run) == []
    # Seeded fault: a spill that is never closed (close does nothing): the GC says so.
    monkeypatch.setattr(LayerSpill, "close", lambda self: None)
    assert any("unclosed file" in m for m in _left_open(run))


def test_a_witness_file_in_layers_loads_in_place(spill_everything, tmp_path):
    dr = np.zeros((4, 5, 5), dtype=np.uint8)
    r = search_opt_path_fast(dr, (0, 0), (4, 4), with_witness=True)
    f = tmp_path / "w.npz"
    with r.witness:
        with open(f, "wb") as fh:
            save_npz(fh, r.witness.npz_members())
        with load_witness(f) as w:
            assert isinstance(w.j1, Layers) and isinstance(w.j2, Layers)
            assert np.array_equal(np.asarray(w.j1), np.asarray(r.witness.j1))
            assert check_witness(dr, (0, 0), (4, 4), r, w) == []
    with zipfile.ZipFile(f) as z:
        assert sorted(z.namelist()) == ["format.npy", "j1.npy", "j2.npy", "kind.npy"]


def test_the_kernels_warm_up_closes_the_witness_it_makes(monkeypatch):
    # The warm-up (impl/_kernel_cache.py) runs the fast search with a witness only to load its
    # kernels; the witness (spill files, above SPILL_BYTES) is closed there, not by the GC.
    made: list = []

    class Made:
        closed = False

        def close(self) -> None:
            self.closed = True

    def search(*args, with_witness=False, **kwargs):
        made.append(Made() if with_witness else None)
        return SimpleNamespace(witness=made[-1])

    monkeypatch.setattr(_fast_search, "search_opt_path_fast", search)
    _kernel_cache._warm("search")
    assert [w.closed for w in made if w is not None] == [True]
    # Seeded fault: the warm-up without its close (its source, the close cut out).
    src = textwrap.dedent(inspect.getsource(_kernel_cache._warm))
    cut = "        if found.witness is not None:\n            found.witness.close()"
    assert src.count(cut) == 1
    ns: dict = {}
    exec(src.replace(cut, "        pass"), dict(_kernel_cache._warm.__globals__), ns)  # noqa: S102
    made.clear()
    ns["_warm"]("search")
    assert [w.closed for w in made if w is not None] == [False]
