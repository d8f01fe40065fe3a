"""Atomic file output: a file is either complete or absent, never half-written.

Every file woodcam writes goes through this module, so Ctrl-C, ``kill -9`` or a full disk in the
middle of a write never leaves a truncated GLB, a 0-byte OBJ or a half cache behind:

* :func:`atomic_write` -- ``with atomic_write(path, "wb") as fh: fh.write(...)``. Writes a unique
  temporary file in the *target folder* (same file system, so the final rename is atomic), fsyncs
  it and ``os.replace``\\ s it onto ``path``. On an exception the temporary file is removed and the
  old ``path`` (if any) is untouched.
* :func:`atomic_path` -- the same for libraries that want a path rather than a file object
  (``np.savez``, ``PIL.Image.save``, ``torch.save``): ``with atomic_path(p) as tmp: np.savez(tmp,
  ...)``. The temporary path keeps ``p``'s suffix, so libraries that pick a format from it (or
  append ``.npz``) behave.
* :func:`atomic_folder` -- the same for a folder written whole (a benchmark set's block):
  ``with atomic_folder(p) as tmp: write_block(block, tmp)``.
* :func:`write_bytes` / :func:`write_text` -- one-liners over :func:`atomic_write`.
* :func:`atomic_files` -- several files that belong together (OBJ + MTL + PNG, GLB + side files):
  all are written to temporaries first and renamed only when every one succeeded; the *first*
  path named (the primary file, e.g. the OBJ that references the others) is renamed *last*, so
  its presence means the whole group is in place. A crash between renames can leave complete
  side files without their primary, never a partial file.
* :func:`all_or_nothing` -- ``with all_or_nothing(): export_glb(...); export_obj(...)``: every
  atomic write inside the block is renamed into place only when the whole block succeeded
  (the first file written, renamed last), so a GLB and its OBJ + MTL + PNG appear as one set.
  :func:`apart` keeps a write out of the set (a cache entry, of use whatever becomes of it).
* :func:`run_outputs` -- a command's files in its output folder as one set, and the earlier
  run's files it does not write again removed (:func:`remove_stale`).
* :func:`check_output_path` -- validate an output path *before* the work starts: known suffix,
  not a directory, parent folder exists, is a folder and is writable. Raises
  :class:`~woodcam.errors.WoodcamError` naming the option, the rule, the value and a fix.

Temporary names are ``.<name>.<pid>-<random>.tmp<suffix>`` (hidden, unique per writer), so two
processes writing the same target never share a temporary file; the last ``os.replace`` wins and
the result is always one writer's complete file. A writer killed mid-write leaves its hidden
temporary behind; the next write of the same target removes it (its process is gone).
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import tempfile
import warnings
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import IO

from . import _interrupt
from .errors import WoodcamError, WoodcamWarning

__all__ = ["all_or_nothing", "apart", "atomic_files", "atomic_folder", "atomic_path", "atomic_write",
           "check_folder_writable", "check_output_path", "in_flight",
           "listed_outputs", "manifest_path", "remove_stale", "run_outputs", "write_bytes", "write_figure",
           "write_text"]


def _umask() -> int:
    # os.umask can only be read by setting it; done once at import (single-threaded then).
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


_FILE_MODE = 0o666 & ~_umask()  # what open() would have given a new file


def _temp_in(path: Path) -> Path:
    """A new, empty, uniquely named temporary file next to ``path`` (same folder), named
    ``.<name>.<pid>-<random>.tmp<suffix>``; temporaries of the same target left by a process
    that no longer runs (killed mid-write) are removed first, so crashes leave no litter.
    A refusal is an OSError naming ``path``, the file asked for, for every writer: it named the
    temporary (``/proc/self/.k.png.13252-6nk58k2c.tmp.png``)."""
    _sweep_orphans(path)
    try:
        fd, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.{os.getpid()}-",
                                    suffix=f".tmp{path.suffix}")
    except OSError as err:
        raise OSError(err.errno, err.strerror, str(path)) from err
    os.close(fd)
    return Path(name)


def _sweep_orphans(path: Path) -> None:
    """Delete ``path``'s temporaries whose writing process is gone (best effort)."""
    prefix, suffix = f".{path.name}.", f".tmp{path.suffix}"
    try:
        names = [n for n in os.listdir(path.parent) if n.startswith(prefix) and n.endswith(suffix)]
    except OSError:
        return
    for name in names:
        pid_text = name[len(prefix):].split("-", 1)[0]
        if not pid_text.isdigit() or _writer_runs(int(pid_text)):
            continue
        orphan = path.parent / name
        if orphan.is_dir() and not orphan.is_symlink():  # an atomic_folder's
            import shutil

            shutil.rmtree(orphan, ignore_errors=True)
        else:
            _discard(orphan)


def _writer_runs(pid: int) -> bool:
    """Whether the process ``pid`` named in a temporary still runs (this one does)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)  # signal 0: does the writer still run?
    except ProcessLookupError:
        return False
    except OSError:  # e.g. another user's live process
        return True
    return True


def in_flight(path) -> bool:
    """Whether ``path`` is the temporary of an atomic write still under way: named
    ``.<name>.<pid>-<random>.tmp<suffix>`` by a process that still runs. It is no file of its
    own yet (it becomes ``<name>`` when renamed), so whoever lists, counts or clears files
    (the cache's prune and clear) leaves it; one whose writer is gone is litter."""
    import re

    m = re.fullmatch(r"\..+\.(\d+)-[a-z0-9_]+\.tmp(\.[^.]*)?", Path(path).name)
    return m is not None and _writer_runs(int(m.group(1)))


def _not_a_folder(path: Path, what: str) -> None:
    """The one refusal of an output path that is an existing folder (:func:`check_output_path`
    before the work; every atomic writer at its start: the writer ran, then the rename failed
    with IsADirectoryError naming the temporary file)."""
    if path.is_dir():
        raise WoodcamError(f"{what}: {str(path)!r} is an existing folder, not a file; "
                           f"give a file name inside it, e.g. '{path / ('part' + path.suffix)}'")


def _fsync_path(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_dir(folder: Path) -> None:
    """Make a rename durable (POSIX); silently skipped where folders cannot be opened."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


#: Renames deferred by an active :func:`all_or_nothing` block, and the list it yields of the
#: targets renamed at its end: ([(tmp, target), ...], [target, ...]).
_PENDING: contextvars.ContextVar[tuple[list, list] | None] = contextvars.ContextVar("woodcam_pending",
                                                                                   default=None)


def _commit(tmp: Path, path: Path, fsync: bool) -> None:
    _interrupt.check()  # after a Ctrl-C (even one a library swallowed) no file lands
    os.chmod(tmp, _FILE_MODE)  # mkstemp makes 0600; give the file ordinary permissions
    if fsync:
        _fsync_path(tmp)
    deferred = _PENDING.get()
    if deferred is not None:  # inside all_or_nothing(): renamed when the whole block succeeds
        _defer(deferred[0], tmp, path)
        return
    os.replace(tmp, path)
    if fsync:
        _fsync_dir(path.parent)


def _defer(pending: list, tmp: Path, path: Path) -> None:
    """Add ``tmp`` (bound for ``path``) to an :func:`all_or_nothing` set. A target written again
    in the same set takes the place of its earlier write (whose temporary goes): both were
    renamed in turn, and the first file written is renamed last, so a primary file written
    twice landed its *first* content."""
    for i, (old_tmp, old_path) in enumerate(pending):
        # the name first: a set of hundreds of files resolves no folder twice over
        if old_path.name == path.name and old_path.parent.resolve() == path.parent.resolve():
            _discard(old_tmp)
            pending[i] = (tmp, path)
            return
    pending.append((tmp, path))


@contextlib.contextmanager
def all_or_nothing() -> Iterator[list[Path]]:
    """Defer every atomic write made inside the block and rename them together at its end.

    Several writers (e.g. ``export_glb`` then ``export_obj``) become one unit: if anything in
    the block raises, every temporary file is removed and no target changes; on success the
    targets are renamed in the order they were written, except the *first* one (the primary
    file, e.g. the GLB), which is renamed last so its presence means the set is complete.
    Yields a list that then holds every target, in the order written. Blocks nest: an inner
    block joins the outer one (and yields the outer's list, filled when that one ends).
    """
    outer = _PENDING.get()
    if outer is not None:
        yield outer[1]
        return
    pending: list = []
    written: list[Path] = []
    token = _PENDING.set((pending, written))
    try:
        yield written
    except BaseException:
        _PENDING.reset(token)
        for tmp, _ in pending:
            _discard(tmp)
        raise
    _PENDING.reset(token)
    order = pending[1:] + pending[:1]
    try:
        _interrupt.check()
        with _interrupt.held():  # a Ctrl-C between two renames left part of a new set by an old one
            for tmp, path in order:
                os.replace(tmp, path)
    except BaseException:
        for tmp, _ in order:
            _discard(tmp)
        raise
    for folder in {path.parent for _, path in order}:
        _fsync_dir(folder)
    written += [path for _, path in pending]


@contextlib.contextmanager
def apart() -> Iterator[None]:
    """Atomic writes inside the block land at once even within :func:`all_or_nothing`: a cache
    entry is of use whether or not the outputs it served are kept, and is read back before
    the set ends."""
    token = _PENDING.set(None)
    try:
        yield
    finally:
        _PENDING.reset(token)


def _discard(tmp: Path) -> None:
    with contextlib.suppress(OSError):
        tmp.unlink()


@contextlib.contextmanager
def atomic_path(path, *, fsync: bool = True, mkdir: bool = False) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; on success it replaces ``path`` atomically.

    Parameters
    ----------
    path : str or Path
        The final file.
    fsync : bool
        Flush the data to disk before the rename (default True; off only for scratch files).
    mkdir : bool
        Create missing parent folders first (default False: a missing folder is an error).

    The temporary file exists (empty) when the block starts; writers may overwrite it. If the
    block raises, or the writer wrote nothing under that name, nothing is renamed. A writer
    that appends its own suffix to the path it is given (``np.savez`` adds ``.npz`` to a path
    not ending in it) wrote nothing under that name: a WoodcamError, and its file is removed
    (the empty temporary landed as a 0-byte ``path`` and the data stayed behind as a hidden
    ``.<name>...tmp.bin.npz``).
    """
    path = Path(path)
    _not_a_folder(path, "atomic_path")
    if mkdir:
        path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _temp_in(path)
    try:
        yield tmp
        if not tmp.exists() or tmp.stat().st_size == 0:  # the folder is listed only then
            appended = _appended_to(tmp)
            if not tmp.exists() or appended:
                elsewhere = f" (it wrote {str(appended[0])!r} instead)" if appended else ""
                raise WoodcamError(f"atomic_path: the writer for {str(path)!r} wrote no file at "
                                   f"{str(tmp)!r}{elsewhere}; write to the yielded path exactly "
                                   "(give a writer that appends its own suffix an open file: "
                                   "atomic_write)")
        _commit(tmp, path, fsync)
    except BaseException:
        _discard(tmp)
        for stray in _appended_to(tmp):  # a writer that appended a suffix, stopped part way
            _discard(stray)
        raise


def _appended_to(tmp: Path) -> list[Path]:
    """Files named ``tmp``'s (unique) name plus more: written by a library that appended its own
    suffix to the path it was given."""
    try:
        return sorted(tmp.parent / n for n in os.listdir(tmp.parent)
                      if n.startswith(tmp.name) and n != tmp.name)
    except OSError:
        return []


@contextlib.contextmanager
def atomic_write(path, mode: str = "wb", *, fsync: bool = True, mkdir: bool = False,
                 encoding: str | None = None, newline: str | None = None) -> Iterator[IO]:
    """Open a temporary file next to ``path`` for writing; replace ``path`` with it on success.

    ``mode`` is ``"w"``/``"wb"`` (``"x"`` modes are not supported: the rename overwrites).
    ``encoding`` defaults to UTF-8 for text. See :func:`atomic_path` for ``fsync`` and ``mkdir``.
    """
    if mode not in ("w", "wb", "wt"):
        raise WoodcamError(f"atomic_write: mode must be 'w' or 'wb'; got {mode!r}")
    if "b" not in mode and encoding is None:
        encoding = "utf-8"
    with (atomic_path(path, fsync=False, mkdir=mkdir) as tmp,
          open(tmp, mode, encoding=encoding, newline=newline) as fh):
        yield fh
        fh.flush()
        if fsync:
            os.fsync(fh.fileno())
    if fsync:
        _fsync_dir(Path(path).parent)


@contextlib.contextmanager
def atomic_folder(path) -> Iterator[Path]:
    """Yield a new, empty temporary folder next to ``path`` (named as :func:`atomic_path`'s
    temporaries); when the block ends without error it replaces ``path`` (a folder already
    there is removed first: a folder cannot be renamed over a full one), else it is removed.
    A writer killed mid-way leaves its hidden folder behind; the next write of the same
    ``path`` removes it (its process is gone), as it does a file's temporary."""
    import shutil

    path = Path(path)
    _sweep_orphans(path)
    tmp = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.{os.getpid()}-",
                                suffix=f".tmp{path.suffix}"))
    try:
        yield tmp
        _interrupt.check()
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        os.replace(tmp, path)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    _fsync_dir(path.parent)


def write_bytes(path, data: bytes, **kwargs) -> Path:
    """Atomically write ``data`` to ``path``; returns ``Path(path)``."""
    with atomic_write(path, "wb", **kwargs) as fh:
        fh.write(data)
    return Path(path)


def write_text(path, text: str, **kwargs) -> Path:
    """Atomically write ``text`` (UTF-8) to ``path``; returns ``Path(path)``."""
    with atomic_write(path, "w", **kwargs) as fh:
        fh.write(text)
    return Path(path)


def manifest_path(folder: str | os.PathLike, kind: str) -> Path:
    """The list of the files the last ``kind`` run wrote in ``folder`` (see :func:`remove_stale`)."""
    return Path(folder) / f".woodcam-{kind}-files.json"


def _read_manifest(path: Path) -> list[str] | None:
    """The file names listed in a manifest, or None when there is none or it cannot be read
    as one (then the caller falls back to the pattern rule). Only plain names inside the
    folder are taken: a list edited to name ``../x`` or ``/etc/x`` deletes nothing there."""
    import json

    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return None
    names = data.get("files") if isinstance(data, dict) else None
    if not isinstance(names, list):
        return None
    return [n for n in names if isinstance(n, str) and n not in ("", ".", "..")
            and "/" not in n and "\\" not in n and n != path.name]


def listed_outputs(folder: str | os.PathLike, kind: str) -> list[str]:
    """The file names the last ``kind`` run listed in ``folder`` (:func:`remove_stale`'s list);
    empty without a readable list."""
    return _read_manifest(manifest_path(folder, kind)) or []


def remove_stale(folder: str | os.PathLike, patterns: Iterable[str],
                 keep: Iterable[str | os.PathLike], *, kind: str,
                 spare: Iterable[str | os.PathLike] = ()) -> list[Path]:
    """Delete the files an earlier ``kind`` run wrote in ``folder`` that this run, which has
    just written ``keep`` there, does not write again (a veneer sheet no longer cut, a surface
    at another year): beside this run's they would pass for its own. Call it after the new
    files are in place.

    Each run lists the files it wrote in ``folder`` in :func:`manifest_path` (written
    atomically, after the removal), and a rerun removes exactly the files of that list it does
    not write again. Files that match one of the glob ``patterns`` but were not listed (a file
    of the user's named like an output) are left, with a WoodcamWarning naming them. A folder
    without a readable list (written before woodcam kept one) falls back to the patterns: every
    matching file not in ``keep`` is removed (no ``patterns``: nothing is). A WoodcamWarning
    names every file removed. ``spare``: the run's inputs (an earlier run's OBJ given as the
    part), never removed by this run; one that was on the list stays on it (still an earlier
    run's output: a later run that neither writes nor reads it removes it). Returns the paths
    removed."""
    import json

    folder = Path(folder)
    if not folder.is_dir():  # nothing written there (a report without a gallery): no list to keep
        return []
    ours = {Path(f).resolve() for f in keep}
    spared = {Path(f).resolve() for f in spare}
    manifest = manifest_path(folder, kind)
    listed = _read_manifest(manifest)
    looks = []   # pattern by pattern, as the patterns are given
    for pattern in patterns:
        looks += [old for old in sorted(folder.glob(pattern))
                  if old.is_file() and old.resolve() not in ours and old not in looks]
    if listed is None:
        earlier, foreign = looks, []
        how = ("(no list of an earlier run's files there: every file named like this run's "
               "outputs was taken for one)")
    else:
        earlier = [folder / n for n in listed if (folder / n).is_file() and (folder / n).resolve() not in ours]
        foreign = [old for old in looks if old.name not in set(listed) and old.resolve() not in spared]
        how = f"(listed in {manifest.name})"
    stale = [old for old in earlier if old.resolve() not in spared]
    carried = [old.name for old in earlier if old.resolve() in spared]
    gone = []
    for old in stale:
        old.unlink(missing_ok=True)
        gone.append(old)
    if gone:
        warnings.warn(f"removed {len(gone)} file(s) of an earlier run in {str(folder)!r} {how} that this run "
                      f"does not write again, so that they do not pass for this run's: "
                      f"{', '.join(p.name for p in gone)}", WoodcamWarning, stacklevel=2)
    if foreign:
        warnings.warn(f"left {len(foreign)} file(s) in {str(folder)!r} named like this run's outputs that "
                      f"no earlier run wrote (not in {manifest.name}); remove them if they are stale: "
                      f"{', '.join(p.name for p in foreign)}", WoodcamWarning, stacklevel=2)
    mine = list(dict.fromkeys([*(Path(f).name for f in keep if Path(f).resolve().parent == folder.resolve()),
                               *carried]))
    write_text(manifest, json.dumps({"written_by": f"woodcam {kind}", "files": mine}, indent=1) + "\n")
    return gone


@contextlib.contextmanager
def run_outputs(folder: str | os.PathLike, *, kind: str) -> Iterator[list[Path]]:
    """Write a command's outputs in ``folder`` as one set (:func:`all_or_nothing`: a run stopped
    part way leaves the earlier run's files whole, never new ones beside old ones), then
    remove the files the earlier ``kind`` run listed there and this one did not write again
    (:func:`remove_stale`, no name patterns: only listed files go). Yields the list of the
    files written, filled when the block ends (the list file is not among them). Not inside
    another set: its files are renamed at that one's end, after the removal."""
    if _PENDING.get() is not None:
        raise WoodcamError("run_outputs: called inside all_or_nothing(); call it outside, around "
                           "the whole set")
    with all_or_nothing() as written:
        yield written
    remove_stale(folder, (), written, kind=kind)


def write_figure(fig, path, **savefig_kwargs) -> Path:
    """Atomically save the matplotlib figure ``fig`` to ``path`` (format from its suffix, PNG by
    default; ``savefig_kwargs`` such as ``dpi`` go to ``fig.savefig``); returns ``Path(path)``."""
    path = Path(path)
    with atomic_path(path) as tmp:  # matplotlib writes in pieces: a half picture never lands
        fig.savefig(tmp, format=path.suffix.lstrip(".") or "png", **savefig_kwargs)
    return path


@contextlib.contextmanager
def atomic_files(paths: Iterable, *, fsync: bool = True, mkdir: bool = False) -> Iterator[list[Path]]:
    """Write several files as one unit: yields one temporary path per target, in order.

    All temporaries are renamed only after the block finished without error; the first target
    (the primary file) is renamed last. On an error every temporary is removed and no target is
    touched. Example::

        with atomic_files([obj, mtl, png]) as (t_obj, t_mtl, t_png):
            t_obj.write_text(text); t_mtl.write_bytes(...); t_png.write_bytes(...)
    """
    targets = [Path(p) for p in paths]
    for p in targets:
        _not_a_folder(p, "atomic_files")
    if len({p.resolve() for p in targets}) != len(targets):
        raise WoodcamError(f"atomic_files: targets must be distinct; got {[str(p) for p in targets]}")
    if mkdir:
        for p in targets:
            p.parent.mkdir(parents=True, exist_ok=True)
    temps: list[Path] = []
    try:
        for p in targets:
            temps.append(_temp_in(p))
        yield list(temps)
        for tmp, p in zip(temps, targets):
            if not tmp.exists():
                raise WoodcamError(f"atomic_files: nothing was written for {str(p)!r}")
        # side files first, the primary last: its presence means the group is complete
        _interrupt.check()
        with _interrupt.held():
            for tmp, p in list(zip(temps, targets))[1:] + [(temps[0], targets[0])]:
                _commit(tmp, p, fsync)
    except BaseException:
        for tmp in temps:
            _discard(tmp)
        raise


def check_output_path(path, *, suffixes: Iterable[str] | None = None, what: str = "--out",
                      mkdir: bool = False) -> Path:
    """Check that ``path`` can be written *before* any work starts; return it as a ``Path``.

    Parameters
    ----------
    path : str or Path
        The output file the caller will write.
    suffixes : iterable of str, optional
        Allowed suffixes, lower case with the dot (``(".glb", ".obj")``); None accepts any.
    what : str
        The option or argument name used in the error (``"--out"``, ``"export_glb: path"``).
    mkdir : bool
        Create a missing parent folder (default False: it must exist).

    Raises
    ------
    WoodcamError
        Unknown suffix, ``path`` is a folder, the parent is missing or is a file, or the parent
        folder (or an existing ``path``) is not writable.
    """
    path = Path(path)
    if suffixes is not None:
        allowed = tuple(s.lower() for s in suffixes)
        if path.suffix.lower() not in allowed:
            raise WoodcamError(f"{what} must end in {' or '.join(allowed)}; got {str(path)!r}; "
                               f"give a file name such as 'part{allowed[0]}'")
    _not_a_folder(path, what)
    parent = path.parent
    if mkdir and not parent.exists():
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise WoodcamError(f"{what}: cannot create the folder {str(parent)!r} ({err.strerror}); "
                               "choose an output folder you can write to") from err
    if not parent.exists():
        raise WoodcamError(f"{what}: the folder {str(parent)!r} of {str(path)!r} does not exist; "
                           "create it first or choose another output path")
    if not parent.is_dir():
        raise WoodcamError(f"{what}: {str(parent)!r} (the parent of {str(path)!r}) is a file, not "
                           "a folder; choose another output path")
    check_folder_writable(parent, what=what, name=path.name)
    return path


def output_folder(folder, what: str, *, make: bool = True) -> Path:
    """``folder`` as an output folder: made with its parents (``make=False``: only checked to
    be a folder or makeable, before the work that fills it). A file at ``folder`` or in its
    way is refused naming ``what``; it was ``Path.mkdir``'s bare FileExistsError or
    NotADirectoryError (after the work, where the folder was made last)."""
    folder = Path(folder)
    base = folder
    while not base.exists() and base != base.parent:
        base = base.parent
    if base.exists() and not base.is_dir():
        raise WoodcamError(f"{what}: cannot make the folder {str(folder)!r}: {str(base)!r} is a file; "
                           "choose an output folder")
    if make:
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise WoodcamError(f"{what}: cannot make the folder {str(folder)!r} ({err.strerror}); "
                               "choose an output folder you can write to") from err
    return folder


def check_folder_writable(folder, *, what: str = "--out", name: str = ".woodcam-write-check") -> Path:
    """Check that files can be made in the existing folder ``folder`` *before* any work; return
    it as a ``Path``. The one home of the "not writable" refusal: a FILE ``--out``'s folder
    (:func:`check_output_path`) and an existing FOLDER ``--out`` are refused in the same words.

    A real probe, a temporary file named after ``name`` (the file the caller will write; its
    temporaries left by a killed writer are swept), made and removed: ``os.access()`` says yes to
    root even on read-only mounts.

    Raises
    ------
    WoodcamError
        ``what``: the folder is not writable (the system's reason); choose another.
    """
    folder = Path(folder)
    try:
        probe = _temp_in(folder / name)
    except OSError as err:
        raise WoodcamError(f"{what}: the folder {str(folder)!r} is not writable ({err.strerror}); "
                           "choose an output folder you can write to") from err
    _discard(probe)
    return folder
