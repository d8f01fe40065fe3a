"""On-disk caches that heal: content-keyed, self-repairing, safe for concurrent writers.

Where caches live: ``$WOODCAM_CACHE_DIR`` if set, else the user cache folder of
:mod:`platformdirs` (``$XDG_CACHE_HOME/woodcam``, by default ``~/.cache/woodcam`` on Linux),
never inside a user's block or sample folder (those may be read-only shared data).

How an entry is found: its file name holds :func:`digest` of *every* input that changes the
result (image and mask pixels, traces, settings, the producing code's version), never a
modification time, so an edited ring map or knot mask is a different entry.

What :func:`load_or_build` guarantees:

* an entry that fails to load (truncated by a crash, corrupted, written by an incompatible
  version) is deleted with a :class:`CacheWarning` and rebuilt;
* entries are written atomically (:mod:`woodcam._atomic`): unique temporary name + rename, so a
  reader never sees half a file and two writers never interleave;
* concurrent builders of the *same* entry take an advisory lock (``fcntl.flock`` on
  ``<entry>.lock``): the second waits, then loads what the first built instead of repeating
  minutes of work. The kernel drops the lock when a holder dies, so a killed run never leaves a
  stale lock behind.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import sys
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, TypeVar

from ._atomic import apart, atomic_path, in_flight
from .errors import WoodcamError, WoodcamWarning

__all__ = ["CacheWarning", "cache_dir", "cache_root", "check_cache_root", "digest", "entry_path", "file_lock",
           "load_or_build"]

T = TypeVar("T")


class CacheWarning(WoodcamWarning):
    """A cache entry could not be read and was discarded; it is rebuilt (nothing to do)."""


def cache_root() -> Path:
    """``$WOODCAM_CACHE_DIR``, else platformdirs' user cache folder for woodcam (honours
    ``$XDG_CACHE_HOME`` on Linux)."""
    base = os.environ.get("WOODCAM_CACHE_DIR")
    if base:
        return Path(base).expanduser()
    import platformdirs

    return Path(platformdirs.user_cache_dir("woodcam", appauthor=False))


def check_cache_root() -> Path:
    """:func:`cache_root`, refused where it is not a folder: ``$WOODCAM_CACHE_DIR`` naming a
    file made every fit warn and redo its work, and ``woodcam cache info``/``clear`` report
    "0 entries" of the file. The one rule of the setting (a folder not made yet is fine)."""
    root = cache_root()
    if root.exists() and not root.is_dir():
        given = os.environ.get("WOODCAM_CACHE_DIR")
        if given:
            raise WoodcamError(f"WOODCAM_CACHE_DIR must be a folder (woodcam keeps its caches in it); got "
                               f"{given!r}, which is a file; export WOODCAM_CACHE_DIR=FOLDER (one "
                               "that is not there is made), or unset it for the default user cache folder")
        raise WoodcamError(f"the cache folder {str(root)!r} must be a folder; it is a file; move the file "
                           "away, or export WOODCAM_CACHE_DIR=FOLDER")
    return root


#: The kinds of cache entry, one folder each: fitted fields (``woodcam.stock``), neural colour
#: volumes (``woodcam.appearance.neural``) and ring detections (``woodcam.detect.block``).
CACHE_KINDS: tuple[str, ...] = ("appearance", "detect", "fields")
#: What each kind's entries are, for ``woodcam cache``'s help.
CACHE_KIND_TEXT: dict[str, str] = {"fields": "fitted growth fields", "appearance": "neural colour volumes",
                                   "detect": "ring detections"}


def cache_dir(kind: str) -> Path:
    """The folder of one kind of cache entry (:data:`CACHE_KINDS`); not created. Any other
    name is refused: a kind is a folder name under the cache, and ``woodcam cache clear
    --kind /home/me`` emptied whatever folder it was given."""
    if kind not in CACHE_KINDS:
        raise WoodcamError(f"cache kind must be one of {', '.join(CACHE_KINDS)}; got {kind!r}")
    return cache_root() / kind


def _entry_stem(name: str) -> str:
    """A block's name as the start of a cache entry's file name: letters, digits, ``_.-`` only,
    at most 40 (a block named "../../x" put its detection outside the cache; 250 characters
    made the file name too long)."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", str(name))[:40] or "block"


def entry_path(folder, name: str, key: str, suffix: str = ".npz") -> Path:
    """The file of the entry keyed ``key`` in ``folder``: ``<_entry_stem(name)>-<key><suffix>``,
    or an entry of the same key already there under another block name.

    The key is the content; the name only labels the file for someone browsing the cache. A
    block folder copied under another name is the same content, and was fitted and stored a
    second time (byte-identical) when the name chose the file."""
    folder = Path(folder)
    tail = f"-{key}{suffix}"
    own = folder / f"{_entry_stem(name)}{tail}"
    if own.is_file():
        return own
    with contextlib.suppress(OSError):
        for p in sorted(folder.glob(f"*{tail}")):
            if p.is_file():
                return p
    return own


def _is_numpy(obj: Any) -> bool:
    """An array or numpy scalar, told without importing numpy (`woodcam cache --help` stays light;
    an object of numpy's comes from a loaded numpy)."""
    np = sys.modules.get("numpy")
    return np is not None and isinstance(obj, (np.ndarray, np.generic))


def _feed(h, obj: Any) -> None:
    """Feed ``obj`` to the hash unambiguously: type tag, length, content (arrays by dtype, shape
    and bytes; dicts by sorted key)."""
    if obj is None:
        h.update(b"N")
    elif isinstance(obj, (bool, int, float, str)):
        b = repr(obj).encode() if not isinstance(obj, str) else obj.encode()
        h.update(b"S" if isinstance(obj, str) else type(obj).__name__.encode()[:1])
        h.update(len(b).to_bytes(8, "little") + b)
    elif isinstance(obj, (bytes, bytearray, memoryview)):
        b = bytes(obj)
        h.update(b"B" + len(b).to_bytes(8, "little") + b)
    elif _is_numpy(obj):
        import numpy as np

        a = np.ascontiguousarray(obj)
        h.update(b"A" + a.dtype.str.encode() + repr(a.shape).encode())
        h.update(a.tobytes())
    elif isinstance(obj, dict):
        h.update(b"D" + len(obj).to_bytes(8, "little"))
        for k in sorted(obj, key=str):
            _feed(h, str(k))
            _feed(h, obj[k])
    elif isinstance(obj, (list, tuple)):
        h.update(b"L" + len(obj).to_bytes(8, "little"))
        for v in obj:
            _feed(h, v)
    elif isinstance(obj, Path):
        _feed(h, obj.read_bytes())
    else:
        raise WoodcamError(f"digest: cannot hash a {type(obj).__name__}; pass arrays, numbers, "
                           "strings, bytes, lists or dicts")


def digest(*parts: Any, length: int = 24) -> str:
    """Hex SHA-256 (first ``length`` characters) of ``parts``: arrays, numbers, strings, bytes,
    ``Path`` (the file's *content*), and lists/dicts of these."""
    h = hashlib.sha256()
    _feed(h, list(parts))
    return h.hexdigest()[:length]


@contextlib.contextmanager
def file_lock(path) -> Iterator[None]:
    """Hold an exclusive advisory lock on ``<path>.lock`` (waits for other holders).

    POSIX only; elsewhere it does nothing (atomic writes still keep entries whole)."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - Windows
        yield
        return
    lock = Path(str(path) + ".lock")
    lock.parent.mkdir(parents=True, exist_ok=True)
    fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o666)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # closing releases the lock


def _try_load(path: Path, load: Callable[[Path], T], what: str) -> tuple[bool, T | None]:
    if not path.is_file():
        return False, None
    try:
        return True, load(path)
    except Exception as err:  # noqa: BLE001 - any failure to read a cache entry means "rebuild"
        warnings.warn(CacheWarning(
            f"{what}: discarded the unreadable cache entry {str(path)!r} "
            f"({type(err).__name__}: {err}); rebuilding it"), stacklevel=3)
        with contextlib.suppress(OSError):
            path.unlink()
        return False, None


def load_or_build(path, *, load: Callable[[Path], T], build: Callable[[], T],
                  save: Callable[[T, Path], Any], what: str = "cache") -> tuple[T, bool]:
    """Return ``(value, hit)``: the cached value at ``path``, or a freshly built and saved one.

    Parameters
    ----------
    path : Path
        The entry's file; its name should hold :func:`digest` of the inputs.
    load : ``path -> value``; any exception means the entry is broken (discarded, rebuilt).
    build : ``() -> value``, the expensive work.
    save : ``(value, tmp_path) -> ...``, writes the value to the temporary path it is given
        (renamed onto ``path`` afterwards). A failed save (e.g. a read-only cache folder) warns
        and still returns the value.
    what : str
        Names the cache in warnings.
    """
    path = Path(path)
    ok, value = _try_load(path, load, what)
    if ok:
        return value, True
    # a folder where the lock belongs failed the lock's open with "Is a directory", reported as
    # an unusable cache folder, and every run redid the work
    _remove_folder_at(Path(str(path) + ".lock"), what, "cache entry's lock file")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        lock = file_lock(path)
        lock.__enter__()
    except OSError as err:  # cache folder not writable: work without the cache
        warnings.warn(CacheWarning(f"{what}: cannot use the cache folder {str(path.parent)!r} "
                                   f"({err.strerror}); set WOODCAM_CACHE_DIR to a writable "
                                   "folder to keep results"), stacklevel=2)
        return build(), False
    try:
        ok, value = _try_load(path, load, what)  # another process may have built it meanwhile
        if ok:
            return value, True
        value = build()
        _remove_folder_at(path, what, "cache entry")
        try:
            with apart(), atomic_path(path) as tmp:  # not part of the outputs' set it serves
                save(value, tmp)
            prune(keep=path)
        except OSError as err:
            warnings.warn(CacheWarning(f"{what}: could not write the cache entry {str(path)!r} "
                                       f"({err}); the result is used but not kept"), stacklevel=2)
        return value, False
    finally:
        lock.__exit__(None, None, None)


def _remove_folder_at(path: Path, what: str, role: str) -> None:
    """Remove a folder standing where the cache's file ``path`` belongs (made by hand or by
    another tool): it blocked every save, so the work was redone on every run. It goes, as a
    broken entry does; only inside the cache root, never through a link."""
    if path.is_dir() and not path.is_symlink() and cache_root().resolve() in path.resolve().parents:
        import shutil

        warnings.warn(CacheWarning(f"{what}: removed the folder {str(path)!r} that stood where the "
                                   f"{role} belongs"), stacklevel=3)
        shutil.rmtree(path, ignore_errors=True)


#: Default size limit of the whole cache (bytes); ``$WOODCAM_CACHE_MAX_MB`` overrides it. Fitted
#: fields are ~1-10 MB and neural colour volumes ~70 MB each, so 2 GB keeps a few dozen blocks.
DEFAULT_CACHE_MAX_BYTES = 2 * 2**30


def cache_max_bytes() -> int:
    """The cache's size limit: ``$WOODCAM_CACHE_MAX_MB`` (MiB) or :data:`DEFAULT_CACHE_MAX_BYTES`."""
    text = os.environ.get("WOODCAM_CACHE_MAX_MB")
    if not text:
        return DEFAULT_CACHE_MAX_BYTES
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not (value > 0 and value < 1e9):
        raise WoodcamError(f"WOODCAM_CACHE_MAX_MB must be a number of MiB > 0; got {text!r}; "
                           "e.g. export WOODCAM_CACHE_MAX_MB=4096")
    return int(value * 2**20)


def _kind_folders(kind: str | None) -> list[Path]:
    """The existing folders of one ``kind`` of entry, or of every kind (:data:`CACHE_KINDS`):
    only these hold woodcam's files. The cache root is the user's to choose
    (``WOODCAM_CACHE_DIR=~/.cache``, a shared scratch folder), and walking all of it, the
    size limit's prune deleted other programs' and the user's files there, oldest first, and
    ``woodcam cache clear`` every file under it."""
    return [d for d in (cache_dir(k) for k in (CACHE_KINDS if kind is None else (kind,))) if d.is_dir()]


def entries(kind: str | None = None) -> list[Path]:
    """Cache entry files, of one ``kind`` or all, oldest use first. Lock files are left out, and
    so is the temporary of an entry another run is writing (:func:`woodcam._atomic.in_flight`):
    a prune or clear deleted it under that run, whose build then failed with "the writer ...
    wrote no file" (a killed writer's temporary is litter, and counted)."""
    files = [p for root in _kind_folders(kind) for p in root.rglob("*")
             if p.is_file() and p.suffix != ".lock" and not in_flight(p)]
    return sorted(files, key=lambda p: max(p.stat().st_atime, p.stat().st_mtime))


def prune(max_bytes: int | None = None, *, keep: Path | None = None) -> int:
    """Delete the least recently used entries until the cache fits ``max_bytes`` (default
    :func:`cache_max_bytes`); ``keep`` is never deleted. Returns the bytes freed."""
    limit = cache_max_bytes() if max_bytes is None else int(max_bytes)
    files = entries()
    total = sum(p.stat().st_size for p in files)
    freed = 0
    for p in files:
        if total - freed <= limit:
            break
        if keep is not None and p == keep:
            continue
        size = p.stat().st_size
        with contextlib.suppress(OSError):
            p.unlink()
            freed += size
    if freed:
        _drop_idle_locks()
    return freed


def _drop_idle_locks(kind: str | None = None) -> None:
    """Delete the ``.lock`` files of one ``kind`` of entry (or of all) whose entry is gone and
    that nobody holds: one was left per entry ever built, and neither clearing nor pruning
    removed them. A lock being built under is held, so it stays (taking the lock without
    waiting tells which)."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - Windows: no lock files
        return
    for lock in (lk for root in _kind_folders(kind) for lk in root.rglob("*.lock")):
        if Path(str(lock)[:-len(".lock")]).exists():
            continue
        with contextlib.suppress(OSError):
            fd = os.open(lock, os.O_RDWR)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # OSError when held: keep it
                lock.unlink()
            finally:
                os.close(fd)


def clear(kind: str | None = None) -> tuple[int, int]:
    """Delete every cache entry (of one ``kind``) and the idle locks left beside them; returns
    (entries, bytes) deleted."""
    n = size = 0
    for p in entries(kind):
        with contextlib.suppress(OSError):
            b = p.stat().st_size
            p.unlink()
            n, size = n + 1, size + b
    _drop_idle_locks(kind)
    return n, size

