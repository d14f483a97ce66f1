"""HDF5 files written and read safely: the demonstration files and run logs go through here.

Writing: a file is built in memory (h5py on a :class:`io.BytesIO`) and its bytes are written
with :func:`teachfit.core.atomic.atomic_write_bytes`. HDF5 never writes to the disk itself, so
a full disk or a file-size limit (``ulimit -f``) is one :class:`OutputError` from a plain write
instead of HDF5 failing in its cache (tracebacks from object destructors, a crash at exit and a
temporary file left behind).

Reading: :func:`open_hdf5` refuses, before anything is read through them, links to other files
(external links) and datasets whose data lie in other files (external storage, virtual
datasets): a user's file cannot make teachfit read a system file. :class:`H5Reader` checks what
a dataset declares (group or dataset, value type, shape times value size) before reading it, so
a small file declaring billions of compressed values is refused instead of filling the memory;
it reads at most :data:`MAX_READ_BYTES` from one file. Attributes are read with their type
checked (a string attribute that holds a number is refused, not converted).
"""

from __future__ import annotations

import io
import math
import reprlib
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Literal, overload

import h5py
import numpy as np

from teachfit.core.atomic import atomic_write_bytes, write_error
from teachfit.core.errors import DatasetError, OutputError

#: the most bytes of data read from one HDF5 file (declared shape times value size, summed over
#: what is read): about 1 GiB, 4.6 million run-log samples or 9.5 million demonstration samples
MAX_READ_BYTES = 1 << 30
#: h5py's errors on a damaged file
H5_ERRORS = (OSError, RuntimeError, KeyError)


def one_line(exc: BaseException) -> str:
    """An exception's text on one line (HDF5's messages span several)."""
    return " ".join(str(exc).split())


def shown(value: object) -> str:
    """A short repr of an attribute's value (numpy values as Python ones)."""
    plain = value.tolist() if isinstance(value, np.ndarray | np.generic) else value
    return reprlib.repr(plain)


def _size(n: float) -> str:
    """A size in bytes, in words (binary units)."""
    for unit in ("bytes", "KiB", "MiB", "GiB"):
        if n < 1024 or unit == "GiB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n:.1f} GiB"


def write_hdf5(
    dest: str | Path, fill: Callable[[h5py.File], None], what: str, base: Path | None = None
) -> Path:
    """Write the HDF5 file that ``fill`` builds to ``dest`` atomically; ``base`` (an existing
    HDF5 file, at most :data:`MAX_READ_BYTES`) is the starting content, for an append.

    Raises
    ------
    OutputError
        The folder cannot be made, or the write failed (full disk, file-size limit, ...), or
        ``fill`` raised an ``OSError``; ``dest`` is left as it was.
    DatasetError
        ``base`` is too large to be rewritten in memory.
    """
    dest = Path(dest)
    image = b""
    if base is not None:
        size = base.stat().st_size
        if size > MAX_READ_BYTES:
            raise DatasetError(
                f"is {_size(size)}, over the {_size(MAX_READ_BYTES)} teachfit appends to: "
                "write the new data to a new file",
                path=str(base),
            )
        image = base.read_bytes()
    buf = io.BytesIO(image)
    try:
        with h5py.File(buf, "r+" if image else "w") as f:
            fill(f)
    except OSError as exc:  # as inside atomic_path: one error naming the file
        if isinstance(exc, OutputError):
            raise
        raise OutputError(f"cannot write {what} {dest}: {write_error(exc)}") from exc
    return atomic_write_bytes(dest, buf.getvalue(), what)


def _refuse_external(f: h5py.File, path: Path) -> None:
    """DatasetError naming the first link to another file (checked before anything is read
    through one; soft links stay inside the file and are followed)."""

    def links(group: h5py.Group) -> None:
        for name in group:
            link = group.get(name, getlink=True)
            if isinstance(link, h5py.ExternalLink):
                where = f"{group.name.rstrip('/')}/{name}"
                raise DatasetError(
                    f"{where} is an external link to {link.filename}:{link.path}; teachfit "
                    "follows no links to other files: copy that data into this file",
                    path=str(path),
                )

    links(f)
    f.visititems(lambda _name, obj: links(obj) if isinstance(obj, h5py.Group) else None)


@contextmanager
def open_hdf5(path: str | Path, limit: int = MAX_READ_BYTES) -> Iterator[H5Reader]:
    """Open an HDF5 file to read, its external links refused; yields an :class:`H5Reader`.
    h5py's errors on a damaged file, in the body too, become :class:`DatasetError`."""
    path = Path(path)
    if not path.is_file():
        raise DatasetError("no such file", path=str(path))
    if not h5py.is_hdf5(path):
        raise DatasetError("not an HDF5 file", path=str(path))
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise DatasetError(f"cannot open as HDF5 ({one_line(exc)})", path=str(path)) from exc
    try:
        with f:
            _refuse_external(f, path)
            yield H5Reader(f, path, limit)
    except H5_ERRORS as exc:
        raise DatasetError(
            f"damaged HDF5 file, cannot read it ({one_line(exc)})", path=str(path)
        ) from exc


def _kind_of(obj: object) -> str:
    return "group" if isinstance(obj, h5py.Group) else "dataset"


class H5Reader:
    """Reads groups, datasets and attributes of one open file with their kind, type and size
    checked first; counts the bytes read against ``limit``."""

    def __init__(self, f: h5py.File, path: Path, limit: int = MAX_READ_BYTES) -> None:
        self.file, self.path, self.limit, self.read_bytes = f, path, limit, 0

    def error(self, message: str, column: str | None = None) -> DatasetError:
        return DatasetError(message, path=str(self.path), column=column)

    def check_version(self, supported: int) -> None:
        """DatasetError unless the root's ``format_version`` attribute is ``supported``."""
        version = self.file.attrs.get("format_version")
        version = version.item() if isinstance(version, np.generic) else version
        if type(version) is not int or version != supported:
            raise self.error(
                f"unsupported format_version {shown(version)} (this teachfit reads {supported})"
            )

    def group(self, parent: h5py.Group, name: str) -> h5py.Group:
        """The group ``name`` of ``parent``; DatasetError when missing or not a group."""
        obj = parent.get(name)
        where = f"{parent.name.rstrip('/')}/{name}"
        if obj is None:
            raise self.error(f"missing group {where}")
        if not isinstance(obj, h5py.Group):
            raise self.error(f"{where} is a {_kind_of(obj)}, not a group")
        return obj

    @overload
    def dataset(
        self, parent: h5py.Group, name: str, kinds: str = ..., required: Literal[True] = ...
    ) -> np.ndarray: ...
    @overload
    def dataset(
        self, parent: h5py.Group, name: str, kinds: str = ..., *, required: bool
    ) -> np.ndarray | None: ...
    def dataset(
        self, parent: h5py.Group, name: str, kinds: str = "iuf", required: bool = True
    ) -> np.ndarray | None:
        """The values of dataset ``name`` of ``parent`` (None when missing and not required),
        after checking it is a dataset of ``kinds`` (numpy kind letters, ``"OSU"``: text)
        stored in this file, and that its declared size fits what is left of the limit."""
        obj = parent.get(name)
        where = f"{parent.name.rstrip('/')}/{name}"
        if obj is None:
            if required:
                raise self.error(f"{parent.name} has no dataset {name!r}", name)
            return None
        if not isinstance(obj, h5py.Dataset):
            raise self.error(f"{where} is a {_kind_of(obj)}, not a dataset", name)
        text = kinds == "OSU" and h5py.check_string_dtype(obj.dtype) is not None
        if not text and obj.dtype.kind not in kinds:
            want = "text" if kinds == "OSU" else "real numbers"
            raise self.error(f"{where} holds {obj.dtype} values, not {want}", name)
        if obj.shape is None:
            raise self.error(f"{where} holds no values (an empty dataspace)", name)
        if obj.external or obj.is_virtual:
            raise self.error(
                f"{where} keeps its data in other files; teachfit reads data stored in "
                "this file only",
                name,
            )
        self._count(obj, where, name)
        return obj[()]

    def _count(self, obj: h5py.Dataset, where: str, name: str) -> None:
        declared = math.prod(obj.shape) * obj.dtype.itemsize
        if self.read_bytes + declared > self.limit:
            file_size = self.path.stat().st_size
            raise self.error(
                f"{where} declares {obj.shape} values ({_size(declared)}) in a file of "
                f"{_size(file_size)}: over the {_size(self.limit)} teachfit reads from one "
                "file (damaged or crafted, or split the data over several files)",
                name,
            )
        self.read_bytes += declared

    def text(self, obj: h5py.HLObject, label: str, default: str | None = None) -> str:
        """String attribute ``label`` of ``obj`` (``default`` when absent; DatasetError when
        absent without a default, or when it holds anything but one string)."""
        if label not in obj.attrs:
            if default is None:
                raise self.error(f"{obj.name} has no attribute {label!r}", label)
            return default
        value = self.attr(obj, label)
        if isinstance(value, bytes | np.bytes_):
            try:
                return bytes(value).decode("utf-8")
            except UnicodeDecodeError:
                pass
        elif isinstance(value, str):
            return value
        raise self.error(
            f"{obj.name}: attribute {label!r} is {shown(value)} ({type(value).__name__}), "
            "not a text string",
            label,
        )

    def attr(self, obj: h5py.HLObject, label: str) -> Any:
        """Attribute ``label`` of ``obj`` as h5py reads it (scalars as numpy scalars)."""
        try:
            return obj.attrs[label]
        except (OSError, TypeError, ValueError) as exc:  # a type h5py cannot convert
            raise self.error(
                f"{obj.name}: attribute {label!r} cannot be read ({one_line(exc)})", label
            ) from exc
