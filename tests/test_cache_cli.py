"""woodcam cache: the user cache folder (XDG_CACHE_HOME), a size limit, info and clear."""

from __future__ import annotations

import os
import time

from woodcam._cache import cache_root, load_or_build, prune
from woodcam.cli import main


def test_cache_follows_xdg_and_keeps_under_its_limit(tmp_path, monkeypatch, capsys):
    monkeypatch.delenv("WOODCAM_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache_root() == tmp_path / "xdg" / "woodcam"
    monkeypatch.setenv("WOODCAM_CACHE_MAX_MB", "1")  # 1 MiB: room for two 400 KiB entries
    for i in range(4):
        load_or_build(cache_root() / "fields" / f"e{i}.bin", load=lambda p: p.read_bytes(),
                      build=lambda: os.urandom(400 * 1024),
                      save=lambda v, p: p.write_bytes(v))
        time.sleep(0.01)
    names = sorted(p.name for p in (cache_root() / "fields").glob("*.bin"))
    assert names == ["e2.bin", "e3.bin"]  # the least recently used went first
    assert main(["cache", "info"]) == 0
    assert "2 entries" in capsys.readouterr().out
    assert main(["cache", "clear"]) == 0
    assert "deleted 2 entries" in capsys.readouterr().out
    assert list((cache_root() / "fields").glob("*.bin")) == []
    assert prune(0) == 0


def test_clear_takes_only_a_known_kind(tmp_path, monkeypatch, capsys):
    """'cache clear --kind /some/folder' deleted every file under that folder (a kind was joined
    to the cache root unchecked), and '--kind bogus' said 'deleted 0' with exit 0."""
    import pytest

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    victim = tmp_path / "victim"
    (victim / "sub").mkdir(parents=True)
    (victim / "a.txt").write_text("a")
    (victim / "sub" / "b.txt").write_text("b")
    (tmp_path / "cache" / "fields").mkdir(parents=True)
    (tmp_path / "cache" / "fields" / "x.npz").write_bytes(b"x")
    (tmp_path / "cache" / "detect").mkdir()
    (tmp_path / "cache" / "detect" / "y.npz").write_bytes(b"y")
    for kind in (str(victim), "../victim", "bogus", ""):
        with pytest.raises(SystemExit) as exc:
            main(["cache", "clear", "--kind", kind])
        assert exc.value.code == 2 and "invalid choice" in capsys.readouterr().err
    assert (victim / "a.txt").is_file() and (victim / "sub" / "b.txt").is_file()
    from woodcam._cache import clear
    from woodcam.errors import WoodcamError

    with pytest.raises(WoodcamError, match="cache kind must be one of"):
        clear("../victim")
    assert main(["cache", "clear", "--kind", "fields"]) == 0
    assert "deleted 1 entries" in capsys.readouterr().out
    assert (tmp_path / "cache" / "detect" / "y.npz").is_file()


def test_clear_removes_the_idle_locks_but_not_a_held_one(tmp_path, monkeypatch, capsys):
    """One .lock file was left per entry ever built; clearing and pruning skipped them."""
    from woodcam._cache import clear, file_lock

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path))
    for i in range(3):
        load_or_build(tmp_path / "fields" / f"e{i}.bin", load=lambda p: p.read_bytes(),
                      build=lambda: b"x", save=lambda v, p: p.write_bytes(v))
    assert len(list((tmp_path / "fields").glob("*.lock"))) == 3
    with file_lock(tmp_path / "fields" / "building.bin"):  # another process building an entry
        assert clear() == (3, 3)
        assert [p.name for p in (tmp_path / "fields").iterdir()] == ["building.bin.lock"]
    assert prune(0) == 0
    clear()
    assert list((tmp_path / "fields").iterdir()) == []


def test_a_folder_where_an_entry_belongs_is_replaced_by_the_entry(tmp_path, monkeypatch):
    """The entry was never saved (it could not replace the folder), so the work was redone on
    every run, with a warning each time."""
    import warnings

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path))
    entry = tmp_path / "fields" / "e.bin"
    (entry / "junk").mkdir(parents=True)
    builds = []

    def build():
        builds.append(1)
        return b"x"

    for _ in range(2):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            load_or_build(entry, load=lambda p: p.read_bytes(), build=build, save=lambda v, p: p.write_bytes(v))
    assert entry.is_file() and len(builds) == 1


def test_the_cache_help_names_every_kind_it_holds():
    """'woodcam cache --help' and the command list said "fitted fields, colour volumes" while
    'cache info' counts ring detections too (the detect folder) and 'cache clear --kind' takes
    it: each help now names every kind of CACHE_KINDS, with its folder's name."""
    from woodcam._cache import CACHE_KINDS
    from woodcam.cli import _commands, build_parser

    helps = {path: (text, sp) for path, text, sp in _commands(build_parser())}
    text, cache = helps[("cache",)]
    clear = " ".join(helps[("cache", "clear")][1].format_help().split())
    for kind in CACHE_KINDS:
        assert f"({kind})" in cache.description and f"({kind})" in clear, (kind, cache.description, clear)
    assert "ring detections" in text and "ring detections (detect)" in cache.description, text
