"""D_R on disk: ``dr.npy`` or the chunked store ``dr.zarr`` (docs/model.md §9).

Both hold the same array, ``uint8`` of shape ``(N + 1, m, n)``, 1 = blocked, the rest layer at
index N (§4.3), and both have the same ``dr_sha256``: the sha256 of the array's ``.npy`` bytes
(numpy's format 1.0 header of a C-order ``|u1`` array of that shape, then the cells in C order).
For dr.npy that is the file itself; for dr.zarr it is computed from the chunks, layer block by
layer block, without the array being written out.

``dr.zarr`` is a Zarr version 3 array (a folder: ``zarr.json`` and one file per chunk under
``c/``), written with the ``zarr`` library: chunks of ``(L, m, n)``, whole layers, ``L`` the
layers in ``CHUNK_BYTES`` (at least one), every chunk written (an all-free block too),
compressed with zstd (with its content checksum). Any Zarr v3 reader opens it
(``zarr.open_array(DIR / "dr.zarr")``).

Writing is atomic: the store is made under a temporary name in the same folder, every file
flushed to disk, then renamed into place; on an error or Ctrl-C the temporary folder is removed
and an earlier ``dr.zarr`` stays as it was. Reading is bounded: ``zarr.json`` is read with a
size limit and checked (format, shape against the grid, ``uint8``, chunks of whole layers of at
most ``MAX_CHUNK_BYTES``, codecs ``bytes`` and optionally ``zstd``) before any chunk is read;
each chunk file is refused when larger than its layers could compress to, and is decoded into a
buffer of exactly its size (a chunk that claims more, or decodes to less, is refused), so a
corrupt or hostile store costs at most one chunk of memory and ends at exit 2 with one line
naming the file. A chunk that is absent reads as the array's fill value, as Zarr specifies.

``default_store``: ``zarr`` for a grid of more than ``ZARR_ABOVE_CELLS`` cells (100 M; the
environment variable ``CFMPA_ZARR_CELLS`` sets another threshold), else ``npy``.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import shutil
import stat
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import MISSING, InputError
from ..files import Limit, cause_text, check_file_size, read_bounded, write_atomic_with

__all__ = ["CHUNK_BYTES", "DR_FILES", "DR_STORES", "MAX_CHUNK_BYTES", "ZARR_ABOVE_CELLS",
           "ZARR_CELLS_ENV", "ZarrDr", "default_store", "dr_file", "dr_sha256_of", "find_dr",
           "load_dr", "npy_header", "open_dr_layers", "store_of", "write_dr", "zarr_threshold"]

#: The stores `cfmpa dr` and `cfmpa plan` write (``--store``), and each one's name in DIR.
DR_STORES = ("npy", "zarr")
DR_FILES = {"npy": "dr.npy", "zarr": "dr.zarr"}
#: A grid of more cells than this is written as dr.zarr unless --store says otherwise.
ZARR_ABOVE_CELLS = 100_000_000
ZARR_CELLS_ENV = "CFMPA_ZARR_CELLS"
#: Raw bytes of one chunk, about: whole layers, at least one.
CHUNK_BYTES = 16 * 1024 * 1024
#: The largest chunk (raw bytes) a reader accepts: what one chunk may cost in memory.
MAX_CHUNK_BYTES = 256 * 1024 * 1024
#: The zstd level: D_R is long runs of 0 and 1, which level 1 already packs tightly.
ZSTD_LEVEL = 1
#: zarr.json is a few hundred bytes; anything past this is not a D_R store's.
_META = Limit("CFMPA_MAX_ZARR_META_BYTES", 1024 * 1024, "a dr.zarr's zarr.json")
_FORMAT = "cfmpa-dr-1"


def zarr_threshold() -> int:
    """The cells above which `cfmpa dr` and `cfmpa plan` write dr.zarr: CFMPA_ZARR_CELLS if set
    (a whole number >= 0), else ZARR_ABOVE_CELLS."""
    raw = os.environ.get(ZARR_CELLS_ENV)
    if raw is None:
        return ZARR_ABOVE_CELLS
    try:
        v = int(raw)
    except ValueError:
        v = -1
    if v < 0:
        raise InputError(ZARR_CELLS_ENV, raw[:80], "must be a whole number of cells >= 0")
    return v


def default_store(cells: int) -> str:
    """``zarr`` for more than ``zarr_threshold()`` cells, else ``npy``."""
    return "zarr" if cells > zarr_threshold() else "npy"


def dr_file(out: str | Path, store: str) -> Path:
    """DIR/dr.npy or DIR/dr.zarr."""
    return Path(out) / DR_FILES[store]


def store_of(path: str | Path) -> str:
    """The store a D_R path is: ``zarr`` for a folder or a name ending in ``.zarr``, else
    ``npy``."""
    p = Path(path)
    return "zarr" if p.is_dir() or p.suffix == ".zarr" else "npy"


def find_dr(folder: str | Path, preferred: str | None = None) -> Path:
    """The D_R of a plan folder: ``preferred`` (plan.json's ``dr_store``) when given, else
    dr.npy if it exists, else dr.zarr (which the reader then finds missing or reads)."""
    if preferred in DR_FILES:
        return dr_file(folder, preferred)
    npy = dr_file(folder, "npy")
    zarr_path = dr_file(folder, "zarr")
    return npy if npy.exists() or not zarr_path.exists() else zarr_path


# --- the hash -------------------------------------------------------------------------------


def npy_header(shape: tuple[int, ...]) -> bytes:
    """The .npy header numpy writes for a C-order uint8 array of ``shape`` (format 1.0)."""
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        buf, {"descr": np.lib.format.dtype_to_descr(np.dtype(np.uint8)), "fortran_order": False,
              "shape": tuple(int(x) for x in shape)})
    return buf.getvalue()


def dr_sha256_of(dr: npt.NDArray[Any]) -> str:
    """dr_sha256 of an in-memory D_R: the sha256 of its .npy bytes in C order (what either
    store's file gives), computed a layer at a time for uint8 of three axes, the whole .npy
    bytes otherwise (a D_R of another type is only ever written as dr.npy)."""
    if dr.dtype != np.uint8 or dr.ndim != 3:
        from ..files import npy_bytes

        return hashlib.sha256(npy_bytes(dr)).hexdigest()
    h = hashlib.sha256(npy_header(dr.shape))
    for layer in dr:
        h.update(np.ascontiguousarray(layer).data)
    return h.hexdigest()


# --- writing --------------------------------------------------------------------------------


def write_dr(out: str | Path, dr: npt.NDArray[np.uint8], store: str | None = None,
             *, layers_per_chunk: int | None = None) -> tuple[Path, str]:
    """Write D_R into the folder ``out`` as ``store`` (default ``default_store(dr.size)``),
    atomically; the path written and dr_sha256. A D_R of the other store left in ``out`` by an
    earlier run is removed after the new one is in place (a folder keeps one D_R)."""
    store = default_store(int(dr.size)) if store is None else store
    if store not in DR_FILES:
        raise ValueError(f"store must be one of {DR_STORES}, got {store!r}")
    target = dr_file(out, store)
    if store == "npy":
        c = dr if dr.flags.c_contiguous else np.ascontiguousarray(dr)
        path, sha = write_atomic_with(target, lambda fh: np.save(fh, c, allow_pickle=False),
                                      digest=True)
        assert sha is not None
    else:
        path, sha = write_zarr_atomic(target, dr, layers_per_chunk=layers_per_chunk)
    _remove_other(out, store)
    return path, sha


def _remove_other(out: str | Path, store: str) -> None:
    for other, name in DR_FILES.items():
        if other == store:
            continue
        p = Path(out) / name
        if other == "npy" and p.is_file() and not p.is_symlink():
            p.unlink()
        elif other == "zarr" and p.is_dir() and not p.is_symlink() and (
                (p / "zarr.json").is_file() or not any(p.iterdir())):
            shutil.rmtree(p)


def chunk_layers(m: int, n: int, layers: int) -> int:
    """Layers a chunk holds: those in CHUNK_BYTES, at least one, at most ``layers``."""
    return max(1, min(layers, CHUNK_BYTES // max(1, m * n)))


def write_zarr_atomic(target: str | Path, dr: npt.NDArray[np.uint8], *,
                      layers_per_chunk: int | None = None) -> tuple[Path, str]:
    """``dr`` as a Zarr v3 store at ``target`` (see the module's docstring), built under a
    temporary name beside it, flushed and renamed into place; the path and dr_sha256."""
    target = Path(target)
    if dr.ndim != 3 or dr.dtype != np.uint8:
        raise ValueError(f"D_R must be uint8 of shape (N + 1, m, n), got {dr.dtype} {dr.shape}")
    K, m, n = (int(x) for x in dr.shape)
    L = layers_per_chunk or chunk_layers(m, n, K)
    tmp = temporary_store(target)
    try:
        h = hashlib.sha256(npy_header(dr.shape))
        z = create_store(tmp, (K, m, n), L)
        for k0 in range(0, K, L):
            block = np.ascontiguousarray(dr[k0:k0 + L])
            h.update(block.data)
            _write_block(z, k0, block)
        _sync_tree(tmp)
        publish_store(tmp, target)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return target, h.hexdigest()


def temporary_store(target: str | Path) -> Path:
    """A new empty folder beside ``target`` (``.dr.zarr.XXXX.tmp``), where a store is made
    before ``publish_store`` renames it into place (the caller removes it on failure)."""
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent))
    os.chmod(tmp, 0o755)
    return tmp


def create_store(root: Path, shape: tuple[int, int, int], layers_per_chunk: int) -> Any:
    """The Zarr v3 array of D_R at ``root`` (zarr.json only; the module docstring's layout),
    opened for writing with every chunk written, an all-free one too."""
    import zarr
    from zarr.codecs import ZstdCodec

    K, m, n = shape
    return zarr.create_array(store=str(root), shape=(K, m, n), chunks=(layers_per_chunk, m, n),
                             dtype="uint8", fill_value=0, zarr_format=3,
                             compressors=ZstdCodec(level=ZSTD_LEVEL, checksum=True),
                             config={"write_empty_chunks": True},
                             attributes={"cfmpa": {
                                 "format": _FORMAT,
                                 "layout": "D_R, uint8 (N + 1, m, n), 1 = blocked, the rest "
                                           "layer at index N (docs/model.md §4.3, §9)",
                                 "dr_sha256": "sha256 of the array's .npy bytes (format 1.0 "
                                              "header, C order)"}})


def encode_chunk(layers: npt.NDArray[np.uint8], layers_per_chunk: int) -> bytes:
    """One chunk's file as ``create_store``'s array writes it: the layers padded with the fill
    value (0) to ``layers_per_chunk`` (the last chunk of the array), C-order bytes, zstd at
    ZSTD_LEVEL with its content checksum (zarr's ``bytes`` and ``zstd`` codecs)."""
    raw = np.zeros((layers_per_chunk, *layers.shape[1:]), dtype=np.uint8)
    raw[:layers.shape[0]] = layers
    return bytes(_zstd(level=ZSTD_LEVEL, checksum=True).encode(raw.tobytes()))


def _zstd(**config: Any) -> Any:
    """numcodecs' Zstd codec (zarr's zstd) with ``config``, imported when first needed."""
    from numcodecs.zstd import Zstd  # type: ignore[import-untyped]  # no py.typed

    return Zstd(**config)


def chunk_file(root: Path, c: int) -> Path:
    """Chunk c's file in a store ``create_store`` made (the default key encoding, "/")."""
    return Path(root) / "c" / str(c) / "0" / "0"


def publish_store(tmp: Path, target: Path) -> None:
    """Rename the finished, flushed store ``tmp`` to ``target``: an earlier store there is
    moved aside first and removed after, or put back if the rename fails."""
    old: Path | None = None
    try:
        if target.exists() or target.is_symlink():
            old = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".old",
                                        dir=target.parent))
            os.rename(target, old / "store")
        os.rename(tmp, target)
        _sync_dir(target.parent)
    except BaseException:
        if old is not None and (old / "store").exists() and not target.exists():
            os.rename(old / "store", target)      # put the earlier store back
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
        raise
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def _write_block(z: Any, k0: int, block: npt.NDArray[np.uint8]) -> None:
    """Layers k0 .. k0 + len(block) - 1 into the open array (one chunk; a seam for tests)."""
    z[k0:k0 + block.shape[0]] = block


def _sync_tree(root: Path) -> None:
    """Every file and folder under ``root`` flushed to disk (then a rename publishes whole)."""
    for here, _dirs, files in os.walk(root):
        for f in files:
            fd = os.open(os.path.join(here, f), os.O_RDONLY)
            try:
                os.fsync(fd)
            finally:
                os.close(fd)
        _sync_dir(Path(here))


def _sync_dir(path: Path) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:          # pragma: no cover - a platform without directory descriptors
        return
    try:
        os.fsync(fd)
    except OSError:          # pragma: no cover
        pass
    finally:
        os.close(fd)


# --- reading --------------------------------------------------------------------------------


@dataclass(frozen=True)
class ZarrDr:
    """An opened, checked dr.zarr: nothing but zarr.json has been read. ``chunk(c)`` reads
    chunk c (layers c L .. c L + L - 1, the last one cut to the array), bounded."""

    root: Path
    shape: tuple[int, int, int]
    layers_per_chunk: int
    compressed: bool
    fill: int
    separator: str

    @property
    def chunks(self) -> int:
        return -(-self.shape[0] // self.layers_per_chunk)

    def _bad(self, what: str, path: Path | None = None) -> InputError:
        return InputError("dr", MISSING, what, source=str(path or self.root))

    def chunk_path(self, c: int) -> Path:
        if self.separator == "/":
            return self.root / "c" / str(c) / "0" / "0"
        return self.root / f"c.{c}.0.0"

    def chunk(self, c: int) -> npt.NDArray[np.uint8]:
        """Chunk c's layers, exactly as stored (refused when corrupt)."""
        K, m, n = self.shape
        L = self.layers_per_chunk
        raw = L * m * n
        valid = min(L, K - c * L)
        path = self.chunk_path(c)
        try:
            st = os.stat(path)
        except FileNotFoundError:
            if not self.root.is_dir():      # the store moved or removed: not an all-free chunk
                raise self._bad(f"chunk {c} cannot be read: the store is gone") from None
            return np.full((valid, m, n), self.fill, dtype=np.uint8)
        except OSError as exc:
            raise self._bad(f"chunk {c} cannot be read ({exc.strerror or exc})", path) from None
        if not stat.S_ISREG(st.st_mode):
            raise self._bad(f"chunk {c} is not a regular file", path)
        # zstd never grows data by more than a little (ZSTD_compressBound); raw bytes are exact.
        cap = raw + raw // 128 + 4096 if self.compressed else raw
        if st.st_size > cap or (not self.compressed and st.st_size != raw):
            raise self._bad(f"chunk {c} has {st.st_size:,} bytes, not what {valid} layers of "
                            f"{m} x {n} cells can be ({'at most ' if self.compressed else ''}"
                            f"{cap:,}): the store is corrupt", path)
        try:
            with open(path, "rb") as fh:
                data = fh.read(cap + 1)
        except OSError as exc:
            raise self._bad(f"chunk {c} cannot be read ({exc.strerror or exc})", path) from None
        if self.compressed:
            out = np.empty(raw, dtype=np.uint8)
            try:
                # Into a buffer of exactly the chunk's size: a frame that claims or holds more
                # is an error, so a corrupt chunk cannot cost more than its size; one that
                # claims less is refused here (numcodecs checks only a frame without a size).
                claimed = _zstd_content_size(data)
                if claimed is not None and claimed != raw:
                    raise ValueError(f"the frame holds {claimed:,} bytes")
                _zstd().decode(data, out=out)
            except Exception as exc:   # numcodecs raises RuntimeError / ValueError
                raise self._bad(f"chunk {c} does not decode to {raw:,} bytes "
                                f"({cause_text(exc)}): the store is corrupt", path) from None
        else:
            out = np.frombuffer(data, dtype=np.uint8)
        return out.reshape(L, m, n)[:valid]

    def blocks(self) -> Iterator[tuple[int, npt.NDArray[np.uint8]]]:
        """(first layer, layers) of every chunk in order."""
        for c in range(self.chunks):
            yield c * self.layers_per_chunk, self.chunk(c)

    def read(self) -> tuple[npt.NDArray[np.uint8], str]:
        """The whole array and dr_sha256, from one pass over the chunks."""
        out = np.empty(self.shape, dtype=np.uint8)
        h = hashlib.sha256(npy_header(self.shape))
        for k0, block in self.blocks():
            out[k0:k0 + block.shape[0]] = block
            h.update(np.ascontiguousarray(block).data)
        return out, h.hexdigest()

    def sha256(self) -> str:
        """dr_sha256, a chunk at a time."""
        h = hashlib.sha256(npy_header(self.shape))
        for _, block in self.blocks():
            h.update(np.ascontiguousarray(block).data)
        return h.hexdigest()

    def layers(self, blocked: int | None = None) -> Any:
        """The array as ``StoreLayers`` (a ``spec.Layers``): layer s read when asked for, one
        chunk held. ``blocked``: the store's count of blocked cells when known (its builder
        counted them), so that the free fraction needs no pass over the store."""
        held: list[tuple[int, npt.NDArray[np.uint8]]] = []

        def read(s: int) -> npt.NDArray[np.uint8]:
            c = s // self.layers_per_chunk
            if not held or held[0][0] != c:
                held[:] = [(c, self.chunk(c))]
            return held[0][1][s - c * self.layers_per_chunk]

        return _store_layers(self.shape, read, blocked)


def _store_layers(shape: tuple[int, int, int], read: Callable[[int], npt.NDArray[np.uint8]],
                  blocked: int | None) -> Any:
    """A ``StoreLayers`` (the class is made on first use: ``spec`` is imported lazily here)."""
    from ..spec import Layers

    global StoreLayers
    if StoreLayers is None:

        class _StoreLayers(Layers):
            """D_R read from its store a layer at a time (``spec.Layers``), which also answers
            what the contracts ask of D_R without holding it: ``dr[k, i, j]`` for arrays of
            cells (gathered a layer at a time, in the order given) and ``blocked_cells()``."""

            blocked: int | None = None

            def __getitem__(self, key: Any) -> Any:
                if (isinstance(key, tuple) and len(key) == 3
                        and isinstance(key[0], np.ndarray) and key[0].ndim >= 1):
                    return self._gather(*(np.asarray(x, dtype=np.int64) for x in key))
                return super().__getitem__(key)

            def _gather(self, k: Any, i: Any, j: Any) -> npt.NDArray[np.uint8]:
                k, i, j = np.broadcast_arrays(k, i, j)
                out = np.empty(k.shape, dtype=np.uint8)
                for layer in np.unique(k):
                    at = k == layer
                    out[at] = self.layer(int(layer))[i[at], j[at]]
                return out

            def blocked_cells(self) -> int:
                """Blocked cells (ones) of D_R: the count its builder gave, else one pass."""
                if self.blocked is None:
                    self.blocked = sum(int(np.count_nonzero(a)) for a in self)
                return self.blocked

        StoreLayers = _StoreLayers
    out = StoreLayers(shape, np.uint8, read)
    out.blocked = blocked
    return out


#: The class ``ZarrDr.layers`` returns (made on first use; see ``_store_layers``).
StoreLayers: Any = None


def open_zarr(path: str | Path, expect: tuple[int, int, int] | None = None,
              max_cells: int | None = None) -> ZarrDr:
    """Open dr.zarr and check its zarr.json (module docstring) against the grid's shape
    ``expect`` (or, without it, against ``max_cells``); InputError naming the file otherwise."""
    root = Path(path)
    meta_path = root / "zarr.json"
    src = str(meta_path)

    def bad(field: str, value: Any, what: str) -> InputError:
        return InputError(field, value, what, source=src)

    if not root.is_dir():
        raise InputError("dr", MISSING, "is not a folder (a dr.zarr store is one)" if
                         root.exists() else "cannot be read (No such file or directory)",
                         source=str(root))
    check_file_size(meta_path, _META, src, field="zarr.json")
    text = read_bounded(meta_path, _META, src, lines=False, field="zarr.json")
    try:
        meta = json.loads(text.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise bad("zarr.json", MISSING, f"is not JSON ({cause_text(exc)}): the store is "
                                        f"corrupt") from None
    if not isinstance(meta, dict):
        raise bad("zarr.json", type(meta).__name__, "must be a JSON object")
    if meta.get("zarr_format") != 3 or meta.get("node_type") != "array":
        raise bad("zarr_format", meta.get("zarr_format"), "must be 3 with node_type \"array\" "
                  "(a Zarr version 3 array)")
    known = {"zarr_format", "node_type", "shape", "data_type", "chunk_grid",
             "chunk_key_encoding", "fill_value", "codecs", "attributes", "dimension_names",
             "storage_transformers"}
    for key, value in meta.items():
        if key not in known and not (isinstance(value, dict)
                                     and value.get("must_understand") is False):
            raise bad(key, MISSING, "is an extension cfmpa does not read")
    shape = meta.get("shape")
    if not (isinstance(shape, list) and len(shape) == 3
            and all(isinstance(x, int) and not isinstance(x, bool) and x >= 1 for x in shape)):
        raise bad("shape", _cut(shape), "must be three whole numbers >= 1, (N + 1, m, n)")
    K, m, n = shape
    if expect is not None and tuple(shape) != tuple(expect):
        raise bad("shape", shape, f"is not the scenario's grid (N + 1, m, n) = {list(expect)} "
                                  f"(nothing read)")
    cap = max_cells
    if expect is None and cap is not None and K * m * n > cap:
        raise bad("shape", shape, f"has {K * m * n:,} cells, over the budget of {cap:,} "
                                  f"(CFMPA_MAX_CELLS)")
    if meta.get("data_type") != "uint8":
        raise bad("data_type", _cut(meta.get("data_type")), "must be \"uint8\" (D_R: 1 = "
                                                            "blocked, 0 = free)")
    grid = meta.get("chunk_grid")
    chunk = (grid.get("configuration", {}).get("chunk_shape")
             if isinstance(grid, dict) and grid.get("name") == "regular"
             and isinstance(grid.get("configuration"), dict) else None)
    if not (isinstance(chunk, list) and len(chunk) == 3 and chunk[1:] == [m, n]
            and isinstance(chunk[0], int) and not isinstance(chunk[0], bool)
            and 1 <= chunk[0] <= K):
        raise bad("chunk_grid", _cut(grid), f"must be regular with chunk_shape [L, {m}, {n}] "
                                            f"(whole layers), 1 <= L <= {K}")
    L = chunk[0]
    if L * m * n > MAX_CHUNK_BYTES:
        raise bad("chunk_grid", chunk, f"has chunks of {L * m * n:,} cells, over "
                                       f"{MAX_CHUNK_BYTES:,} (one chunk is what a reader holds)")
    enc = meta.get("chunk_key_encoding", {"name": "default"})
    sep = (enc.get("configuration") or {}).get("separator", "/") if isinstance(enc, dict) else None
    if not (isinstance(enc, dict) and enc.get("name") == "default" and sep in ("/", ".")):
        raise bad("chunk_key_encoding", _cut(enc), "must be \"default\" with separator / or .")
    fill = meta.get("fill_value", 0)
    if not (isinstance(fill, int) and not isinstance(fill, bool) and 0 <= fill <= 255):
        raise bad("fill_value", _cut(fill), "must be a uint8")
    if meta.get("storage_transformers") not in (None, []):
        raise bad("storage_transformers", _cut(meta["storage_transformers"]), "must be empty")
    codecs = meta.get("codecs")
    names = ([c.get("name") if isinstance(c, dict) else None for c in codecs]
             if isinstance(codecs, list) else None)
    if names not in (["bytes"], ["bytes", "zstd"]):
        raise bad("codecs", _cut(names if names is not None else codecs),
                  "must be [\"bytes\"] or [\"bytes\", \"zstd\"] (what cfmpa reads)")
    return ZarrDr(root, (K, m, n), L, names == ["bytes", "zstd"], fill, sep)


def _zstd_content_size(data: bytes) -> int | None:
    """The content size a zstd frame's header states (None when it states none); ValueError
    for what is not a zstd frame (RFC 8878 §3.1.1)."""
    if len(data) < 6 or int.from_bytes(data[:4], "little") != 0xFD2FB528:
        raise ValueError("not a zstd frame")
    fhd = data[4]
    fcs_flag, single = fhd >> 6, (fhd >> 5) & 1
    at = 5 + (0 if single else 1) + (0, 1, 2, 4)[fhd & 3]
    size = (1 if single else 0) if fcs_flag == 0 else (0, 2, 4, 8)[fcs_flag]
    if size == 0:
        return None
    if len(data) < at + size:
        raise ValueError("a zstd frame header cut short")
    value = int.from_bytes(data[at:at + size], "little")
    return value + 256 if size == 2 else value


def _cut(x: Any) -> Any:
    text = repr(x)
    return x if len(text) <= 80 else text[:77] + "..."


def _npy_sha256(path: Path) -> str:
    h = hashlib.sha256()
    try:
        with open(path, "rb") as fh:
            for chunk in iter(lambda: fh.read(1 << 20), b""):
                h.update(chunk)
    except OSError as exc:
        raise InputError("dr", MISSING, f"cannot be read ({exc.strerror or exc})",
                         source=str(path)) from None
    return h.hexdigest()


def _npy_shape(path: Path) -> tuple[tuple[int, ...], np.dtype[Any]] | None:
    """The shape and dtype in a .npy file's header (nothing else read); None when the file has
    no readable header (np.load then says what is wrong)."""
    try:
        with open(path, "rb") as fh:
            version = np.lib.format.read_magic(fh)
            reader: Callable[..., Any] = (np.lib.format.read_array_header_1_0 if version == (1, 0)
                                          else np.lib.format.read_array_header_2_0)
            shape, _fortran, dtype = reader(fh)
    except (OSError, ValueError):
        return None
    return tuple(int(x) for x in shape), np.dtype(dtype)


def load_dr(path: str | Path, expect: tuple[int, int, int] | None = None
            ) -> tuple[npt.NDArray[Any], str]:
    """A dr.npy or dr.zarr as an array and its dr_sha256; InputError (exit 2, one line naming
    the file) when it cannot be read, is corrupt or is larger than the cell budget allows.

    A dr.npy is returned with whatever dtype and shape it has (``cfmpa check`` judges them) as
    long as it holds at most max(the cell budget, the grid's cells) bytes; a dr.zarr must match
    the grid ``expect`` before a chunk is read (``open_zarr``)."""
    from ..spec import max_cells

    p = Path(path)
    budget = max(max_cells(), 0 if expect is None else int(np.prod(expect)))
    if store_of(p) == "zarr":
        return open_zarr(p, expect, budget).read()
    source = str(p)
    head = _npy_shape(p) if p.is_file() else None
    if head is not None:
        shape, dtype = head
        nbytes = int(np.prod(shape, dtype=object)) * dtype.itemsize
        if nbytes > budget:
            raise InputError("dr", MISSING, f"holds {nbytes:,} bytes ({dtype} {list(shape)}), "
                                            f"over the {budget:,} bytes of the cell budget (one "
                                            f"byte a cell; CFMPA_MAX_CELLS)", source=source)
    try:
        arr = np.load(p, allow_pickle=False)
    except OSError as exc:
        raise InputError("dr", MISSING, f"cannot be read ({exc.strerror or exc})",
                         source=source) from None
    except ValueError as exc:
        raise InputError("dr", MISSING, f"is not a .npy array file ({cause_text(exc)})",
                         source=source) from None
    if not isinstance(arr, np.ndarray):
        raise InputError("dr", MISSING, "is not a single .npy array", source=source)
    return arr, _npy_sha256(p)


def open_dr_layers(path: str | Path, expect: tuple[int, int, int] | None = None) -> Any:
    """A dr.zarr as ``spec.Layers`` read a chunk at a time (one chunk held): what the searches
    take in place of the array, so D_R need not be held whole. A dr.npy is read whole
    (``load_dr``) and served the same way."""
    from ..spec import Layers, max_cells

    p = Path(path)
    if store_of(p) == "zarr":
        return open_zarr(p, expect, max_cells()).layers()
    arr, _ = load_dr(p, expect)
    return Layers(arr.shape, arr.dtype, lambda s: arr[s])
