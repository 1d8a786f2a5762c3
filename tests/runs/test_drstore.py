"""D_R's two stores (docs/model.md §9): dr.npy and the chunked dr.zarr hold the same array with the
same dr_sha256; `cfmpa check` and `check --batch` read either; a corrupt or oversized store is
exit 2 with one line naming the file; an interrupted write leaves no dr.zarr; the default store
follows the grid's cells; the searches read a store a chunk at a time with the same answer."""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

import factory
from cfmpa.cli import main
from cfmpa.errors import InputError
from cfmpa.files import npy_bytes
from cfmpa.impl import search_opt_path, search_opt_path_fast
from cfmpa.runs import _drstore
from cfmpa.runs._drstore import (
    dr_sha256_of,
    load_dr,
    open_dr_layers,
    open_zarr,
    write_dr,
    zarr_threshold,
)
from cfmpa.runs._plan import plan, write_plan
from cfmpa.runs._selftest import WORKCELLS
from cfmpa.spec import load_scenario, make_grid


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """The small workcell's file, its plan (modified), and that plan written both ways; the zarr
    one in chunks of two layers (several chunks, the last one short)."""
    d = tmp_path_factory.mktemp("drstore")
    (d / "small.toml").write_text(factory.toml(WORKCELLS["small"]))
    s = load_scenario(d / "small.toml")
    p = plan(s, "modified", contracts="off")
    write_plan(p, d / "npy", store="npy")
    m, n = p.dr.shape[1:]
    saved = _drstore.CHUNK_BYTES
    _drstore.CHUNK_BYTES = 2 * m * n
    try:
        write_plan(p, d / "zarr", store="zarr")
    finally:
        _drstore.CHUNK_BYTES = saved
    return d, s, p


def _doc(folder: Path) -> dict:
    return json.loads((folder / "plan.json").read_text())


def _cli(argv: list[str], capsys) -> tuple[int, str, str]:
    code = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


# --- one array, two stores, one hash -------------------------------------------------------------


def test_npy_and_zarr_hold_the_same_array_with_the_same_sha256(small):
    d, s, p = small
    npy, zarr_dir = d / "npy" / "dr.npy", d / "zarr" / "dr.zarr"
    assert not (d / "npy" / "dr.zarr").exists() and not (d / "zarr" / "dr.npy").exists()
    a, sha_a = load_dr(npy, make_grid(s).shape)
    b, sha_b = load_dr(zarr_dir, make_grid(s).shape)
    assert np.array_equal(a, p.dr) and np.array_equal(b, p.dr) and b.dtype == np.uint8
    # dr_sha256 is the .npy bytes' hash for both: the file's, and the same bytes for the store
    file_sha = hashlib.sha256(npy.read_bytes()).hexdigest()
    assert sha_a == sha_b == file_sha == dr_sha256_of(p.dr)
    assert hashlib.sha256(npy_bytes(p.dr)).hexdigest() == file_sha
    doc_npy, doc_zarr = _doc(d / "npy"), _doc(d / "zarr")
    assert doc_npy["dr_sha256"] == doc_zarr["dr_sha256"] == file_sha
    assert (doc_npy["dr_store"], doc_zarr["dr_store"]) == ("npy", "zarr")
    # plan.json is otherwise the same document
    for doc in (doc_npy, doc_zarr):
        del doc["timings_s"], doc["dr_store"]
    assert doc_npy == doc_zarr


def test_the_zarr_store_is_chunked_compressed_and_any_zarr_reader_opens_it(small):
    zarr = pytest.importorskip("zarr")
    d, _, p = small
    z = zarr.open_array(d / "zarr" / "dr.zarr", mode="r")
    assert z.shape == p.dr.shape and z.dtype == np.uint8
    assert z.chunks == (2, *p.dr.shape[1:])
    assert np.array_equal(z[:], p.dr)
    meta = json.loads((d / "zarr" / "dr.zarr" / "zarr.json").read_text())
    assert [c["name"] for c in meta["codecs"]] == ["bytes", "zstd"]
    assert meta["attributes"]["cfmpa"]["format"] == "cfmpa-dr-1"
    st = open_zarr(d / "zarr" / "dr.zarr", p.dr.shape)
    assert st.chunks == -(-p.dr.shape[0] // 2) > 2
    assert all(st.chunk_path(c).is_file() for c in range(st.chunks))   # every chunk written


def test_a_store_written_in_chunks_of_one_layer_reads_back(tmp_path):
    rng = np.random.default_rng(7)
    dr = (rng.random((5, 4, 6)) < 0.4).astype(np.uint8)
    path, sha = write_dr(tmp_path, dr, "zarr", layers_per_chunk=1)
    got, sha2 = load_dr(path, dr.shape)
    assert np.array_equal(got, dr) and sha == sha2 == dr_sha256_of(dr)
    assert open_zarr(path).chunks == 5


# --- reading: cfmpa check, check --batch ---------------------------------------------------------


def test_cfmpa_check_accepts_a_zarr_plan_folder(small, capsys):
    d, _, _ = small
    code, out, err = _cli(["check", str(d / "small.toml"), "--dr", str(d / "zarr" / "dr.zarr"),
                           "--plan", str(d / "zarr" / "plan.json")], capsys)
    assert code == 0 and err == "", out
    assert "ok    plan.json dr_sha256 is the dr file's" in out
    assert out.rstrip().endswith("result: all checks hold")


def test_a_zarr_store_paired_with_a_npy_plan_json_checks_too(small, capsys):
    """The hash is the array's: a dr.zarr matches the plan.json written beside a dr.npy."""
    d, _, _ = small
    code, out, _ = _cli(["check", str(d / "small.toml"), "--dr", str(d / "zarr" / "dr.zarr"),
                         "--plan", str(d / "npy" / "plan.json")], capsys)
    assert code == 0, out


def test_a_zarr_of_another_array_fails_the_hash_check(small, tmp_path, capsys):
    d, _, p = small
    other = p.dr.copy()
    other[0, 0, 0] ^= 1
    write_dr(tmp_path, other, "zarr")
    code, out, _ = _cli(["check", str(d / "small.toml"), "--dr", str(tmp_path / "dr.zarr"),
                         "--plan", str(d / "zarr" / "plan.json")], capsys)
    assert code == 1
    assert "FAIL  plan.json dr_sha256 is the dr file's" in out


def test_check_batch_reads_npy_and_zarr_plan_folders(small, tmp_path, capsys):
    d, _, _ = small
    root = tmp_path / "plans"
    shutil.copytree(d / "npy", root / "a-npy")
    shutil.copytree(d / "zarr", root / "b-zarr")
    shutil.copytree(d / "zarr", root / "c-zarr-unnamed")      # plan.json without dr_store
    doc = _doc(root / "c-zarr-unnamed")
    del doc["dr_store"]
    (root / "c-zarr-unnamed" / "plan.json").write_text(json.dumps(doc))
    code, out, _ = _cli(["check", "--batch", str(root), str(d / "small.toml"), "--workers", "0"],
                        capsys)
    assert code == 0, out
    rows = {r["folder"]: r for r in json.loads((root / "check-batch.json").read_text())["rows"]}
    assert {k: r["status"] for k, r in rows.items()} == {
        "a-npy": "ok", "b-zarr": "ok", "c-zarr-unnamed": "ok"}


# --- a corrupt or oversized store: exit 2, one line naming the file ------------------------------


def _corrupt_chunk(store: Path) -> Path:
    f = store / "c" / "1" / "0" / "0"
    data = bytearray(f.read_bytes())
    data[len(data) // 2] ^= 0xFF
    f.write_bytes(bytes(data))
    return f


def _meta(key: str, value):
    def edit(store: Path) -> Path:
        meta = json.loads((store / "zarr.json").read_text())
        if key == "chunk_shape":
            meta["chunk_grid"]["configuration"]["chunk_shape"] = value
        else:
            meta[key] = value
        (store / "zarr.json").write_text(json.dumps(meta))
        return store / "zarr.json"
    return edit


def _oversized_chunk(store: Path) -> Path:
    f = store / "c" / "0" / "0" / "0"
    f.write_bytes(f.read_bytes() + b"\0" * 10**6)
    return f


def _bomb_chunk(store: Path) -> Path:
    """A valid zstd frame of ten times the chunk's size (nothing else wrong)."""
    from numcodecs.zstd import Zstd

    st = open_zarr(store)
    f = st.chunk_path(0)
    f.write_bytes(Zstd(level=1).encode(np.zeros(10 * st.layers_per_chunk * st.shape[1]
                                                * st.shape[2], np.uint8).tobytes()))
    return f


def _short_chunk(store: Path) -> Path:
    from numcodecs.zstd import Zstd

    f = store / "c" / "0" / "0" / "0"
    f.write_bytes(Zstd(level=1).encode(b"\x01" * 17))
    return f


def _truncated_meta(store: Path) -> Path:
    text = (store / "zarr.json").read_text()
    (store / "zarr.json").write_text(text[: len(text) // 2])
    return store / "zarr.json"


def _huge_meta(store: Path) -> Path:
    with open(store / "zarr.json", "wb") as fh:
        fh.write(b" " * (2 * 1024 * 1024))
    return store / "zarr.json"


def _no_meta(store: Path) -> Path:
    (store / "zarr.json").unlink()
    return store / "zarr.json"


CORRUPT = {
    "a chunk's bytes changed (zstd checksum)": (_corrupt_chunk, "does not decode"),
    "a chunk larger than its layers compress to": (_oversized_chunk, "the store is corrupt"),
    "a chunk that decodes to more than its size": (_bomb_chunk, "does not decode"),
    "a chunk that decodes to less than its size": (_short_chunk, "does not decode"),
    "zarr.json cut short": (_truncated_meta, "is not JSON"),
    "zarr.json of 2 MiB": (_huge_meta, "larger than the limit"),
    "zarr.json missing": (_no_meta, "cannot be read"),
    "another grid's shape": (_meta("shape", [10**6, 10**6, 10**6]), "is not the scenario's grid"),
    "float64 cells": (_meta("data_type", "float64"), "must be \"uint8\""),
    "chunks that cut a layer": (_meta("chunk_shape", [2, 3, 3]), "whole layers"),
    "a codec cfmpa does not read": (_meta("codecs", [{"name": "bytes"}, {"name": "gzip"}]),
                                    "codecs"),
    "zarr format 2": (_meta("zarr_format", 2), "zarr_format"),
}


@pytest.mark.parametrize("case", list(CORRUPT))
def test_a_corrupt_store_is_exit_2_naming_the_file(small, tmp_path, capsys, case):
    d, _, _ = small
    store = tmp_path / "dr.zarr"
    shutil.copytree(d / "zarr" / "dr.zarr", store)
    spoil, words = CORRUPT[case]
    named = spoil(store)
    code, out, err = _cli(["check", str(d / "small.toml"), "--dr", str(store), "--plan",
                           str(d / "zarr" / "plan.json")], capsys)
    assert code == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"{named}: error: ") and words in lines[0], lines[0]


def test_a_store_with_chunks_too_large_to_hold_is_refused_unread(tmp_path):
    dr = np.zeros((3, 4, 5), np.uint8)
    path, _ = write_dr(tmp_path, dr, "zarr")
    _meta("shape", [3, 30000, 30000])(path)
    _meta("chunk_shape", [1, 30000, 30000])(path)
    with pytest.raises(InputError) as exc:       # no grid given: the cell budget
        load_dr(path)
    assert "has 2,700,000,000 cells, over the budget of 2,000,000,000" in str(exc.value)
    with pytest.raises(InputError) as exc:       # the grid's shape, in chunks too large
        load_dr(path, (3, 30000, 30000))
    assert "over 268,435,456" in str(exc.value) and "zarr.json" in str(exc.value)


def test_a_npy_over_the_cell_budget_is_refused_from_its_header(small, tmp_path, capsys,
                                                               monkeypatch):
    d, s, _ = small
    big = tmp_path / "dr.npy"
    np.save(big, np.zeros((40, 100, 100), np.uint8))          # 400,000 bytes
    monkeypatch.setenv("CFMPA_MAX_CELLS", "10000")
    with pytest.raises(InputError) as exc:
        load_dr(big, (2, 3, 4))
    assert "over the 10,000 bytes of the cell budget" in str(exc.value)
    assert str(big) in str(exc.value)


def test_a_missing_chunk_reads_as_the_fill_value(tmp_path):
    """As Zarr specifies (cfmpa writes every chunk; another writer may skip all-zero ones)."""
    dr = np.ones((4, 3, 3), np.uint8)
    path, _ = write_dr(tmp_path, dr, "zarr", layers_per_chunk=2)
    (path / "c" / "1" / "0" / "0").unlink()
    got, sha = load_dr(path, dr.shape)
    want = dr.copy()
    want[2:] = 0
    assert np.array_equal(got, want) and sha == dr_sha256_of(want)


# --- writing: atomic ------------------------------------------------------------------------------


def test_an_interrupted_write_leaves_no_dr_zarr(tmp_path, monkeypatch):
    dr = (np.random.default_rng(3).random((6, 5, 5)) < 0.5).astype(np.uint8)
    real = _drstore._write_block
    calls = []

    def interrupted(z, k0, block):
        calls.append(k0)
        if len(calls) == 2:
            raise KeyboardInterrupt
        real(z, k0, block)

    monkeypatch.setattr(_drstore, "_write_block", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_dr(tmp_path, dr, "zarr", layers_per_chunk=1)
    assert calls == [0, 1]
    assert list(tmp_path.iterdir()) == []                 # no dr.zarr, no temporary folder


def test_an_interrupted_rewrite_keeps_the_earlier_store(tmp_path, monkeypatch):
    old = np.zeros((4, 3, 3), np.uint8)
    write_dr(tmp_path, old, "zarr")

    def fail(z, k0, block):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(_drstore, "_write_block", fail)
    with pytest.raises(OSError, match="No space left on device"):
        write_dr(tmp_path, np.ones((4, 3, 3), np.uint8), "zarr")
    assert [p.name for p in tmp_path.iterdir()] == ["dr.zarr"]
    assert np.array_equal(load_dr(tmp_path / "dr.zarr")[0], old)


def test_a_rewrite_replaces_the_store_and_removes_the_other_one(tmp_path):
    a = np.zeros((4, 3, 3), np.uint8)
    b = np.ones((4, 3, 3), np.uint8)
    write_dr(tmp_path, a, "npy")
    write_dr(tmp_path, a, "zarr")
    assert [p.name for p in tmp_path.iterdir()] == ["dr.zarr"]
    write_dr(tmp_path, b, "zarr")
    assert [p.name for p in tmp_path.iterdir()] == ["dr.zarr"]
    assert np.array_equal(load_dr(tmp_path / "dr.zarr")[0], b)
    write_dr(tmp_path, a, "npy")
    assert [p.name for p in tmp_path.iterdir()] == ["dr.npy"]


# --- the default store by the grid's cells --------------------------------------------------------


def test_the_default_store_follows_the_cell_count(small, tmp_path, monkeypatch, capsys):
    d, s, _ = small
    g = make_grid(s)
    cells = (g.N + 1) * g.m * g.n
    monkeypatch.delenv("CFMPA_ZARR_CELLS", raising=False)
    assert zarr_threshold() == 100_000_000
    assert _drstore.default_store(100_000_000) == "npy"
    assert _drstore.default_store(100_000_001) == "zarr"
    for threshold, name in ((cells, "dr.npy"), (cells - 1, "dr.zarr")):
        monkeypatch.setenv("CFMPA_ZARR_CELLS", str(threshold))
        out = tmp_path / f"t{threshold}"
        code, _, _ = _cli(["dr", str(d / "small.toml"), "--out", str(out)], capsys)
        assert code == 0 and [p.name for p in out.iterdir()] == [name]
        code, _, _ = _cli(["plan", str(d / "small.toml"), "--out", str(out / "p"),
                           "--contracts", "off"], capsys)
        assert code == 0 and (out / "p" / name).exists()
        assert _doc(out / "p")["dr_store"] == name.split(".")[1]
    # --store overrides the default
    code, _, _ = _cli(["dr", str(d / "small.toml"), "--out", str(tmp_path / "o"), "--store",
                       "npy"], capsys)
    assert code == 0 and (tmp_path / "o" / "dr.npy").exists()


def test_a_bad_threshold_is_exit_2_before_any_work(small, tmp_path, monkeypatch, capsys):
    d, _, _ = small
    monkeypatch.setenv("CFMPA_ZARR_CELLS", "many")
    for cmd in ("dr", "plan"):
        code, out, err = _cli([cmd, str(d / "small.toml"), "--out", str(tmp_path / cmd)], capsys)
        assert code == 2 and "CFMPA_ZARR_CELLS" in err
        assert not (tmp_path / cmd).exists() or not any((tmp_path / cmd).iterdir())


# --- the searches read a store a chunk at a time ---------------------------------------------------


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("per_chunk", [1, 3])
def test_the_searches_on_a_streamed_store_answer_as_on_the_array(tmp_path, seed, per_chunk):
    rng = np.random.default_rng(seed)
    K, m, n = int(rng.integers(3, 9)), int(rng.integers(3, 9)), int(rng.integers(3, 9))
    dr = (rng.random((K, m, n)) < 0.25).astype(np.uint8)
    start = (int(rng.integers(m)), int(rng.integers(n)))
    goal = (int(rng.integers(m)), int(rng.integers(n)))
    dr[0][start] = 0
    dr[-1][goal] = 0
    path, _ = write_dr(tmp_path, dr, "zarr", layers_per_chunk=per_chunk)
    layers = open_dr_layers(path, dr.shape)
    assert not isinstance(layers, np.ndarray)
    for search in (search_opt_path, search_opt_path_fast):
        kw = {} if search is search_opt_path else {"progress": False}
        want = search(dr, start, goal, with_witness=True, **kw)
        got = search(layers, start, goal, with_witness=True, **kw)
        assert (got.status, got.reason, got.path, got.J1, got.J2) == (
            want.status, want.reason, want.path, want.J1, want.J2)
        for name, a in want.witness.npz_members().items():
            b = got.witness.npz_members()[name]
            assert np.array_equal(np.asarray(a), np.asarray(b)), name


def test_a_streamed_store_holds_one_chunk(tmp_path, monkeypatch):
    """The searches ask for layer after layer; the store decodes each chunk about once."""
    dr = np.zeros((12, 4, 4), np.uint8)
    path, _ = write_dr(tmp_path, dr, "zarr", layers_per_chunk=3)
    st = open_zarr(path, dr.shape)
    read = []
    real = _drstore.ZarrDr.chunk

    def counted(self, c):
        read.append(c)
        return real(self, c)

    monkeypatch.setattr(_drstore.ZarrDr, "chunk", counted)
    layers = st.layers()
    r = search_opt_path_fast(layers, (0, 0), (3, 3), progress=False)
    assert (r.J1, r.J2) == (6, 4)               # three diagonal moves
    # the start's and the goal's layers first (layer 0, the rest layer), then in order
    assert read == [0, 3, 0, 1, 2, 3]


def test_a_store_in_layers_gives_the_cells_the_contracts_ask_for(tmp_path, monkeypatch):
    """``dr[k, i, j]`` for arrays of cells (any order, repeats) is the array's, read a layer at
    a time; the count of blocked cells is the builder's when given, else one pass; a store
    moved away is an error, not an all-free D_R."""
    rng = np.random.default_rng(7)
    dr = (rng.random((9, 5, 6)) < 0.3).astype(np.uint8)
    path, _ = write_dr(tmp_path, dr, "zarr", layers_per_chunk=2)
    layers = open_zarr(path, dr.shape).layers()
    k, i, j = (rng.integers(0, x, size=40) for x in dr.shape)
    assert np.array_equal(layers[k, i, j], dr[k, i, j])
    assert layers[3, 2, 4] == dr[3, 2, 4] and np.array_equal(layers[5], dr[5])
    assert layers.blocked_cells() == int(np.count_nonzero(dr))
    monkeypatch.setattr(_drstore.ZarrDr, "chunk", lambda self, c: pytest.fail("read a chunk"))
    assert open_zarr(path, dr.shape).layers(blocked=17).blocked_cells() == 17
    monkeypatch.undo()
    # Seeded fault: a gather that takes the cells in layer order answers otherwise.
    order = np.argsort(k, kind="stable")
    assert not np.array_equal(layers[k, i, j][order], dr[k, i, j])
    fresh = open_zarr(path, dr.shape).layers()
    shutil.move(path, tmp_path / "moved.zarr")
    with pytest.raises(InputError, match="chunk 0 cannot be read: the store is gone"):
        fresh[0]
    # A chunk missing from a store that is there reads as the fill value, as Zarr says.
    (tmp_path / "moved.zarr" / "c" / "0" / "0" / "0").unlink()
    assert not open_zarr(tmp_path / "moved.zarr", dr.shape).layers()[1].any()
