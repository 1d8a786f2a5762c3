"""Arrays read one layer at a time: the witness's labels on grids too large to hold
(docs/model.md §11).

A witness has ``N + 1`` layers of ``9 m n`` labels; held whole it is 36 bytes a D_R cell (two
uint16 arrays), 1.7 GB on the default workcell at dt = 0.01. The search makes it one layer at a
time and the checker reads it one layer at a time (``spec.check_witness`` goes through the steps
in order and looks at steps s and min(s + 1, N) together), so neither needs it whole:

- ``Layers``: a read-only array of shape ``(L, *layer)`` that gives ``a[s]`` (and ``a[s, ...]``,
  the first index an integer) by reading layer ``s``; it keeps the last two layers read. What a
  checker reads of it is exactly what an ndarray of the same values gives (``np.asarray`` makes
  that ndarray, for small grids and tests).
- ``LayerSpill``: layers appended in order to an unnamed temporary file (``tempfile``, in
  ``TMPDIR``; removed when the last reference goes), then read back as ``Layers``. The file is
  in the page cache or on disk, not in the process's memory (on a tmpfs ``TMPDIR`` it is memory
  again, outside the process: point TMPDIR at a disk there).
- ``npz_layers``: a member of an uncompressed ``.npz`` file as ``Layers``, read in place.
- ``save_npz``: an uncompressed ``.npz`` written member by member and layer by layer; ``np.load``
  reads it as it reads ``np.savez``'s.

Arrays at most ``SPILL_BYTES`` large are kept whole as before (``spill_wanted``).
"""

from __future__ import annotations

import operator
import os
import struct
import tempfile
import zipfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, Any

import numpy as np
import numpy.typing as npt

__all__ = ["SPILL_BYTES", "LayerSpill", "Layers", "layered", "npz_layers", "npz_member",
           "save_npz", "spill_wanted", "take_cells"]

#: Label arrays larger than this (bytes, both together) go to a LayerSpill, and witness members
#: larger than this are read in place (npz_layers); smaller ones are held whole.
SPILL_BYTES = 1 << 26

Array = npt.NDArray[Any]


def spill_wanted(nbytes: int) -> bool:
    """Whether arrays of ``nbytes`` in all are kept in layers rather than whole."""
    return nbytes > SPILL_BYTES


class Layers:
    """A read-only array of shape ``(L, *layer)`` read one layer at a time by ``read(s)``."""

    def __init__(self, shape: tuple[int, ...], dtype: npt.DTypeLike,
                 read: Callable[[int], Array],
                 close: Callable[[], None] | None = None) -> None:
        self.shape = tuple(int(x) for x in shape)
        self.dtype = np.dtype(dtype)
        self._read = read
        self._close = close
        self._cache: list[tuple[int, Array]] = []     # the last two layers read, newest last

    def close(self) -> None:
        """Release what the layers are read from (a LayerSpill's temporary file); reading them
        after that fails. Idempotent; nothing to do for most sources."""
        self._cache = []
        if self._close is not None:
            self._close()

    def __enter__(self) -> Layers:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def ndim(self) -> int:
        return len(self.shape)

    @property
    def nbytes(self) -> int:
        return int(np.prod(self.shape, dtype=np.int64)) * self.dtype.itemsize

    def __len__(self) -> int:
        return self.shape[0]

    def layer(self, s: int) -> Array:
        """Layer s (negative counts from the end) as a read-only ndarray."""
        s = operator.index(s)
        if s < 0:
            s += self.shape[0]
        if not 0 <= s < self.shape[0]:
            raise IndexError(f"layer {s} of {self.shape[0]}")
        for k, a in self._cache:
            if k == s:
                return a
        a = np.asarray(self._read(s), dtype=self.dtype).reshape(self.shape[1:])
        a.flags.writeable = False
        self._cache = self._cache[-1:] + [(s, a)]
        return a

    def __getitem__(self, key: Any) -> Any:
        if isinstance(key, tuple):
            if not key:
                return np.asarray(self)
            return self.layer(key[0])[key[1:]]
        return self.layer(key)

    def __iter__(self) -> Iterator[Array]:
        for s in range(self.shape[0]):
            yield self.layer(s)

    def __array__(self, dtype: npt.DTypeLike | None = None, copy: bool | None = None) -> Array:
        out = np.empty(self.shape, dtype=self.dtype)
        for s in range(self.shape[0]):
            out[s] = np.asarray(self._read(s), dtype=self.dtype).reshape(self.shape[1:])
        return out if dtype is None else out.astype(dtype)

    def map(self, fn: Callable[[Array], Array], dtype: npt.DTypeLike) -> Layers:
        """The layers ``fn(a[s])`` (each of this layer shape), read when asked for."""
        return Layers(self.shape, dtype, lambda s: fn(self.layer(s)), close=self.close)


def layered(a: Any) -> Array | Layers:
    """``a`` as a checker reads D_R: a ``Layers`` (D_R in its store, docs/model.md §9) as it is,
    read a layer at a time; anything else as an ndarray (``np.asarray``)."""
    return a if isinstance(a, Layers) else np.asarray(a)


def take_cells(a: Any, k: Any, i: Any, j: Any) -> Array:
    """``a[k, i, j]`` for arrays of cells (k, i, j broadcast together): of an ndarray by
    numpy's indexing; of a ``Layers`` a layer at a time (each layer the cells name read once),
    so that D_R in its store is never read whole."""
    if not isinstance(a, Layers):
        return np.asarray(a)[k, i, j]
    k, i, j = np.broadcast_arrays(*(np.asarray(x, dtype=np.int64) for x in (k, i, j)))
    shape = k.shape
    k, i, j = k.ravel(), i.ravel(), j.ravel()
    out = np.empty(k.size, dtype=a.dtype)
    if not k.size:
        return out.reshape(shape)
    order = np.argsort(k, kind="stable")       # the cells grouped by layer, each read once
    ks = k[order]
    cuts = np.flatnonzero(np.diff(ks)) + 1
    for lo, hi in zip(np.r_[0, cuts], np.r_[cuts, ks.size]):
        at = order[lo:hi]
        out[at] = a.layer(int(ks[lo]))[i[at], j[at]]
    return out.reshape(shape)


def _pread(fd: int, nbytes: int, offset: int) -> bytes:
    parts, got = [], 0
    while got < nbytes:
        chunk = os.pread(fd, nbytes - got, offset + got)
        if not chunk:
            raise OSError(f"unexpected end of file at byte {offset + got}")
        parts.append(chunk)
        got += len(chunk)
    return b"".join(parts)


class LayerSpill:
    """Layers of one shape and type appended in order to an unnamed temporary file.

    A layer is stored as the part inside the bounding box, over its last two axes, of the
    entries that differ from ``fill`` (by default the type's largest value, "no label"); the
    rest reads back as ``fill``. The labels of the search's step s lie within s moves of the
    start, so its early steps take little room."""

    def __init__(self, shape: tuple[int, ...], dtype: npt.DTypeLike,
                 fill: Any = None) -> None:
        self.shape = tuple(int(x) for x in shape)
        self.dtype = np.dtype(dtype)
        self.fill = (np.iinfo(self.dtype).max if fill is None and self.dtype.kind in "ui"
                     else (fill or 0))
        self._file: IO[bytes] = tempfile.TemporaryFile(prefix="cfmpa-layers-")
        self._parts: list[tuple[int, tuple[int, int, int, int]]] = []   # (offset, box)
        self._end = 0

    @property
    def written(self) -> int:
        return len(self._parts)

    def close(self) -> None:
        """Close (and so remove) the temporary file; the layers read from it fail after that.
        Idempotent. The search closes its spills where they end, not the garbage collector."""
        self._file.close()

    def __enter__(self) -> LayerSpill:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def append(self, layer: Array, box: tuple[int, int, int, int] | None = None) -> None:
        """Write the next layer (converted to this type): the whole layer, or with ``box`` =
        (r0, r1, c0, c1) its part at rows r0:r1, columns c0:c1 of the last two axes (``fill``
        elsewhere)."""
        a = np.asarray(layer)
        R, C = self.shape[-2:]
        r0, r1, c0, c1 = box or (0, R, 0, C)
        want = (*self.shape[1:-2], r1 - r0, c1 - c0)
        if (self.written >= self.shape[0] or a.shape != want
                or not (0 <= r0 <= r1 <= R and 0 <= c0 <= c1 <= C)):
            raise ValueError(f"LayerSpill.append: layer {self.written} of shape {a.shape} at "
                             f"{(r0, r1, c0, c1)}, expected {want} inside {(R, C)} and at "
                             f"most {self.shape[0]} layers")
        a = a.astype(self.dtype, copy=False)
        lead = int(np.prod(a.shape[:-2], dtype=np.int64))
        used = (a != self.fill).reshape(lead, *a.shape[-2:]).any(axis=0)
        rows, cols = np.flatnonzero(used.any(axis=1)), np.flatnonzero(used.any(axis=0))
        if rows.size == 0:
            self._parts.append((self._end, (0, 0, 0, 0)))
            return
        a = np.ascontiguousarray(a[..., rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1])
        self._parts.append((self._end, (r0 + int(rows[0]), r0 + int(rows[-1]) + 1,
                                        c0 + int(cols[0]), c0 + int(cols[-1]) + 1)))
        self._file.write(a.data)
        self._end += a.nbytes

    def _part(self, s: int) -> tuple[Array, tuple[int, int, int, int]]:
        offset, (r0, r1, c0, c1) = self._parts[s]
        shape = (*self.shape[1:-2], r1 - r0, c1 - c0)
        size = int(np.prod(shape, dtype=np.int64)) * self.dtype.itemsize
        data = _pread(self._file.fileno(), size, offset) if size else b""
        return np.frombuffer(data, self.dtype).reshape(shape), (r0, r1, c0, c1)

    def _layer(self, s: int) -> Array:
        out = np.full(self.shape[1:], self.fill, dtype=self.dtype)
        part, (r0, r1, c0, c1) = self._part(s)
        out[..., r0:r1, c0:c1] = part
        return out

    def widened(self, dtype: npt.DTypeLike) -> LayerSpill:
        """A new spill holding the layers written so far converted to ``dtype`` (values kept,
        ``fill`` becoming the new type's largest value)."""
        out = LayerSpill(self.shape, dtype)
        self._file.flush()
        for s in range(self.written):
            part, box = self._part(s)
            wide = part.astype(out.dtype)
            wide[part == self.fill] = out.fill
            out.append(wide, box)
        return out

    def layers(self) -> Layers:
        """Every layer, written in full, as Layers reading this file."""
        if self.written != self.shape[0]:
            raise ValueError(f"LayerSpill.layers: {self.written} of {self.shape[0]} written")
        self._file.flush()
        return Layers(self.shape, self.dtype, self._layer, close=self.close)


def npz_layers(path: str | Path, name: str) -> Layers | None:
    """Member ``name`` of the ``.npz`` file at ``path`` as Layers read in place, or None when it
    cannot be read so (compressed, Fortran order, fewer than one axis, object type, or the file
    shorter than the member): the caller then reads it whole, with numpy's own checks."""
    try:
        with zipfile.ZipFile(path) as z:
            info = z.getinfo(name + ".npy")
        if info.compress_type != zipfile.ZIP_STORED:
            return None
        with open(path, "rb") as f:
            f.seek(info.header_offset)
            local = f.read(30)
            if len(local) != 30 or local[:4] != b"PK\x03\x04":
                return None
            name_len, extra_len = struct.unpack("<HH", local[26:30])
            member_start = info.header_offset + 30 + name_len + extra_len
            f.seek(member_start)
            version = np.lib.format.read_magic(f)
            if version == (1, 0):
                shape, fortran, dtype = np.lib.format.read_array_header_1_0(f)
            elif version == (2, 0):
                shape, fortran, dtype = np.lib.format.read_array_header_2_0(f)
            else:
                return None
            start = f.tell()
            f.seek(0, os.SEEK_END)
            end = f.tell()
    except (OSError, KeyError, ValueError, zipfile.BadZipFile, struct.error):
        return None
    if fortran or len(shape) < 1 or dtype.hasobject:
        return None
    size = int(np.prod(shape[1:], dtype=np.int64)) * dtype.itemsize
    if start + size * shape[0] > min(end, member_start + info.compress_size):
        return None
    source = str(path)

    def read(s: int) -> Array:
        with open(source, "rb") as f:
            return np.frombuffer(_pread(f.fileno(), size, start + s * size), dtype)

    return Layers(shape, dtype, read)


def npz_member(path: str | Path, z: Any, name: str) -> Array | Layers:
    """Member ``name`` of the open ``np.load`` result ``z`` of ``path``: read in place
    (``npz_layers``) when larger than SPILL_BYTES and readable so, else whole (``z[name]``, with
    numpy's own checks and errors)."""
    try:
        size = z.zip.getinfo(f"{name}.npy").file_size
    except (AttributeError, KeyError):
        size = 0
    view = npz_layers(path, name) if spill_wanted(size) else None
    return z[name] if view is None else view


def save_npz(fh: IO[bytes], members: dict[str, Array | Layers]) -> None:
    """An uncompressed ``.npz`` of ``members`` (name: array or Layers) written to ``fh``, each
    array member by member and a Layers layer by layer, so no member is held whole."""
    with zipfile.ZipFile(fh, "w", zipfile.ZIP_STORED, allowZip64=True) as z:
        for name, value in members.items():
            with z.open(name + ".npy", "w", force_zip64=True) as out:
                if isinstance(value, Layers):
                    header = {"descr": np.lib.format.dtype_to_descr(value.dtype),
                              "fortran_order": False, "shape": value.shape}
                    np.lib.format.write_array_header_2_0(out, header)
                    for layer in value:
                        out.write(np.ascontiguousarray(layer).data)
                else:
                    np.lib.format.write_array(out, np.asanyarray(value), allow_pickle=False)
