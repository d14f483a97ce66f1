"""Where a study is stored: a file path (an SQLite database) or a database URL.

A storage given as ``scheme://...`` is a URL, kept as it is once checked: its back end must be
one Optuna stores studies in (:data:`BACKENDS`) and its driver must be installed, else a
:class:`LearningError` names the study, what is wrong and the fix -- before anything is
written. Anything else is a file path, quoted into an ``sqlite:///`` URL so that the database
lands exactly at the name given (``?``, ``#``, ``%`` and spaces are file name characters, not
URL syntax); ``./nosuch://x`` is a file path too.
"""

from __future__ import annotations

import re
from pathlib import Path

from sqlalchemy.engine import URL, make_url
from sqlalchemy.exc import ArgumentError, NoSuchModuleError

from teachfit.core.atomic import ensure_folder
from teachfit.core.params import LearningError

#: database back ends (SQLAlchemy dialect names) Optuna stores studies in
BACKENDS = ("sqlite", "postgresql", "mysql")

#: pip package of a driver SQLAlchemy imports under another name
_PACKAGES = {
    "MySQLdb": "mysqlclient",
    "psycopg": "'psycopg[binary]'",
    "psycopg2": "psycopg2-binary",
    "pymysql": "PyMySQL",
    "mysql": "mysql-connector-python",
    "pysqlcipher3": "sqlcipher3-binary",
}

_SCHEME = re.compile(r"[A-Za-z][A-Za-z0-9+.\-]*://")

#: the first 16 bytes of every SQLite database file
_SQLITE_HEADER = b"SQLite format 3\x00"


def is_url(storage: str | Path) -> bool:
    """Whether ``storage`` is a URL (``scheme://...``) rather than a file path."""
    return isinstance(storage, str) and _SCHEME.match(storage) is not None


def shown(url: str) -> str:
    """A storage URL as a person reads it: an SQLite file's path, any other URL without its
    password."""
    parsed = make_url(url)
    if parsed.get_backend_name() == "sqlite" and parsed.database not in (None, "", ":memory:"):
        return str(parsed.database)
    return parsed.render_as_string(hide_password=True)


def _check_url(text: str) -> None:
    try:
        url = make_url(text)
    except (ArgumentError, ValueError):
        raise LearningError(
            f"study {text}: not a database URL; give a file path (SQLite) or a URL like "
            "postgresql://USER@HOST/DB"
        ) from None
    name, backend = url.render_as_string(hide_password=True), url.get_backend_name()
    if backend not in BACKENDS:
        raise LearningError(
            f"study {name}: unknown database scheme {url.drivername!r}; give a file path "
            f"(SQLite) or a URL of {', '.join(BACKENDS)} (e.g. postgresql://USER@HOST/DB); a "
            f"file named so: ./{name}"
        )
    try:
        dialect = url.get_dialect()
    except NoSuchModuleError:
        raise LearningError(
            f"study {name}: SQLAlchemy has no driver {url.get_driver_name()!r} for {backend}; "
            f"name an installed one, or none: {backend}://..."
        ) from None
    if dialect.is_async:
        raise LearningError(
            f"study {name}: {url.get_driver_name()} is an asyncio driver; name a blocking one "
            f"(e.g. {backend}://...)"
        )
    try:
        dialect.import_dbapi()
    except ImportError as exc:
        module = (exc.name or url.get_driver_name()).split(".")[0]
        raise LearningError(
            f"study {name}: its {backend} driver {module} is not installed: pip install "
            f"{_PACKAGES.get(module, module)} (or name an installed driver: {backend}+DRIVER://...)"
        ) from None
    if backend == "sqlite" and url.database in (None, "", ":memory:"):
        raise LearningError(
            f"study {name}: an in-memory database keeps no trial; give a file (e.g. runs/s.db)"
        )


def _check_file(storage: str | Path) -> Path:
    text = str(storage)
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        raise LearningError(
            f"study file {text!r}: the name is not valid UTF-8; rename it or give another"
        ) from None
    path = Path(text).expanduser().resolve()
    if path.is_dir():
        raise LearningError(f"study file {text} is a folder; give a file name (e.g. runs/s.db)")
    if path.is_file() and path.stat().st_size > 0:
        try:
            with path.open("rb") as fh:
                header = fh.read(16)
        except OSError as exc:
            raise LearningError(f"cannot read study file {text}: {exc.strerror}") from exc
        if header != _SQLITE_HEADER:
            raise LearningError(
                f"study file {text} is not an SQLite database; give a new file name, an "
                "existing study, or a database URL"
            )
    return path


def check_storage(storage: str | Path) -> None:
    """Refuse a storage that cannot hold a study (:class:`LearningError` naming it and the
    fix), creating nothing: a URL of an unknown back end or without its driver, a file that
    is a folder or no SQLite database."""
    if is_url(storage):
        _check_url(str(storage))
    else:
        _check_file(storage)


def storage_url(storage: str | Path) -> str:
    """The SQLAlchemy URL of a checked storage: a URL as it is; a file path (``~`` expanded)
    quoted into ``sqlite:///<absolute path>``, its folder created."""
    if is_url(storage):
        _check_url(str(storage))
        return str(storage)
    path = _check_file(storage)
    ensure_folder(path.parent, f"the folder of study file {storage}")
    return URL.create("sqlite", database=str(path)).render_as_string(hide_password=False)


def params_path(storage: str | Path) -> Path | None:
    """Where ``learn skill`` writes the best parameters by default: beside a study file, with
    the suffix ``.params.toml``; ``None`` for a database URL."""
    if is_url(storage):
        return None
    return Path(str(storage)).expanduser().with_suffix(".params.toml")
