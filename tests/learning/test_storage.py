"""Study storages: a file path is a file path (the database lands exactly at that name), a URL
is a URL, and one that cannot work (unknown scheme, missing or asyncio driver, in memory) is
one clear error before anything is written."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from teachfit.core.params import LearningError
from teachfit.learning import ParamDomain, ParamSpace, Study, TrialResult
from teachfit.learning.storage import check_storage, is_url, params_path, shown, storage_url
from teachfit.learning.study import stored_tags

SPACE = ParamSpace({"a": ParamDomain(0.0, 1.0)})
ODD_NAMES = ["a?b.db", "50%41.db", "c#d e@h:1.db", "x;y=z&w+v%3F.db", "é.db"]


def _open(storage: str | Path) -> Study:
    return Study(
        storage, task="puzzle", skill="peg-in-hole", space=SPACE, method="lhs", options={"n": 3}
    )


@pytest.mark.parametrize("name", ODD_NAMES)
def test_a_file_path_lands_exactly_at_its_name_and_resumes(tmp_path: Path, name: str) -> None:
    folder = tmp_path / "runs"
    study = _open(str(folder / name))
    cand = study.ask(3)
    assert cand is not None
    study.tell(cand, TrialResult(0.5, True))
    study.close()
    assert sorted(p.name for p in tmp_path.rglob("*")) == sorted(["runs", name])
    assert shown(study.url) == study.where == str(folder / name)
    tags = stored_tags(str(folder / name))
    assert tags is not None and tags["method"] == "lhs"
    assert [t.cost for t in _open(str(folder / name)).trials()] == [0.5]
    assert params_path(str(folder / name)) == folder / (Path(name).stem + ".params.toml")


def test_paths_and_urls_are_told_apart(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from sqlalchemy.engine import make_url

    for url in ("sqlite:///x.db", "postgresql://u@h/db", "mysql+pymysql://u@h/db", "nosuch://x"):
        assert is_url(url) and params_path(url) is None
    for path in ("runs/a://b.db", "./nosuch://x", "a?b.db", "s.db", Path("sqlite:///x.db")):
        assert not is_url(path)
    assert params_path("~/s.db") == Path.home() / "s.params.toml"
    url = f"sqlite:///{tmp_path / 'given.db'}"
    assert storage_url(url) == url  # a URL stays as it is
    monkeypatch.chdir(tmp_path)
    assert make_url(storage_url("./nosuch://x")).database == str(tmp_path / "nosuch:" / "x")


def _missing(module: str) -> bool:
    return importlib.util.find_spec(module) is None


REFUSED = [
    ("nosuch://x", "unknown database scheme 'nosuch'; give a file path (SQLite) or a URL of"),
    ("mssql://u@h/db", "unknown database scheme 'mssql'"),
    ("mysql+nosuchdriver://u@h/db", "SQLAlchemy has no driver 'nosuchdriver' for mysql"),
    ("postgresql+asyncpg://u@h/db", "asyncpg is an asyncio driver; name a blocking one"),
    ("sqlite://", "an in-memory database keeps no trial"),
    ("sqlite:///:memory:", "an in-memory database keeps no trial"),
    ("mysql://u@h:port/db", "not a database URL"),
]


@pytest.mark.parametrize(("url", "message"), REFUSED)
def test_a_url_that_cannot_hold_a_study_is_one_clear_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, url: str, message: str
) -> None:
    monkeypatch.chdir(tmp_path)
    for call in (check_storage, storage_url, _open, stored_tags):
        with pytest.raises(LearningError) as err:
            call(url)
        assert message in str(err.value) and "\n" not in str(err.value)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not _missing("MySQLdb"), reason="mysqlclient is installed")
def test_a_missing_driver_names_its_package_and_hides_the_password(tmp_path: Path) -> None:
    with pytest.raises(LearningError) as err:
        check_storage("mysql://user:secret@db.example/studies")
    text = str(err.value)
    assert text.startswith("study mysql://user:***@db.example/studies: its mysql driver MySQLdb")
    assert "pip install mysqlclient" in text and "secret" not in text
    if _missing("pymysql"):
        with pytest.raises(LearningError, match="pip install PyMySQL"):
            check_storage("mysql+pymysql://u@h/db")


def test_a_file_that_cannot_hold_a_study_is_one_clear_error(tmp_path: Path) -> None:
    with pytest.raises(LearningError, match="is a folder"):
        check_storage(str(tmp_path))
    bad = "\udcff.db"  # a name that is not UTF-8 (as Linux hands it over)
    with pytest.raises(LearningError, match="not valid UTF-8"):
        check_storage(str(tmp_path / bad))
    assert list(tmp_path.iterdir()) == []
