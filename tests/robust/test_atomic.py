"""Atomic output: complete or absent, never partial; output paths checked before work."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from woodcam._atomic import (
    all_or_nothing,
    atomic_files,
    atomic_folder,
    atomic_path,
    atomic_write,
    check_output_path,
    manifest_path,
    remove_stale,
    write_bytes,
    write_text,
)
from woodcam.errors import WoodcamError


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if ".tmp" in p.name)


def test_atomic_write_replaces_and_leaves_no_temp(tmp_path):
    target = tmp_path / "a.txt"
    target.write_text("old")
    write_text(target, "new")
    assert target.read_text() == "new"
    assert _leftovers(tmp_path) == []
    # ordinary permissions, not mkstemp's 0600
    assert target.stat().st_mode & 0o044 == 0o044 & ~_current_umask()


def _current_umask() -> int:
    m = os.umask(0o022)
    os.umask(m)
    return m


def test_atomic_write_error_keeps_old_file(tmp_path):
    target = tmp_path / "a.bin"
    write_bytes(target, b"old")
    with pytest.raises(RuntimeError, match="boom"), atomic_write(target, "wb") as fh:
        fh.write(b"half")
        raise RuntimeError("boom")
    assert target.read_bytes() == b"old"
    assert _leftovers(tmp_path) == []


def test_atomic_path_keeps_suffix_for_numpy(tmp_path):
    target = tmp_path / "c.npz"
    with atomic_path(target) as tmp:
        assert tmp.suffix == ".npz" and tmp.parent == tmp_path
        np.savez(tmp, a=np.arange(3))
    assert np.load(target)["a"].tolist() == [0, 1, 2]
    assert _leftovers(tmp_path) == []


def test_atomic_path_refuses_a_writer_that_appends_its_own_suffix(tmp_path):
    # np.savez adds .npz to a path not ending in it: the empty temporary landed as a 0-byte
    # target and the data stayed behind as a hidden .a.bin...tmp.bin.npz
    target = tmp_path / "a.bin"
    target.write_bytes(b"old")
    with pytest.raises(WoodcamError, match=r"wrote no file at .*\.npz' instead"), atomic_path(target) as tmp:
        np.savez(tmp, a=np.arange(3))
    assert target.read_bytes() == b"old"
    assert _leftovers(tmp_path) == []


def test_a_file_written_twice_in_one_set_keeps_its_last_content(tmp_path):
    # the writes were renamed in turn, the first one (the primary) last: a primary file written
    # again later in the set landed its first content
    first, other = tmp_path / "a.json", tmp_path / "b.txt"
    with all_or_nothing() as written:
        write_text(first, "first")
        write_text(other, "b")
        write_text(tmp_path / "." / "a.json", "second")
    assert first.read_text() == "second" and other.read_text() == "b"
    assert written == [first, other]
    assert _leftovers(tmp_path) == []


def test_atomic_folder_is_whole_or_absent_and_a_killed_writers_folder_goes(tmp_path):
    target = tmp_path / "block_0000"
    target.mkdir()
    (target / "old.txt").write_text("old")
    with pytest.raises(RuntimeError, match="boom"), atomic_folder(target) as tmp:
        (tmp / "half.png").write_bytes(b"half")
        raise RuntimeError("boom")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block_0000"]  # no temporary folder
    assert [p.name for p in target.iterdir()] == ["old.txt"]
    # a writer killed mid-way left its hidden folder: the next write of the target removes it
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True).stdout.strip()
    orphan = tmp_path / f".block_0000.{dead}-x1y2z3.tmp"
    orphan.mkdir()
    (orphan / "half.png").write_bytes(b"half")
    with atomic_folder(target) as tmp:
        (tmp / "new.txt").write_text("new")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block_0000"]
    assert [p.name for p in target.iterdir()] == ["new.txt"]


def test_a_ctrl_c_while_a_set_is_renamed_lands_after_the_whole_set(tmp_path, monkeypatch):
    # the renames ran one by one: a Ctrl-C after the first raised there, the rest of the set
    # was discarded, and the new side file stood beside the earlier run's primary
    from woodcam import _interrupt

    files = [tmp_path / "p.glb", tmp_path / "p.obj", tmp_path / "p.png"]
    for f in files:
        f.write_text("old")
    real_replace = os.replace
    # the Ctrl-C lands on another thread of the process, as the kernel may deliver it to any
    # thread not blocking it (numba, OpenMP, progress bars): a SIGINT masked on the main thread
    # alone still ran Python's handler mid-set (seen: old, new, new)
    idle = threading.Event()
    other = threading.Thread(target=idle.wait, daemon=True)
    other.start()

    def replace_then_ctrl_c(src, dst):
        real_replace(src, dst)
        signal.pthread_kill(other.ident, signal.SIGINT)
        time.sleep(0.01)  # that thread's C handler has run: Python's runs on the main thread next

    try:
        with _interrupt.handling(), pytest.raises(KeyboardInterrupt):
            with all_or_nothing():
                for f in files:
                    write_text(f, "new")
                monkeypatch.setattr(os, "replace", replace_then_ctrl_c)
    finally:
        monkeypatch.undo()
        idle.set()
    assert [f.read_text() for f in files] == ["new", "new", "new"]
    assert _leftovers(tmp_path) == []


def test_atomic_files_all_or_nothing(tmp_path):
    obj, mtl, png = tmp_path / "p.obj", tmp_path / "p.mtl", tmp_path / "p.png"
    with (pytest.raises(OSError, match="disk full"),
          atomic_files([obj, mtl, png]) as (t_obj, t_mtl, _t_png)):
        t_obj.write_text("obj")
        t_mtl.write_text("mtl")
        raise OSError("disk full")  # the PNG write fails
    assert list(tmp_path.iterdir()) == []
    with atomic_files([obj, mtl, png]) as (t_obj, t_mtl, t_png):
        t_obj.write_text("obj")
        t_mtl.write_text("mtl")
        t_png.write_bytes(b"png")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.mtl", "p.obj", "p.png"]


def test_every_writer_flushes_the_data_before_the_rename_and_the_folder_after(tmp_path, monkeypatch):
    """A rename is atomic, but without fsync of the data first a power cut can leave the new
    name on an empty file (delayed allocation), and without fsync of the folder after it the
    old one: each file lands as data-fsync, rename, folder-fsync."""
    events = []
    real_fsync, real_replace = os.fsync, os.replace

    def fsync(fd):
        events.append(("fsync", os.readlink(f"/proc/self/fd/{fd}")))
        real_fsync(fd)

    def replace(src, dst):
        events.append(("replace", str(src), str(dst)))
        real_replace(src, dst)

    monkeypatch.setattr(os, "fsync", fsync)
    monkeypatch.setattr(os, "replace", replace)
    write_bytes(tmp_path / "a.bin", b"a")
    with atomic_path(tmp_path / "b.npy") as tmp:
        np.save(tmp, np.arange(3))
    with atomic_files([tmp_path / "c.obj", tmp_path / "c.mtl"]) as temps:
        for t in temps:
            t.write_text("c")
    renames = [e for e in events if e[0] == "replace"]
    assert sorted(Path(e[2]).name for e in renames) == ["a.bin", "b.npy", "c.mtl", "c.obj"]
    for _, src, dst in renames:
        at = events.index(("replace", src, dst))
        assert ("fsync", src) in events[:at], f"{Path(dst).name}: data not flushed before the rename"
        assert ("fsync", str(tmp_path)) in events[at + 1:], f"{Path(dst).name}: folder not flushed"


def test_no_file_lands_after_a_recorded_ctrl_c(tmp_path, monkeypatch):
    """A Ctrl-C a library swallowed is recorded (woodcam._interrupt); every atomic write checks
    it before its file lands, so nothing is written after it, and no temporary is left."""
    from woodcam import _interrupt
    from woodcam._atomic import all_or_nothing

    target = tmp_path / "a.txt"
    write_text(target, "old")
    monkeypatch.setattr(_interrupt, "_requested", True)
    with pytest.raises(KeyboardInterrupt):
        write_text(target, "new")
    with pytest.raises(KeyboardInterrupt), atomic_path(tmp_path / "b.png") as tmp:
        tmp.write_bytes(b"b")
    with pytest.raises(KeyboardInterrupt), atomic_files([tmp_path / "c.obj", tmp_path / "c.mtl"]) as temps:
        for t in temps:
            t.write_text("c")
    assert target.read_text() == "old" and sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]
    # inside a set the files land at its end: a Ctrl-C recorded after the writes stops them there
    monkeypatch.setattr(_interrupt, "_requested", False)
    with pytest.raises(KeyboardInterrupt), all_or_nothing():
        write_text(target, "new")
        write_bytes(tmp_path / "d.bin", b"d")
        monkeypatch.setattr(_interrupt, "_requested", True)
    assert target.read_text() == "old" and sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]


def test_atomic_files_rejects_duplicate_targets(tmp_path):
    with pytest.raises(WoodcamError, match="distinct"), atomic_files([tmp_path / "a", tmp_path / "a"]):
        pass


def test_unique_temp_names_for_concurrent_writers(tmp_path):
    target = tmp_path / "x.bin"
    with atomic_path(target) as t1, atomic_path(target) as t2:
        assert t1 != t2
        t1.write_bytes(b"1" * 10)
        t2.write_bytes(b"2" * 10)
    assert target.read_bytes() in (b"1" * 10, b"2" * 10)


@pytest.mark.parametrize("case, match", [
    ("suffix", "must end in .glb or .obj"),
    ("dir", "is an existing folder"),
    ("noparent", "does not exist"),
    ("parentfile", "is a file, not a folder"),
])
def test_check_output_path(tmp_path, case, match):
    (tmp_path / "d.glb").mkdir()
    (tmp_path / "f").write_text("")
    path = {"suffix": tmp_path / "a.stl", "dir": tmp_path / "d.glb",
            "noparent": tmp_path / "missing" / "a.glb", "parentfile": tmp_path / "f" / "a.glb"}[case]
    with pytest.raises(WoodcamError, match=match):
        check_output_path(path, suffixes=(".glb", ".obj"))
    assert check_output_path(tmp_path / "ok.GLB", suffixes=(".glb",)) == tmp_path / "ok.GLB"


def test_check_output_path_unwritable():
    ro = Path("/proc/self")  # read-only even for root
    with pytest.raises(WoodcamError, match="not writable"):
        check_output_path(ro / "a.glb", suffixes=(".glb",))


def test_sigkill_mid_write_leaves_old_file_or_nothing(tmp_path):
    """A writer killed half-way through leaves the previous complete file, never a partial."""
    target = tmp_path / "big.bin"
    script = textwrap.dedent(f"""
        import sys, time
        from woodcam._atomic import atomic_write
        with atomic_write({str(target)!r}, "wb") as fh:
            fh.write(b"x" * 1000)
            fh.flush()
            print("ready", flush=True)
            time.sleep(60)
            fh.write(b"y")
    """)
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[2]))
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, env=env)
    assert proc.stdout.readline().strip() == b"ready"
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    proc.stdout.close()
    assert not target.exists()  # the target never appears partial
    assert len(_leftovers(tmp_path)) == 1  # the killed writer's hidden temporary
    write_bytes(target, b"done")  # the next run just works, and sweeps the orphan
    assert target.read_bytes() == b"done" and _leftovers(tmp_path) == []


def test_all_or_nothing_defers_every_write(tmp_path):
    from woodcam._atomic import all_or_nothing

    glb, obj, mtl = tmp_path / "p.glb", tmp_path / "p.obj", tmp_path / "p.mtl"
    write_bytes(glb, b"old glb")
    with pytest.raises(OSError, match="png write failed"), all_or_nothing():
        write_bytes(glb, b"new glb")
        assert glb.read_bytes() == b"old glb"  # nothing renamed yet
        with atomic_files([obj, mtl]) as (t_obj, t_mtl):
            t_obj.write_text("obj")
            t_mtl.write_text("mtl")
        raise OSError("png write failed")
    assert glb.read_bytes() == b"old glb" and not obj.exists() and not mtl.exists()
    assert _leftovers(tmp_path) == []
    order = []
    real_replace = os.replace

    def spy(src, dst):
        order.append(Path(dst).name)
        real_replace(src, dst)

    import woodcam._atomic as mod
    mod.os.replace = spy
    try:
        with all_or_nothing():
            write_bytes(glb, b"new glb")
            with atomic_files([obj, mtl]) as (t_obj, t_mtl):
                t_obj.write_text("obj")
                t_mtl.write_text("mtl")
    finally:
        mod.os.replace = real_replace
    assert order == ["p.mtl", "p.obj", "p.glb"]  # the first written (primary) renamed last
    assert glb.read_bytes() == b"new glb" and obj.read_text() == "obj"


def test_failed_obj_export_leaves_no_new_glb(tmp_path, monkeypatch):
    """Issue 15: a failed OBJ/PNG write left the GLB behind (plus a traceback)."""
    import trimesh

    from woodcam import export
    from woodcam.pipeline import preview_mesh
    from woodcam.stock import open_stock

    def broken(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(export, "export_obj", broken)
    mesh = trimesh.creation.box(extents=(10, 10, 10))
    mesh.apply_translation((20, 20, 20))
    with pytest.raises(OSError, match="No space left"):
        preview_mesh(mesh, open_stock("builtin:flat-sawn"), tmp_path / "part.glb",
                     texels_per_mm=1, screenshot=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_temporaries_of_killed_writers_are_swept(tmp_path):
    target = tmp_path / "big.bin"
    proc = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)
    dead = int(proc.stdout)  # a pid that has exited
    orphan = tmp_path / f".big.bin.{dead}-abc123.tmp.bin"
    orphan.write_bytes(b"half")
    live = tmp_path / f".big.bin.{os.getppid()}-xyz.tmp.bin"  # a running process: kept
    live.write_bytes(b"busy")
    write_bytes(target, b"whole")
    assert not orphan.exists() and live.exists() and target.read_bytes() == b"whole"


def test_every_writer_gives_new_files_the_usual_permissions(tmp_path):
    """Outputs are for other programs and people too (a CNC machine's account, a web server):
    the parquetry files and a synth spec were written through ``tempfile.mkstemp``, mode 0600."""
    from woodcam.parquetry._io import atomic_write_png
    from woodcam.parquetry.job import ParquetryJob, write_job
    from woodcam.synth.spec import SynthSpec

    expected = 0o666 & ~_current_umask()
    made = [write_text(tmp_path / "a.txt", "a"), write_job(ParquetryJob(), tmp_path / "sub" / "b.json"),
            atomic_write_png(tmp_path / "c.png", np.zeros((2, 2, 3))), SynthSpec().save(tmp_path / "d.json")]
    assert {p.name: oct(p.stat().st_mode & 0o777) for p in made} == {p.name: oct(expected) for p in made}


def _current_umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def test_a_figure_that_fails_half_way_leaves_the_old_picture(tmp_path):
    from woodcam._atomic import write_figure

    class HalfFigure:  # matplotlib writes a PNG in pieces; this one dies after the first
        def savefig(self, fname, format=None, **kwargs):
            Path(fname).write_bytes(b"\x89PNG half")
            raise KeyboardInterrupt

    class Figure:
        def savefig(self, fname, format=None, **kwargs):
            Path(fname).write_bytes(f"{format} {kwargs['dpi']}".encode())

    target = tmp_path / "plot.png"
    target.write_bytes(b"old")
    with pytest.raises(KeyboardInterrupt):
        write_figure(HalfFigure(), target, dpi=100)
    assert target.read_bytes() == b"old" and _leftovers(tmp_path) == []
    assert write_figure(Figure(), tmp_path / "plot.svg", dpi=72).read_bytes() == b"svg 72"


def test_a_refused_write_names_the_file_asked_for_not_its_temporary(tmp_path):
    """Sweep h5 item 8: the error named '/proc/.k.png.13252-6nk58k2c.tmp.png'; only atomic_path
    was fixed, atomic_files (export_obj, export_glb) still named its temporary."""
    with pytest.raises(OSError) as err, atomic_path("/proc/self/k.png"):
        pass
    assert err.value.filename == "/proc/self/k.png"
    with pytest.raises(OSError) as err, atomic_write("/proc/self/k.txt", "w"):
        pass
    assert err.value.filename == "/proc/self/k.txt"
    # the side file's folder refuses: named as asked, and the primary's temporary is gone
    with pytest.raises(OSError) as err, atomic_files([tmp_path / "a.obj", "/proc/self/a.mtl"]):
        pass
    assert err.value.filename == "/proc/self/a.mtl"
    assert _leftovers(tmp_path) == []


def test_remove_stale_removes_the_listed_files_only(tmp_path):
    """Earlier outputs were removed by file pattern: the manifest of the earlier run decides
    (a file it did not write is left, with a warning; a list naming ../x deletes nothing
    outside); a folder without a readable list falls back to the patterns, with the warning."""
    from woodcam.errors import WoodcamWarning

    out = tmp_path / "out"
    out.mkdir()
    (tmp_path / "outside.txt").write_text("keep")
    for n in ("a_1.txt", "a_2.txt", "a_mine.txt"):
        (out / n).write_text(n)
    man = manifest_path(out, "t")
    man.write_text('{"files": ["a_1.txt", "a_2.txt", "../outside.txt", "/etc/hostname"]}')
    with pytest.warns(WoodcamWarning) as rec:
        gone = remove_stale(out, ["a_*.txt"], [out / "a_1.txt"], kind="t")
    assert [p.name for p in gone] == ["a_2.txt"]
    assert sorted(p.name for p in out.iterdir()) == [man.name, "a_1.txt", "a_mine.txt"]
    assert (tmp_path / "outside.txt").exists()
    said = [str(w.message) for w in rec]
    assert any("removed 1 file(s)" in m and m.endswith(": a_2.txt") for m in said)
    assert any(m.startswith("left 1 file(s)") and m.endswith(": a_mine.txt") for m in said)
    assert json.loads(man.read_text())["files"] == ["a_1.txt"]
    man.write_text("not json")          # unreadable: the pattern rule, as before manifests
    with pytest.warns(WoodcamWarning, match=r"no list of an earlier run.*: a_mine\.txt$"):
        remove_stale(out, ["a_*.txt"], [out / "a_1.txt"], kind="t")
    assert sorted(p.name for p in out.iterdir()) == [man.name, "a_1.txt"]


def test_remove_stale_in_a_folder_never_made_writes_no_list(tmp_path):
    """A report without a gallery (``--gallery 0 --thumbnails 0``) never makes its gallery
    folder; writing the run's list there failed with 'No such file or directory'."""
    from woodcam._atomic import remove_stale

    assert remove_stale(tmp_path / "gallery", ["b*_*.png"], [], kind="benchmark-gallery") == []
    assert not (tmp_path / "gallery").exists()


def test_all_or_nothing_names_what_it_wrote_and_a_cache_entry_stays_apart(tmp_path):
    """The set's files are known at its end (run_outputs lists them for the next run), and a
    cache entry written inside the set (a fit a command caches while writing its outputs) lands
    at once: deferred, a second lookup in the same run missed it, and a Ctrl-C dropped it."""
    from woodcam._atomic import apart, all_or_nothing, write_bytes

    with all_or_nothing() as written:
        write_bytes(tmp_path / "a.png", b"a")
        with apart():
            write_bytes(tmp_path / "entry.npz", b"cached")
        assert (tmp_path / "entry.npz").read_bytes() == b"cached"
        assert not (tmp_path / "a.png").exists() and written == []
        write_bytes(tmp_path / "table.md", b"t")
    assert written == [tmp_path / "a.png", tmp_path / "table.md"]


def test_every_atomic_writer_refuses_a_folder_before_writing(tmp_path):
    """A path that is a folder: the writer ran (the whole GLB or log made), then the rename
    failed with IsADirectoryError naming the temporary file. Now a WoodcamError naming the
    folder before anything is written; the folder and its contents stay as they were."""
    from woodcam import generate_log, write_log
    from woodcam._atomic import atomic_files, atomic_path, atomic_write, write_bytes, write_text

    folder = tmp_path / "out.json"
    folder.mkdir()
    (folder / "keep.txt").write_text("mine")
    ran = []

    def body(make):
        with make() as handle:
            ran.append(handle)

    for who, call in (("atomic_path", lambda: write_text(folder, "x")),
                      ("atomic_path", lambda: write_bytes(folder, b"x")),
                      ("atomic_path", lambda: body(lambda: atomic_write(folder, "w"))),
                      ("atomic_path", lambda: body(lambda: atomic_path(folder))),
                      ("atomic_files", lambda: body(lambda: atomic_files([tmp_path / "a.txt", folder])))):
        with pytest.raises(WoodcamError, match=rf"{who}: '{folder}' is an existing folder, not a file; give a "
                                               rf"file name inside it, e.g. '{folder}/part.json'"):
            call()
    assert ran == [] and sorted(p.name for p in tmp_path.iterdir()) == ["out.json"]
    assert [p.name for p in folder.iterdir()] == ["keep.txt"]
    with pytest.raises(WoodcamError, match="is an existing folder, not a file"):  # a public writer
        write_log(generate_log(1, length_mm=200).to_skeleton(), folder)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.json"]
