"""Caches that heal: content keys, broken entries rebuilt, user cache folder, one build at a time."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import numpy as np
import pytest

from woodcam._cache import CacheWarning, cache_root, digest, load_or_build

REPO = Path(__file__).resolve().parents[2]


def test_digest_is_content_based(tmp_path):
    a = np.zeros((4, 4), np.uint8)
    b = a.copy()
    assert digest(a, "x", 1.0) == digest(b, "x", 1.0)
    b[2, 2] = 1
    assert digest(a) != digest(b)
    assert digest(a.astype(np.uint16)) != digest(a)  # dtype is part of the content
    # so is the shape: the same bytes as a (2, 8) or a (16,) array are other content
    assert len({digest(a), digest(a.reshape(2, 8)), digest(a.reshape(16))}) == 3
    assert digest([1, 2]) != digest([12]) and digest("ab", "c") != digest("a", "bc")
    assert digest(1) != digest("1") and digest(True) != digest("True")  # and the type
    assert digest({"k": 1, "j": 2}) == digest({"j": 2, "k": 1})
    # a Path is its file's content: an edit changes the key, a copy under another name does not
    f, g = tmp_path / "f.json", tmp_path / "g.json"
    f.write_text("one")
    g.write_text("one")
    before = digest(f)
    assert before == digest(g) == digest(b"one")
    f.write_text("two")
    assert digest(f) == digest(b"two") != before


def test_cache_root_honours_xdg(monkeypatch, tmp_path):
    monkeypatch.delenv("WOODCAM_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache_root() == tmp_path / "xdg" / "woodcam"
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "mine"))
    assert cache_root() == tmp_path / "mine"


def _npy_cache(path, value, calls):
    def build():
        calls.append(1)
        return value

    return load_or_build(path, load=lambda p: np.load(p, allow_pickle=False),
                         build=build, save=lambda v, tmp: np.save(tmp, v), what="test cache")


@pytest.mark.parametrize("damage", ["truncate", "empty", "garbage"])
def test_broken_entry_is_discarded_with_a_warning_and_rebuilt(tmp_path, damage):
    path = tmp_path / "entry.npy"
    calls = []
    _value, hit = _npy_cache(path, np.arange(1000.0), calls)
    assert not hit and calls == [1]
    data = path.read_bytes()
    path.write_bytes({"truncate": data[: len(data) // 2], "empty": b"",
                      "garbage": os.urandom(len(data))}[damage])
    with pytest.warns(CacheWarning, match="discarded the unreadable cache entry"):
        _value, hit = _npy_cache(path, np.arange(1000.0), calls)
    assert not hit and calls == [1, 1]
    np.testing.assert_array_equal(np.load(path), np.arange(1000.0))  # healed on disk
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _value, hit = _npy_cache(path, np.arange(1000.0), calls)
    assert hit and calls == [1, 1]


def test_unwritable_cache_folder_still_returns_the_value(tmp_path):
    (tmp_path / "file").write_text("")
    with pytest.warns(CacheWarning, match="cannot use the cache folder"):
        value, hit = _npy_cache(tmp_path / "file" / "entry.npy", np.ones(3), [])
    assert not hit and value.tolist() == [1, 1, 1]


def test_a_folder_where_the_lock_belongs_is_removed_and_the_entry_kept(tmp_path, monkeypatch):
    """A folder at ``<entry>.lock`` was reported as an unusable cache folder ("Is a directory"),
    although the folder was fine, and the entry was rebuilt on every run, never kept."""
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path))
    path = tmp_path / "fields" / "entry.npy"
    (tmp_path / "fields" / "entry.npy.lock").mkdir(parents=True)
    calls = []
    with pytest.warns(CacheWarning, match="removed the folder .*entry.npy.lock.* where the cache entry's lock file belongs"):
        _value, hit = _npy_cache(path, np.ones(3), calls)
    assert not hit and path.is_file() and (tmp_path / "fields" / "entry.npy.lock").is_file()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _value, hit = _npy_cache(path, np.ones(3), calls)
    assert hit and calls == [1]


def test_concurrent_builders_build_once(tmp_path):
    """Two processes asking for the same missing entry: one builds, the other waits and loads."""
    script = textwrap.dedent(f"""
        import time, numpy as np
        from woodcam._cache import load_or_build
        def build():
            with open({str(tmp_path / "builds.log")!r}, "a") as fh:
                fh.write("b\\n")
            time.sleep(1.0)
            return np.arange(5.0)
        v, hit = load_or_build({str(tmp_path / "e.npy")!r}, load=np.load, build=build,
                               save=lambda v, t: np.save(t, v))
        print(hit, v.sum())
    """)
    env = dict(os.environ, PYTHONPATH=str(REPO))
    procs = [subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, env=env,
                              text=True) for _ in range(2)]
    outs = sorted(p.communicate(timeout=120)[0].strip() for p in procs)
    assert outs == ["False 10.0", "True 10.0"]
    assert (tmp_path / "builds.log").read_text() == "b\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["builds.log", "e.npy", "e.npy.lock"]


# -- the fitted-field cache of block folders and Mokume samples -------------------------------------

@pytest.fixture(scope="module")
def traced_block():
    from woodcam.fields.builtin import builtin_block
    from woodcam.synth import synth_block

    block = synth_block(builtin_block("flat-sawn").field, (40, 30, 20), face_px=48, seed=0)
    block.true_field = None
    return block


def _field_entries(cache: Path) -> list[Path]:
    return sorted((cache / "fields").glob("*.npz"))


def test_truncated_field_cache_heals(traced_block, tmp_path, monkeypatch):
    """Issue 15: a kill during the first fit left a truncated field cache and every later run of
    that block died with BadZipFile/EOFError. Now it warns, refits and rewrites the entry."""
    from woodcam.stock import fitted_field

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path))
    pts = np.random.default_rng(0).uniform(0, 1, (500, 3)) * (40, 30, 20)
    first = fitted_field(traced_block)(pts)
    (entry,) = _field_entries(tmp_path)
    entry.write_bytes(entry.read_bytes()[:200])
    with pytest.warns(CacheWarning, match="unreadable cache entry"):
        again = fitted_field(traced_block)(pts)
    np.testing.assert_allclose(again, first, atol=1e-9)
    assert _field_entries(tmp_path) == [entry] and entry.stat().st_size > 200


def test_field_cache_key_is_content_not_mtime(traced_block, tmp_path, monkeypatch):
    """Issue 15: fields were keyed by block.json's mtime, so a changed ring trace reused the old
    field. Editing one trace (and a knot mask) must make a new entry."""
    import copy

    from woodcam.stock import fitted_field

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path))
    fitted_field(traced_block)
    edited = copy.deepcopy(traced_block)
    face = next(f for f in edited.faces.values() if f.traces)
    face.traces = face.traces[:-1]
    fitted_field(edited)
    assert len(_field_entries(tmp_path)) == 2
    masked = copy.deepcopy(traced_block)
    face = next(iter(masked.faces.values()))
    face.extras["knot_mask"] = np.zeros(face.shape, bool)
    fitted_field(masked)
    assert len(_field_entries(tmp_path)) == 3
    fitted_field(copy.deepcopy(traced_block))  # same content: reused
    assert len(_field_entries(tmp_path)) == 3


def test_field_cache_key_holds_which_pieces_are_one_ring(traced_block, tmp_path, monkeypatch):
    """Pieces of one ring share ``RingTrace.ring`` and the fitter gives them one growth time, but
    the key left the ids out: a block whose pieces were linked otherwise (an SVG's ring ids
    edited) was given the field fitted before the edit. Known answer: the field fitted to the
    edited block without the cache."""
    import copy

    from woodcam.block import RingTrace
    from woodcam.inference import fit_block
    from woodcam.stock import fitted_field

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path))
    rings = copy.deepcopy(traced_block)  # unlabelled, each trace a ring of its own
    for f in rings.faces.values():
        f.traces = [RingTrace(t.points_px, None, k) for k, t in enumerate(f.traces)]
    linked = copy.deepcopy(rings)  # the front face's first three traces made one ring
    front = linked.faces["front"]
    front.traces = [RingTrace(t.points_px, None, 0 if k < 3 else k) for k, t in enumerate(front.traces)]
    pts = np.random.default_rng(0).uniform(0, 1, (500, 3)) * (40, 30, 20)
    before = fitted_field(rings)(pts)
    after = fitted_field(linked)(pts)
    assert len(_field_entries(tmp_path)) == 2
    np.testing.assert_allclose(after, fit_block(linked)(pts), atol=1e-9)
    assert np.abs(after - before).max() > 0.1  # the link changes the fit: a stale field is wrong


def test_the_same_content_under_another_name_is_one_entry(traced_block, tmp_path, monkeypatch):
    """The key is the content, but the entry's file name began with the block's name: the same
    block folder copied as another name was fitted again and stored twice, byte-identical."""
    import copy

    from woodcam import stock

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path))
    stock.fitted_field(traced_block)
    (entry,) = _field_entries(tmp_path)
    renamed = copy.deepcopy(traced_block)
    renamed.name = "copy_of_it"

    def no_refit(*args, **kwargs):
        raise AssertionError("refitted a block whose content is cached under another name")

    monkeypatch.setattr("woodcam.inference.fit_block", no_refit)
    stock.fitted_field(renamed)
    assert _field_entries(tmp_path) == [entry]


def test_read_only_block_folder_is_never_written(traced_block, tmp_path, monkeypatch):
    """Issue 15: a read-only block folder crashed because the cache was written inside it."""
    from woodcam.block.io import write_block
    from woodcam.stock import open_stock

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    folder = tmp_path / "blk"
    write_block(traced_block, folder)
    before = {p: p.stat().st_mtime_ns for p in folder.rglob("*")}
    modes = {p: p.stat().st_mode for p in [folder, *folder.rglob("*")] if p.is_dir()}
    for p in modes:
        p.chmod(0o555)
    try:
        stock = open_stock(str(folder))
    finally:
        for p, m in modes.items():
            p.chmod(m)
    assert {p: p.stat().st_mtime_ns for p in folder.rglob("*")} == before
    assert len(_field_entries(tmp_path / "cache")) == 1
    assert np.isfinite(stock.wood.field(np.array([[20.0, 15.0, 10.0]]))).all()


def test_a_prune_or_clear_leaves_the_entry_another_run_is_writing(tmp_path, monkeypatch):
    """entries() listed the hidden temporary of an entry being written: another run's prune
    (or a 'cache clear') deleted it, and the writing run, its build done, failed with
    "atomic_path: the writer ... wrote no file". A killed writer's temporary is still cleared."""
    import threading

    from woodcam._cache import cache_dir, clear, entries, prune

    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(tmp_path / "cache"))
    path = cache_dir("fields") / "b-key.npz"
    seen, writing, pruned = [], threading.Event(), threading.Event()

    def slow_save(value, tmp):
        with open(tmp, "wb") as fh:
            np.save(fh, value)
        writing.set()  # the writer half way; another run prunes meanwhile
        assert pruned.wait(30)

    def another_run():
        assert writing.wait(30)
        seen.append([p.name for p in entries()])
        prune(0)
        clear("fields")
        pruned.set()

    other = threading.Thread(target=another_run)
    other.start()
    value, hit = load_or_build(path, load=np.load, build=lambda: np.arange(10.0), save=slow_save,
                               what="test cache")
    other.join()
    assert not hit and seen == [[]]
    np.testing.assert_array_equal(np.load(path), np.arange(10.0))
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True).stdout.strip()
    orphan = path.parent / f".b-other.npz.{dead}-x1y2.tmp.npz"
    orphan.write_bytes(b"half")
    assert orphan in entries("fields")
    assert clear("fields")[0] == 2 and not orphan.exists() and not path.exists()


def test_prune_and_clear_touch_only_woodcams_folders_under_the_cache_root(tmp_path, monkeypatch, capsys):
    """The whole cache root was walked: with WOODCAM_CACHE_DIR=~/.cache (or a shared scratch
    folder) the size limit's prune, run after every entry written, deleted other programs' and
    the user's files there, oldest first, and 'woodcam cache clear' every file under it."""
    from woodcam._cache import cache_dir, entries, prune
    from woodcam.cli import main

    root = tmp_path / "dot-cache"
    monkeypatch.setenv("WOODCAM_CACHE_DIR", str(root))
    monkeypatch.setenv("WOODCAM_CACHE_MAX_MB", "0.1")
    theirs = [root / "pip" / "wheel.whl", root / "thesis.tex", root / "other-app" / "db.lock"]
    for f in theirs:
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_bytes(os.urandom(200_000))
    ours = cache_dir("fields") / "b-key.npy"
    load_or_build(ours, load=np.load, build=lambda: np.zeros(10), save=lambda v, tmp: np.save(tmp, v))
    assert entries() == [ours]
    assert all(f.is_file() for f in theirs)  # the prune after the save left them
    prune(0)
    assert main(["cache", "clear"]) == 0
    capsys.readouterr()
    assert all(f.is_file() for f in theirs)
