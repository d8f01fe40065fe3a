"""Options and arguments several commands share: one definition each.

- :func:`add_bake_options` / :func:`stock_options` / :func:`write_screenshot`: the bake options
  of ``bake``, ``demo`` and ``gcode`` (texture resolution, species, appearance and its knot
  colours, OBJ, screenshot), for any later command that bakes too.
- :func:`add_block_argument` and :func:`open_block`: a block spec on the command line and the
  one resolver behind every command that reads a block (:func:`woodcam.stock.open_block`).
- :func:`command_group`: a command with sub-commands that several modules extend.
- :func:`check_numbers` / :data:`RANGES`: every numeric option finite and
  in range, checked by :func:`woodcam.cli.main` before a command runs.
- :func:`add_out_option` / :func:`check_out` / :data:`OUT_RULE`: the one ``--out`` rule of
  every command (a file when the path ends in a known file suffix, a folder otherwise),
  checked by :func:`woodcam.cli.main` before a command runs.
- :func:`add_input` / :func:`check_inputs`: every input path of every command (a file, a
  folder, a block spec's folder or file) there and of its kind, checked by
  :func:`woodcam.cli.main` before a command runs (exit 2).
- :func:`add_units_option` / :func:`lengths_to_mm`: ``--units mm|inch``, the lengths of a
  command line read in it (:data:`LENGTH_OPTIONS`); summaries print with :mod:`woodcam.units`.

Nothing heavy is imported at module level (``woodcam --help`` loads this module).
"""

from __future__ import annotations

import argparse
import math
import re
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Literal, NamedTuple, get_args

from .._specs import WOODIFY_FIELD_FILE
from .._types import CAMERAS
from ..errors import UsageError, WoodcamError
from ..limits import REVIEW_VOXELS_RANGE, limit, WOODIFY_RESOLUTION_RANGE, WORKER_MEMORY_MB_RANGE
from ..units import MM_PER_UNIT, Units, fmt_length, fmt_size, parse_lengths

#: The --species presets (woodcam.appearance.SPECIES, listed here so that --help imports no
#: numba; tests/appearance/test_species.py checks the two agree). README: "Species presets".
CITED_SPECIES = ("red-oak", "white-oak", "black-walnut", "black-cherry", "white-ash", "sassafras",
                 "black-willow", "buckeye", "ponderosa-pine", "western-larch", "douglas-fir",
                 "engelmann-spruce")
LEGACY_SPECIES = ("oak", "maple", "walnut", "cherry", "pine", "spruce")
SPECIES_HELP = (f"colour preset: cited (README 'Species presets'): {', '.join(CITED_SPECIES)}; "
                f"legacy, uncited: {', '.join(LEGACY_SPECIES)}")


#: The epochs of each --quality preset (woodcam.appearance.translation.QUALITY_SPECS, spelled
#: out so that --help imports no numpy; tests/test_cli_help.py checks the two agree).
QUALITY_EPOCHS_HELP = "3 draft, 4 normal, 8 high"


def species_type(text: str) -> str:
    """argparse ``type`` of ``--species``: a preset name, else a usage error (exit 2; the
    library's refusal came after parsing, with exit 1)."""
    if text not in CITED_SPECIES + LEGACY_SPECIES:
        raise argparse.ArgumentTypeError(f"{text!r} is not a colour preset; choose one of "
                                         f"{', '.join(CITED_SPECIES + LEGACY_SPECIES)} ('woodcam species' "
                                         "lists their colours)")
    return text

#: The block argument of the commands that read a block (fit, eval, block show); those that
#: carve from it (bake, gcode, place, review) may also turn it: :data:`BLOCK_SPEC_HELP`.
_BLOCK_HELP = ("block spec: builtin:NAME[:WxDxH] ({unit}), log:gran1@K[:WxDxH], woodify:DIR/field.npz "
               "(a block cut from a grown object), a block folder "
               "(block.json) or a Mokume sample folder (a cube, --size-mm, default 50 mm)")
BLOCK_READ_HELP = _BLOCK_HELP.format(unit="mm")
# the carving commands read the WxDxH in --units (LENGTH_OPTIONS): "(mm)" contradicted it
BLOCK_SPEC_HELP = (_BLOCK_HELP.format(unit="in --units, default mm")
                   + "; append ~x90/~y90/~z90 to turn the block under the part")


# -- --out: one rule for every command ---------------------------------------------------------
#: Suffixes that make an ``--out`` path a FILE; any other path names a FOLDER.
FILE_SUFFIXES: frozenset[str] = frozenset({
    ".glb", ".gltf", ".obj", ".stl", ".png", ".jpg", ".jpeg", ".svg", ".dxf", ".html", ".json",
    ".npz", ".pt", ".md", ".csv", ".txt", ".nc", ".zip"})

#: The rule as ``woodcam --help`` and the README state it.
OUT_RULE = ("--out is a FILE when it ends in a file suffix (.glb, .png, .json, .html, .npz, ...) "
            "and a FOLDER otherwise (created when missing). Each command takes one of the two, "
            "says which and what it writes in its --out help, and refuses the other kind "
            "before any work (exit 2).")


def not_empty(convert: Callable = str, what: str = "a path") -> Callable:
    """argparse ``type`` of a path or block-spec argument: ``convert(text)``, an empty (or
    blank) ``text`` refused as a usage error (exit 2). ``Path('')`` is the current folder, so
    'place PART --block B --out ""' wrote into it with exit 0, 'fit ""' read it as a block, and
    'bake PART --block "" ...' failed in the library (exit 1, in the API's words). ``what``
    says what to give."""
    def parse(text: str):
        if not text.strip():
            raise argparse.ArgumentTypeError(f"got an empty value {text!r}; give {what}")
        return convert(text)

    parse.__name__ = getattr(convert, "__name__", "value")  # argparse's 'invalid NAME value'
    return parse


def add_out_option(p: argparse.ArgumentParser, writes: str, *, suffixes: tuple[str, ...] = (),
                   default: Path | None = None) -> None:
    """``--out`` under :data:`OUT_RULE`: a FILE ending in one of ``suffixes``, or (no
    ``suffixes``) a FOLDER. ``writes`` says what the command writes there; ``default`` makes
    the option optional. :func:`check_out` applies the rule before the command runs."""
    assert all(s in FILE_SUFFIXES for s in suffixes), suffixes  # a contributor's mistake
    kind = f"FILE ending in {' or '.join(suffixes)}" if suffixes else "FOLDER (created)"
    p.add_argument("--out", type=not_empty(Path, f"the output {kind.removesuffix(' (created)')}"),
                   required=default is None, default=default,
                   metavar="FILE" if suffixes else "DIR", help=f"output {kind}: {writes}"
                   + (f" (default {default}{'' if suffixes else '/'})" if default else ""))
    p.set_defaults(_out_suffixes=tuple(suffixes))


def _looks_like_a_suffix(suffix: str) -> bool:
    """``suffix`` (lower case, with its dot) reads as a file type a user meant: 1-5 letters or
    digits, at least one a letter (``.npy``, ``.htm``, ``.jpeg``; not ``.2`` of ``run.2``)."""
    tail = suffix[1:]
    return 1 <= len(tail) <= 5 and tail.isascii() and tail.isalnum() and not tail.isdigit()


def check_out(args: argparse.Namespace) -> None:
    """Refuse an ``--out`` that breaks :data:`OUT_RULE` for this command, before any work:
    a UsageError (exit 2) naming the command, what it wants, the value and a fix."""
    from ..errors import UsageError

    suffixes = getattr(args, "_out_suffixes", None)
    out = getattr(args, "out", None)
    if suffixes is None or out is None:
        return
    out = Path(out)
    suffix = out.suffix.lower()
    command = _command_name(args)
    if suffixes:
        if not out.is_dir() and suffix not in FILE_SUFFIXES and _looks_like_a_suffix(suffix):
            # 'fit --out f.npy', 'review --out page.htm': a file name with a slip in its suffix was
            # told it named a folder, and offered 'f.npy/part.npz'
            raise UsageError(f"--out of 'woodcam {command}' must end in {' or '.join(suffixes)}; "
                             f"got {str(out)!r}, whose suffix {out.suffix!r} is none of them; give e.g. "
                             f"{str(out.with_suffix(suffixes[0]))!r} (or "
                             f"{str(out / ('part' + suffixes[0]))!r} to write into a folder {str(out)!r})")
        if out.is_file() and suffix not in FILE_SUFFIXES:
            # 'review --out notes' with a file 'notes' there was told it named a folder and offered
            # 'notes/part.html', a path that cannot be made under a file
            raise UsageError(f"--out of 'woodcam {command}' is a FILE ending in {' or '.join(suffixes)}; got "
                             f"{str(out)!r}, an existing file without that suffix; give e.g. "
                             f"{str(out.with_name(out.name + suffixes[0]))!r}")
        if out.is_dir() or suffix not in FILE_SUFFIXES:
            # a name not there yet, 'bake ... --out tray': the file 'tray.glb' is as likely meant
            # as a folder 'tray' (only the folder was offered)
            also = "" if out.is_dir() else f", or {str(out.parent / (out.name + suffixes[0]))!r}"
            raise UsageError(f"--out of 'woodcam {command}' is a FILE ending in "
                             f"{' or '.join(suffixes)}; got {str(out)!r}, a folder"
                             f"{'' if out.is_dir() else ' name'}; give a file "
                             f"name such as {str(out / ('part' + suffixes[0]))!r}{also}")
        if suffix not in suffixes:
            raise UsageError(f"--out of 'woodcam {command}' must end in {' or '.join(suffixes)}; "
                             f"got {str(out)!r}; give e.g. {str(out.with_suffix(suffixes[0]))!r}")
        if out.parent.is_dir():  # a real write probe: as root os.access() says yes even to /proc
            from .._atomic import check_output_path

            with output_refused_at_the_door():
                check_output_path(out, what=f"--out of 'woodcam {command}'")
        else:  # the missing folder is made when the file is written: under a file it failed after the work
            _check_folder_can_be_made(out.parent, command)
    elif suffix in FILE_SUFFIXES or out.is_file():
        what = "an existing file" if out.is_file() else f"a file name ({suffix})"
        raise UsageError(f"--out of 'woodcam {command}' is a FOLDER (it writes several files); "
                         f"got {str(out)!r}, {what}; give a folder such as "
                         f"{str(out.with_name(out.stem + '_out' if out.is_file() else out.stem))!r}")
    else:
        _check_folder_can_be_made(out, command)


def absent_output_folders(args: argparse.Namespace) -> list[Path]:
    """The topmost folders on the way to this run's outputs that do not exist yet (absolute):
    ``--out`` itself (a FOLDER ``--out``) or its folder (a FILE ``--out``), and a named
    ``--screenshot``'s folder. Taken before the command runs, for
    :func:`remove_empty_folders` to take back when it fails: ``eval appearance --out new/dir``
    made the folder before reading its block, and a failed read left it there, empty."""
    outs = []
    out = getattr(args, "out", None)
    if isinstance(out, (str, Path)) and getattr(args, "_out_suffixes", None) is not None:
        outs.append(Path(out).parent if args._out_suffixes else Path(out))
    shot = getattr(args, "screenshot", None)
    if isinstance(shot, (str, Path)):
        outs.append(Path(shot).parent)
    tops = []
    for folder in outs:
        folder, top = folder.absolute(), None
        while not folder.exists() and folder != folder.parent:
            folder, top = folder.parent, folder
        if top is not None and top not in tops:
            tops.append(top)
    return tops


def remove_empty_folders(tops: list[Path]) -> None:
    """Remove each folder of ``tops`` (:func:`absent_output_folders`: none of them existed when
    the run began) and the folders in it, deepest first, where they are empty: a failed run
    leaves no empty folders it made; a file in them (a run that wrote some before it failed)
    keeps its folder."""
    import os

    for top in tops:
        if not top.is_dir() or top.is_symlink():
            continue
        for folder, _dirs, _files in os.walk(top, topdown=False):  # links to folders not followed
            try:
                os.rmdir(folder)
            except OSError:  # not empty (or gone): kept
                pass


def _command_name(args: argparse.Namespace) -> str:
    """The command as typed, sub-command included (``block show``), for the doors' messages."""
    return " ".join(str(getattr(args, k)) for k in vars(args)
                    if k == "command" or k.endswith("_command")
                    if getattr(args, k) is not None)


# -- input paths: one door for every command ---------------------------------------------------
#: What an input path argument names (:func:`add_input`): an existing FILE, an existing FOLDER,
#: or a block spec (a block or Mokume sample folder, a ``woodify:`` field or ``log:`` JSON file;
#: a built-in block and the shared ``gran1`` log name none).
InputKind = Literal["file", "folder", "block"]
INPUT_KINDS: tuple[str, ...] = get_args(InputKind)


class InputArgument(NamedTuple):
    """One input path argument as :func:`add_input` registers it on its parser (the parser's
    ``_inputs`` default, a tuple of them) and :func:`check_inputs` reads it."""

    dest: str  #: argparse's attribute
    name: str  #: as the messages name it: ``--block``, or the positional's ``PART``
    kind: InputKind
    paths: Callable[[str], list[str]] | None  #: the paths a value names, when more than itself
    suffixes: Callable[[], tuple[str, ...]] | None  #: a FILE's reader's suffixes
    as_is: bool  #: a block spec the command reads as it is: no turn or resize


def add_input(p, *flags: str, kind: InputKind, paths=None, suffixes=None, as_is: bool = False,
              **kwargs) -> argparse.Action:
    """An input path argument of ``p`` (``add_argument``'s ``flags`` and ``kwargs``) that
    :func:`check_inputs` checks before the command runs: ``kind`` is one of
    :data:`INPUT_KINDS`; ``paths`` maps a value to the paths it names when it holds more than a
    path (``--veneer SCAN:DPI:MASK``); ``suffixes`` (a FILE's) returns the suffixes its reader
    takes, the reader's own list (called at the door only: ``--help`` imports no reader);
    ``as_is`` (a block spec's) says the command reads the block as it is, so a turn or resize
    on it is refused (:func:`woodcam._specs.check_read_as_is`).
    ``tests/test_cli_inputs.py`` runs every command against it and fails a path argument added
    without it."""
    assert kind in INPUT_KINDS, kind  # a contributor's mistake
    assert suffixes is None or kind == "file", kind  # a folder or block spec has no suffix rule
    assert not as_is or kind == "block", kind  # only a block spec has turns and resizes
    what = {"file": "a FILE path", "folder": "a FOLDER path",
            "block": "a block spec such as builtin:flat-sawn or a block folder"}[kind]
    kwargs["type"] = not_empty(kwargs.get("type", str), what)  # '' is no path: Path('') is '.'
    action = p.add_argument(*flags, **kwargs)
    name = next((f for f in action.option_strings if f.startswith("--")), action.dest.upper())
    p.set_defaults(_inputs=(*(p.get_default("_inputs") or ()), InputArgument(action.dest, name, kind, paths,
                                                                          suffixes, as_is)))
    return action


def _check_limits(args: argparse.Namespace) -> None:
    from ..limits import check_all

    check_all()


def _check_cache_dir(args: argparse.Namespace) -> None:
    from .._cache import check_cache_root

    check_cache_root()


def _check_cache_max(args: argparse.Namespace) -> None:
    from .._cache import cache_max_bytes

    cache_max_bytes()


def _check_workers(args: argparse.Namespace) -> None:
    if getattr(args, "workers", None) is None:  # --workers sets it for the run (apply_workers)
        from .._parallel import fit_workers

        fit_workers()


#: woodcam's settings in the environment, by the name a command declares them with
#: (:func:`uses_settings`), each read by the function of its one home (its rule and message):
#: the resource limits ``$WOODCAM_MAX_*`` (:func:`woodcam.limits.check_all`), the cache folder
#: ``$WOODCAM_CACHE_DIR`` (:func:`woodcam._cache.check_cache_root`), its size
#: ``$WOODCAM_CACHE_MAX_MB`` (:func:`woodcam._cache.cache_max_bytes`) and a fit's cores
#: ``$WOODCAM_WORKERS`` (:func:`woodcam._parallel.fit_workers`; not read under ``--workers``).
SETTINGS: dict[str, Callable[[argparse.Namespace], None]] = {
    "limits": _check_limits, "cache_dir": _check_cache_dir, "cache_max": _check_cache_max,
    "workers": _check_workers}


def uses_settings(p: argparse.ArgumentParser, *names: str) -> None:
    """Declare the :data:`SETTINGS` command ``p`` reads (none: ``uses_settings(p)``); a command
    that declares none reads them all (it opens blocks, fits, caches). Only these are checked
    before it runs: a malformed setting it never reads refused ``woodcam blocks`` and ``woodcam
    cache clear`` too."""
    unknown = set(names) - set(SETTINGS)
    if unknown:  # a contributor's mistake: say the names there are
        raise TypeError(f"uses_settings: unknown setting(s) {sorted(unknown)}; one of {', '.join(SETTINGS)}")
    p.set_defaults(_settings=names)


def check_environment(args: argparse.Namespace) -> None:
    """Read the woodcam settings of the environment the command uses (:func:`uses_settings`,
    :data:`SETTINGS`) before any work; a malformed one raises its own error (exit 1) naming
    the variable, its rule, its value and a fix. Each was read where it is used:
    'WOODCAM_CACHE_MAX_MB=abc woodcam fit builtin:rift --method radial --out f.npz' fitted,
    stored the field in the cache, then failed and wrote no --out (a second run, the field
    cached, passed without a word)."""
    for name in getattr(args, "_settings", tuple(SETTINGS)):
        SETTINGS[name](args)


def check_inputs(args: argparse.Namespace) -> None:
    """Refuse an input path (:func:`add_input`) that does not exist or is of the wrong kind,
    before any work: a UsageError (exit 2) naming the argument, the path, the rule and a fix.
    A FILE of a suffix its reader does not take (``add_input(suffixes=)``) is refused too, and a
    turn or resize on a block a command reads as it is (``add_input(as_is=True)``).
    A missing part, program or block folder was the command's own error (exit 1), some after the
    block was opened; an input that exists but whose contents are bad still is (exit 1), but a
    ``.glb`` that is no GLB at all (:func:`_check_glb_header`), a file of another kind."""
    glbs: list[tuple[Path, str]] = []
    for arg in getattr(args, "_inputs", ()):
        value = getattr(args, arg.dest, None)
        for item in value if isinstance(value, list) else [] if value is None else [value]:
            for text in arg.paths(str(item)) if arg.paths else [str(item)]:
                _check_input(str(text), arg.name, arg.kind, args, as_is=arg.as_is)
                if arg.suffixes:
                    _check_suffix(Path(text), arg.name, arg.suffixes(), args)
                    glbs.append((Path(text), arg.name))
    # the files' first bytes last: every path there and of its kind first, whichever came first
    for path, name in glbs:
        _check_glb_header(path, name, args)


def _check_suffix(path: Path, name: str, accepted: tuple[str, ...], args: argparse.Namespace) -> None:
    """Refuse an input FILE whose suffix its reader does not take (``accepted``, lower case with
    the dot): the reader refused it (exit 1) only once the command ran, some after the block was
    opened."""
    suffix = path.suffix.lower()
    if suffix in accepted:
        return
    said = f"has suffix {path.suffix!r}" if suffix else "has no suffix"
    cad = " (a part: export it from your CAD program as STEP or STL)" if ".step" in accepted else ""
    raise UsageError(f"{name} of 'woodcam {_command_name(args)}': {str(path)!r} {said}, which it "
                     f"cannot read; it must end in {', '.join(accepted)}; save the file as one of "
                     f"them{cad}")


def _check_glb_header(path: Path, name: str, args: argparse.Namespace) -> None:
    """Refuse a FILE named ``.glb`` that is no glTF 2.0 binary (its first 12 bytes: the magic
    ``glTF`` and version 2, glTF 2.0 spec, "GLB File Format"): a file of another kind under the
    suffix, the suffix check's mistake (exit 2), not a GLB whose contents are bad. It exited 1
    from the GLB reader ("read_glb_metadata: 'x.glb' is 3 bytes, ..."), after the work began."""
    if path.suffix.lower() != ".glb" or not path.is_file():
        return
    try:
        with path.open("rb") as f:
            head = f.read(12)
    except OSError:  # unreadable: the reader says why (permission), exit 1
        return
    if len(head) == 12 and head[:4] == b"glTF" and int.from_bytes(head[4:8], "little") == 2:
        return
    said = ("is empty (0 bytes)" if not head else f"is {len(head)} bytes, too short to be a GLB file"
            if len(head) < 12 else f"is no glTF 2.0 binary (it starts {head[:4]!r}, not b'glTF' version 2)")
    raise UsageError(f"{name} of 'woodcam {_command_name(args)}': {str(path)!r} {said}; give a .glb written by "
                     "woodcam bake or another glTF exporter, or name the file by its own kind (.obj, .stl, ...)")


def part_suffixes() -> tuple[str, ...]:
    """The suffixes a part file may have (:data:`woodcam.cad.parts.SUPPORTED_SUFFIXES`, what
    :func:`woodcam.cad.load_part` reads), for :func:`add_input`'s ``suffixes``."""
    from ..cad.parts import SUPPORTED_SUFFIXES  # here only: --help imports no numpy

    return SUPPORTED_SUFFIXES


#: What a block spec's path may be, said after the kind it names (a FOLDER, a FILE).
_SPEC_KINDS = (" (a block spec is builtin:NAME, log:LOG@KNOT, woodify:DIR/field.npz, a block folder "
               "with block.json or a Mokume sample folder)")


def _check_input(text: str, name: str, kind: str, args: argparse.Namespace, *, as_is: bool = False) -> None:
    """One input path ``text`` of argument ``name`` (:func:`check_inputs`); ``as_is``: a block
    read as it is, no turn or resize on it."""
    spec = ""
    if kind == "block":
        from .._specs import check_read_as_is, split_spec, spec_path

        if as_is:  # 'fit builtin:flat-sawn~z90' exited 1 when the block was opened
            try:
                check_read_as_is(text)
            except WoodcamError as err:
                raise UsageError(f"{name} of 'woodcam {_command_name(args)}' (block spec {text!r}): "
                                 f"{str(err).removeprefix(f'block spec {text!r}: ')}") from None
        path = spec_path(text)
        if path is None:  # a built-in block or the shared log: no path
            _check_builtin(text, name, args)
            return
        spec, kind = text, "file" if split_spec(text)[0].startswith(("woodify:", "log:")) else "folder"
        if kind == "folder" and path.name == "block.json" and path.is_file():
            return  # the block is read from its folder (woodcam.stock)
    else:
        path = Path(text)
    if path.is_dir() if kind == "folder" else path.is_file():
        return
    where = f"{name} of 'woodcam {_command_name(args)}'" + (f" (block spec {spec!r})" if spec else "")
    if path.exists():
        fix = ("give the file itself, not the folder it is in" if kind == "file" else
               f"did you mean its folder {str(path.parent)!r}?")
        if spec.startswith("woodify:") and path.is_dir() and (path / WOODIFY_FIELD_FILE).is_file():
            # woodcam woodify's --out folder: the field file it wrote there, the spec as typed else
            from .._specs import split_spec

            fix = f"did you mean 'woodify:{path / WOODIFY_FIELD_FILE}{spec[len(split_spec(spec)[0]):]}'?"
        raise UsageError(f"{where}: {str(path)!r} is a {'folder' if path.is_dir() else 'file'}; it must "
                         f"be an existing {kind.upper()}{_SPEC_KINDS if spec else ''}; {fix}")
    raise UsageError(f"{where}: {str(path)!r} does not exist; it must be an existing "
                     f"{kind.upper()}{_SPEC_KINDS if spec else ''}; {_did_you_mean(path, spec)}")


def _check_builtin(spec: str, name: str, args: argparse.Namespace) -> None:
    """Refuse a block ``spec`` of argument ``name`` that names no path (``builtin:NAME``,
    ``log:gran1@K``) when it is malformed or its NAME no built-in block has (exit 2; they were
    the block's opening errors, exit 1)."""
    from .._specs import parse_spec

    try:
        parsed = parse_spec(spec)  # in mm: lengths_to_mm has read it in --units already
        if parsed.kind == "builtin":
            from ..fields.builtin import check_builtin_name  # here only: --help imports no numpy

            check_builtin_name(parsed.source)
    except WoodcamError as err:
        raise UsageError(f"{name} of 'woodcam {_command_name(args)}' (block spec {spec!r}): "
                         f"{str(err).removeprefix(f'block spec {spec!r}: ')}"
                         + (" ('woodcam blocks' lists them)" if spec.startswith("builtin:") else "")) from None


def _did_you_mean(path: Path, spec: str) -> str:
    """The fix of a missing input ``path``: a near name in its folder, a built-in block the spec
    may have meant, or where the path stops existing."""
    from .._checks import did_you_mean  # here only: --help imports no numpy

    if spec and not spec.startswith(("woodify:", "log:")):
        from ..fields.builtin import BUILTIN_NAMES

        near = did_you_mean(spec, BUILTIN_NAMES, show=lambda name: f"'builtin:{name}'")
        if near:
            return f"{near} ('woodcam blocks' lists the built-in blocks)"
    base = path.parent
    while not base.is_dir() and base != base.parent:
        base = base.parent
    if base != path.parent:  # its folder is missing too: say which part of the path is wrong
        return f"no folder {str(path.parent)!r} either; check the path"
    try:
        names = [p.name for p in base.iterdir()]
    except OSError:  # an unreadable folder: no suggestion
        names = []
    return did_you_mean(path.name, names, show=lambda name: repr(str(base / name))) or "check the path"


def check_screenshot(args: argparse.Namespace) -> None:
    """Refuse a ``--screenshot`` PNG (bake, gcode, preview) that cannot be written, before any
    work: a UsageError (exit 2) when it does not end in ``.png``, is a folder, or its folder
    cannot be made. The name-less form writes beside ``--out`` (bake, gcode), which
    :func:`check_out` checks, or beside preview's MESH (MESH_view.png), checked here when MESH
    is a file (a missing MESH is the command's own error)."""
    from ..errors import UsageError

    shot = getattr(args, "screenshot", None)
    mesh = getattr(args, "mesh", None)
    derived = shot is True and not hasattr(args, "out") and isinstance(mesh, Path) and mesh.is_file()
    if derived:  # imported here only: woodcam.pipeline pulls in numba and scipy (0.3 s on every command)
        from ..pipeline import screenshot_path

        shot = screenshot_path(True, mesh)
    if not isinstance(shot, (str, Path)):
        return
    shot = Path(shot)
    command = args.command
    if shot.is_dir() or shot.suffix.lower() != ".png":
        what = "an existing folder" if shot.is_dir() else "not a .png name"
        if derived:
            what += " (--screenshot without a name writes MESH_view.png)"
        raise UsageError(f"--screenshot of 'woodcam {command}' is a FILE ending in .png; got "
                         f"{str(shot)!r}, {what}; give e.g. "
                         f"{str(shot / 'view.png' if shot.is_dir() else shot.with_suffix('.png'))!r}")
    if shot.parent.is_dir():
        from .._atomic import check_output_path

        with output_refused_at_the_door():
            check_output_path(shot, what=f"--screenshot of 'woodcam {command}'")
    else:
        _check_folder_can_be_made(shot.parent, command, "--screenshot")


@contextmanager
def output_refused_at_the_door() -> Iterator[None]:
    """An output path the library's checks (:func:`woodcam._atomic.check_output_path`,
    :func:`woodcam.pipeline.check_outputs`) refuse before any work is a usage error (exit 2,
    one line), whatever the reason: a folder that cannot be made and one that exists but cannot
    be written were told apart (exit 2 and exit 1) though the fix is the same, another
    ``--out``. The library raises a plain WoodcamError (a script's path is no command line)."""
    try:
        yield
    except UsageError:
        raise
    except WoodcamError as err:
        raise UsageError(str(err)) from err


def _check_folder_can_be_made(folder: Path, command: str, option: str = "--out") -> None:
    """A folder made later (``--out`` itself, or a FILE ``--out``'s missing parent): its nearest
    existing ancestor must be a folder one may write in, else a UsageError before any work. An
    ``--out`` folder that exists already is made by no one: it must be writable
    (:func:`woodcam._atomic.check_folder_writable`, the words of bake's ``--out`` into a
    read-only folder; it was 'cannot make the folder'). Either refusal exits 2."""
    from ..errors import UsageError

    base = folder.absolute()
    if base.is_dir():
        from .._atomic import check_folder_writable

        with output_refused_at_the_door():
            check_folder_writable(folder, what=f"{option} of 'woodcam {command}'")
        return
    while not base.exists() and base != base.parent:
        base = base.parent
    why = "is a file" if not base.is_dir() else ""
    if not why:  # a real probe: as root os.access() says yes even to /proc (the folder's mkdir
        # then failed after the work: 'review --out /proc/sub/x.html' exit 1, 'block synth' and
        # 'fit' "No such file or directory (/proc/sub)")
        from .._atomic import check_folder_writable
        from ..errors import WoodcamError

        try:
            check_folder_writable(base, what=option)
        except WoodcamError as err:
            reason = getattr(err.__cause__, "strerror", None)
            why = "is not writable" + (f" ({reason})" if reason else "")
    if why:
        raise UsageError(f"{option} of 'woodcam {command}': cannot make the folder {str(folder)!r}: "
                         f"{str(base)!r} {why}; choose an output folder you can write to")


# -- --units: lengths on the command line and in printed summaries ------------------------------
#: ``(command, option dest)`` -> how the value holds lengths: "number" (float), "vector" (a
#: tuple of floats), "sizes" (a "WxH" or "WxDxH" of :func:`sizes_type`: its text read again in
#: every unit, a tuple of mm), "spec" (a block
#: spec's :WxDxH size and its resizes, read by :func:`woodcam._specs.parse_spec`), "place" (``--place``
#: operations: translate:X,Y,Z and fit:MARGIN), "tools" (``--tool`` specs: diameters, corner radii, tips;
#: angles stay degrees). ``--rapid-rate`` reads unit/min. Options whose name carries a unit
#: (``--texels-per-mm``, ``--size-mm``) keep it; files stay mm.
LENGTH_OPTIONS: dict[tuple[str, str], str] = {
    ("bake", "block"): "spec", ("bake", "tolerance"): "number", ("bake", "place"): "place",
    ("place", "block"): "spec", ("place", "margin"): "number",
    ("preview", "block"): "spec", ("preview", "cut_origin"): "vector",
    ("review", "block"): "spec",
    ("gcode", "block"): "spec", ("gcode", "cell_size"): "number",
    ("gcode", "work_offset"): "vector", ("gcode", "start"): "vector",
    ("gcode", "machine_zero"): "vector",
    ("gcode", "stock"): "sizes", ("gcode", "stock_origin"): "vector",
    ("gcode", "rapid_rate"): "number", ("gcode", "mesh_tol"): "number",
    ("gcode", "tool"): "tools",
    ("woodify", "growth"): "number", ("woodify", "block_size"): "sizes",
    ("woodify", "block_centre"): "vector", ("woodify", "crack_region"): "vector",
    ("parquetry", "sheet_size"): "sizes", ("parquetry", "leaf_thickness"): "number",
    ("parquetry", "saw_kerf"): "number", ("parquetry", "tool_diameter"): "number",
    ("parquetry", "veneer_from"): "spec",
}

#: Positions of the lengths among a tool spec's numbers (``vbit:ANGLE:D`` -> D only).
_TOOL_LENGTHS = {"flat": (0,), "ball": (0,), "bull": (0, 1), "vbit": (1,), "snub": (1, 2),
                 "chamfer": (1, 2), "taperball": (0, 1)}


#: Commands whose printed summary (volumes, suggested --place options) follows --units.
_SUMMARY_IN_UNITS = {"bake", "gcode", "place"}
#: Commands that read every mesh file as mm whatever --units says (woodify: the mesh to grow and
#: its obstacles; a user reading "--units inch" took it for the mesh's unit).
_MESHES_IN_MM = {"woodify"}
#: What else a command writes that stays mm, named in its --units help (review's page measures
#: in mm whatever --units says).
_WRITTEN_IN_MM = {"review": " (the page's measurements too)"}


def add_units_option(p: argparse.ArgumentParser, command: str) -> None:
    """``--units mm|inch`` for ``command``; its help names the options :data:`LENGTH_OPTIONS`
    converts for that command, and says the run's warnings and errors speak it
    (:func:`woodcam.units.message_units`, set for every command that has ``--units``): with no
    length typed, ``review``/``preview --units inch`` changed only those, and the help said nothing
    of them."""
    names = [("a block spec's WxDxH" if d == "block" else f"a {_option(d)} spec's WxDxH"
              if LENGTH_OPTIONS[c, d] == "spec" else _option(d))
             for (c, d) in LENGTH_OPTIONS if c == command]
    assert names, command  # a contributor's mistake: list the command's lengths first
    p.add_argument("--units", choices=("mm", "inch"), default="mm",
                   help=f"unit of {', '.join(names)}"
                   + (", of the printed summary" if command in _SUMMARY_IN_UNITS else "")
                   + " and of the lengths in warnings and errors; options whose names carry their "
                   "unit (-mm, -per-mm), defaults"
                   + (", the meshes read" if command in _MESHES_IN_MM else "")
                   + " and the files written" + _WRITTEN_IN_MM.get(command, "") + " stay mm (default mm)")


def _num(v: float) -> str:
    return f"{v:.12g}"


def _fixed(v: float, decimals: int) -> str:
    """``v`` with ``decimals`` decimals, never ``-0.000``."""
    text = f"{v:.{decimals}f}"
    return f"{0:.{decimals}f}" if float(text) == 0 else text


def _scaled_numbers(text: str, sep: str, k: float, where=None, decimals: int | None = None) -> str:
    """``text``'s ``sep``-separated numbers times ``k`` (only positions ``where``), written with
    12 significant digits or, for printing, ``decimals`` decimals; a non-number is left as
    written for the command's own check to name."""
    parts = text.split(sep)
    out = []
    write = _num if decimals is None else (lambda v: _fixed(v, decimals))
    for i, part in enumerate(parts):
        try:
            out.append(write(float(part) * k) if where is None or i in where else part)
        except ValueError:
            out.append(part)
    return sep.join(out)


def _value_to_mm(kind: str, value, k: float):
    if kind == "number":
        return value * k
    if kind == "vector":
        return tuple(v * k for v in value)
    if kind == "place":
        return [place_op_in(op, k) for op in value]
    if kind == "tools":
        out = []
        for item in value:
            head, eq, rest = item.partition("=")
            # N=SPEC; a spec's own reach parts (flat:6:flute=22) are key=value after a ':'
            num, spec = (head + eq, rest) if eq and ":" not in head else ("", item)
            kind_, colon, nums = spec.partition(":")
            if not colon:  # no numbers: left for the tool parser to name
                out.append(item)
                continue
            where = _TOOL_LENGTHS.get(kind_.strip().lower(), ())
            parts, pos = [], 0
            for part in nums.split(":"):
                key, is_kv, val = part.partition("=")
                if is_kv:  # reach (flute=, shank=, stickout=, holder=): all lengths
                    parts.append(key + "=" + _scaled_numbers(val, ":", k))
                else:
                    parts.append(_scaled_numbers(part, ":", k, (0,) if pos in where else ()))
                    pos += 1
            out.append(num + kind_ + ":" + ":".join(parts))
        return out
    raise ValueError(kind)  # pragma: no cover - LENGTH_OPTIONS holds only the kinds above (a
    # "spec" is read once at the door and written back in mm: lengths_to_mm)


def place_op_in(op: str, k: float, decimals: int | None = None) -> str:
    """A ``--place`` operation with its lengths (translate:X,Y,Z, fit:MARGIN) times ``k``, with
    12 significant digits (a typed op read in mm: nothing lost) or, to print one for the user,
    ``decimals`` decimals (:data:`woodcam.units.TYPED_DECIMALS` of the unit)."""
    name, _, arg = op.partition(":")
    if name.lower() == "translate" or (name.lower() == "fit" and arg):
        return f"{name}:{_scaled_numbers(arg, ',', k, decimals=decimals)}"
    return op


def lengths_to_mm(args: argparse.Namespace, parser: argparse.ArgumentParser) -> None:
    """Convert, in place, every length of ``args`` given in ``--units`` to millimetres (what
    everything below the CLI takes); called by :func:`woodcam.cli.main` before the range checks.
    Defaults are millimetres already (the help states them in mm) and are left alone: argparse
    stores a default as the very object of the parser, a typed value as a new one."""
    units = getattr(args, "units", None)
    command = getattr(args, "command", None)
    # in every unit; an option given many times (parquetry --veneer-from) is a list of specs
    specs = {dest: _read_specs(getattr(args, dest), _option(dest), units or "mm")
             for (cmd, dest), kind in LENGTH_OPTIONS.items()
             if kind == "spec" and cmd == command and getattr(args, dest, None) is not None}
    # sizes (WxDxH) read again as typed, in every unit, their rule and example in it: argparse
    # read them before --units was known
    sizes = {dest: parse_sizes(typed.text, _option(dest), len(typed), units=units or "mm")
             for (cmd, dest), kind in LENGTH_OPTIONS.items()
             if kind == "sizes" and cmd == command and isinstance(typed := getattr(args, dest, None), _TypedSizes)}
    if units in (None, "mm"):
        vars(args).update(sizes)
        return
    k = MM_PER_UNIT[units]
    sub = parser.get_default("_commands").choices[command]
    for (cmd, dest), kind in LENGTH_OPTIONS.items():
        value = getattr(args, dest, None)
        if cmd == command and value is not None and value is not sub.get_default(dest):
            # a spec as read at the door, written back in mm: its text is not split again
            setattr(args, dest, _specs_in_mm(specs[dest]) if kind == "spec"
                    else sizes.get(dest, value) if kind == "sizes" else _value_to_mm(kind, value, k))
            # what was typed, for the range errors: "--mesh-tol 0.5" (inch) said "got 12.7"
            args.__dict__.setdefault("_typed", {})[dest] = (value, units)


def _read_specs(value, option: str, units: Units):
    """``value`` (a spec, or a list of them) read by :func:`_read_spec`, as given."""
    if isinstance(value, list):
        return [_read_spec(str(v), units, option) for v in value]
    return _read_spec(str(value), units, option)


def _specs_in_mm(parsed):
    """:func:`_read_specs`' specs written back in mm (:func:`woodcam._specs.format_spec`)."""
    from .._specs import format_spec

    return [format_spec(p) for p in parsed] if isinstance(parsed, list) else format_spec(parsed)


def _read_spec(spec: str, units: Units, option: str = "--block"):
    """A typed block spec read in ``units`` by the stock's own reader
    (:func:`woodcam._specs.parse_spec`): what the stock would refuse is refused here, at the
    door, a usage error in every unit that names ``option`` and the spec as typed (the
    stock's error, after the conversion, named it in mm: '1000x1x1' inches said "got
    '25400x25.4x25.4' ... in mm"; and a door of its own grammar let through what the stock
    refused)."""
    from .._specs import parse_spec
    from ..errors import BlockSpecError

    try:
        return parse_spec(spec, mm_per_unit=MM_PER_UNIT[units])
    except BlockSpecError as err:
        raise UsageError(_spec_usage(spec, units, err, option)) from err


def _spec_usage(spec: str, units: Units, err, option: str = "--block") -> str:
    """The door's words for ``err`` (a BlockSpecError of ``spec``, given as ``option``, read
    in ``units``): its lengths' rules in ``units``, the rest as the stock says it."""
    said = "mm" if units == "mm" else f"--units {units}"
    cap = fmt_length(limit("MAX_BLOCK_SIZE_MM"), units, 5)
    if err.part == "size":
        return (f"{option} {spec}: the size must be WxDxH in {said}, each > 0 and <= {cap} ("
                f"raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N); got "
                f"{err.text!r}, e.g. {fmt_size((300, 120, 40), units, 3)}")
    e = 1 / MM_PER_UNIT[units]
    example = f"'builtin:knotty[{40 * e:.3g}x{30 * e:.3g}x{20 * e:.3g}@{5 * e:.2g},{5 * e:.2g},{5 * e:.2g}]'"
    # a bracket the grammar does not read ([40x30]) is a resize typed wrong, as the stock reads it
    if err.part == "resize" or (err.part == "op" and err.text.startswith("[")):
        return (f"{option} {spec}: a resize must be [WxDxH] or [WxDxH@X,Y,Z] in {said} (X,Y,Z the "
                f"corner in the block before it), each side > 0 and <= {cap}; got {err.text}, e.g. {example}")
    if err.part == "op":
        return (f"{option} {spec}: {err.text!r} is neither a turn ~AXIS then degrees nor a resize "
                f"[WxDxH] or [WxDxH@X,Y,Z] (plain numbers, in {said}), e.g. {example}")
    return f"{option} {spec}: {err.rule}"  # a turn, a log's knot: no lengths


def as_typed(args: argparse.Namespace, dest: str):
    """Option ``dest`` as the user typed it, before :func:`lengths_to_mm` (for messages that
    quote it: ``--block builtin:oak:4x3x2``, not its size in mm)."""
    typed = vars(args).get("_typed", {}).get(dest)
    return getattr(args, dest, None) if typed is None else typed[0]


def parse_tool_option(item: str):
    """One ``--tool [N=]SPEC`` -> ``(N or None, the tool)`` (:func:`woodcam.toolpath.tools.parse_tool_spec`
    reads the spec); a WoodcamError quoting ``item`` for a malformed one. A spec's own reach
    parts (``flat:6:flute=22``) are key=value after a ':', so only an '=' before the first ':'
    gives the tool number."""
    from ..toolpath.tools import parse_tool_spec

    number = None
    spec = item
    if "=" in item.split(":", 1)[0]:
        num, spec = item.split("=", 1)
        try:
            number = int(num)
        except ValueError as err:
            raise WoodcamError(f"--tool {item!r}: the part before '=' must be a tool "
                               "number, e.g. 2=ball:3") from err
        if not 0 <= number <= 99999:  # a tool table's range (load_tool_table): 1000000= was taken
            raise WoodcamError(f"--tool {item!r}: the tool number must be in [0, 99999]; got {number}; "
                               f"e.g. --tool 1={spec}")
    try:
        return number, parse_tool_spec(spec)
    except WoodcamError as err:  # what is wrong with the spec, not with the number
        raise WoodcamError(f"--tool {item!r}: {err}") from err


def _check_places(ops, typed) -> None:
    from ..cad.place import parse_place

    parse_place(ops, as_typed=typed)


def _check_tools(items, typed) -> None:
    numbers: dict[int, str] = {}
    for item, as_typed_item in zip(items, typed):
        # as typed first: its grammar errors quote what was typed (an inch run's spec in mm,
        # "flat:152.4:7", beside a help in inches read as another spec); the spec in mm then
        # for the rules in mm (the largest diameter)
        try:
            parse_tool_option(as_typed_item)
        except WoodcamError as err:
            # a tool's own rule broken by the inch numbers is said of the spec in mm: it said
            # "--tool 'flat:2000': ... in (0, 1000] mm, got 2000.0" of 2000 in (50800 mm)
            if item == as_typed_item or _is_grammar_error(err, as_typed_item):
                raise
        if item != as_typed_item:
            try:
                parse_tool_option(item)
            except WoodcamError as err:
                # the tool's rule in the message units (--units): its lengths as typed (it said
                # "(read as 'flat:50800' in mm): ... (0, 1000] mm, got 50800" of flat:2000 inches)
                said = str(err).removeprefix(f"--tool {item!r}: ")
                raise WoodcamError(f"--tool {as_typed_item!r}: {said}") from err
        number = parse_tool_option(item)[0]
        if number is not None and number in numbers:  # the last one was taken without a word
            raise WoodcamError(f"--tool {as_typed_item!r}: tool {number} is given twice (also "
                               f"--tool {numbers[number]!r}); give each tool number once")
        if number is not None:
            numbers[number] = as_typed_item


def _is_grammar_error(err: WoodcamError, item: str) -> bool:
    """Whether ``err`` of :func:`parse_tool_option` ``(item)`` is about the ``[N=]SPEC`` grammar
    (the same in any units), not a tool's rule on its numbers (a tool class's, in mm)."""
    said = str(err).removeprefix(f"--tool {item!r}: ")
    return said.startswith(("tool spec ", "the part before '='"))


#: Options whose values a library parser reads (the --units lengths in mm, the errors quoting
#: the value as typed): checked at the door by :func:`check_values`.
_PARSED_OPTIONS = {("bake", "place"): _check_places, ("gcode", "tool"): _check_tools}


def check_values(args: argparse.Namespace) -> None:
    """Read every option of :data:`_PARSED_OPTIONS` before any work; a malformed value (``--place
    fit:abc``, ``--tool flat:abc``) is a UsageError (exit 2: a wrong command line, as argparse
    says of a malformed number), with the parser's words. The library's parsers raise a plain
    WoodcamError (a script's wrong value is no command line); the commands parse them again."""
    command = getattr(args, "command", None)
    for (cmd, dest), check in _PARSED_OPTIONS.items():
        value = getattr(args, dest, None)
        if cmd != command or not value:
            continue
        try:
            check(value, as_typed(args, dest))
        except UsageError:
            raise
        except WoodcamError as err:
            raise UsageError(str(err)) from err


def command_group(subparsers, name: str, **kwargs) -> argparse._SubParsersAction:
    """The sub-commands of command ``name``, created on first call (``kwargs`` go to
    ``add_parser``), shared by later calls: ``eval rings`` and ``eval appearance`` live in two
    modules but one ``eval`` group."""
    groups = subparsers.__dict__.setdefault("_woodcam_groups", {})
    if name not in groups:
        p = subparsers.add_parser(name, **kwargs)
        groups[name] = p.add_subparsers(dest=f"{name}_command", metavar="SUBCOMMAND")
        groups[name].required = True
    return groups[name]


def add_block_argument(p: argparse.ArgumentParser, *, option: bool = True, nargs=None) -> None:
    """``--block SPEC`` (required) or, with ``option=False``, a positional ``block``."""
    if option:
        add_input(p, "--block", kind="block", as_is=True, required=True, help=BLOCK_READ_HELP)
    else:  # read, not carved from: no ~x90 turn (it was offered here and refused)
        add_input(p, "block", kind="block", as_is=True, nargs=nargs, help=BLOCK_READ_HELP)


#: The one help of ``--size-mm`` (every command that takes it: :func:`add_size_option`).
SIZE_MM_HELP = ("block size in mm: one number, a cube's side (e.g. 50), or W x D x H, width x depth x "
                "height in the frame of ../shared/docs/conventions.md (e.g. 50x40x30)")


def block_size_mm(text: str) -> tuple[float, float, float]:
    """argparse ``type`` of ``--size-mm`` (:func:`add_size_option`), its one parser: ``"50"`` (a
    cube's side) or ``"50x40x30"`` (W x D x H) -> (W, D, H) in mm, each finite and in (0,
    :data:`~woodcam.limits.MAX_BLOCK_SIZE_MM`]; else a usage error naming the option, its rule
    and the text received. ``--size-mm`` was a cube's side (one number) in fit, eval rings, eval
    appearance, block show, rings detect and rings show and W x D x H in ``block from-photos``:
    ``50x40x30`` copied from one to another was refused, and the two refusals said different
    rules. A Mokume sample, a cube, refuses another size where it is read
    (:func:`woodcam.block.io.read_mokume`)."""
    cap = limit("MAX_BLOCK_SIZE_MM")
    sides = parse_lengths(text, 3, max_mm=cap, cube=True)
    if sides is None:
        raise argparse.ArgumentTypeError(
            f"--size-mm takes a block size in mm, one number (a cube's side, e.g. 50) or W x D x H (e.g. "
            f"50x40x30), each in (0, {cap:g}] (raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N); got {text!r}")
    return (sides[0], sides[1], sides[2])


def say_size_mm(size) -> str:
    """A ``--size-mm`` value (W, D, H) as a user types it: ``50`` for a cube, else ``50x40x30``."""
    sides = [f"{float(v):g}" for v in size]
    return sides[0] if len(set(sides)) == 1 else "x".join(sides)


def add_size_option(p: argparse.ArgumentParser, *, required: bool = False, of_glb: bool = False) -> None:
    """``--size-mm SIZE`` -> ``args.size_mm``, (W, D, H) mm or None: :func:`block_size_mm`.
    ``required``: the size of a block made of photos (``block from-photos``), which carry none;
    else a Mokume sample folder's size, its default the dataset's 50 mm cube (``of_glb``: a
    command reading a baked GLB, the size it records, :func:`stock_of_glb`). A spec that is no
    folder keeps its own size (:func:`folder_size`)."""
    default = ("; required: photos carry no size" if required else
               " (default 50, a 50 mm cube: sizes a Mokume sample folder, whose files carry no size; a block "
               "folder records its own)" if not of_glb else
               " (sizes a Mokume sample folder given with --block, whose files carry no size; default the "
               "size the GLB was baked at, else 50)")
    p.add_argument("--size-mm", type=block_size_mm, required=required, default=None, metavar="SIZE",
                   help=SIZE_MM_HELP + default)


def add_check_layout_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--check-layout", action="store_true",
                   help="check that every face is laid out as ../shared/docs/conventions.md says: rings meet "
                   "across the block's edges; warn of a face that looks turned or mirrored "
                   "('woodcam rings detect' always checks)")


def report_layout(block) -> None:
    """``--check-layout``: a warning per face that looks turned or mirrored
    (:func:`woodcam.detect.layout.check_face_layout`), else one line saying the layout holds."""
    import warnings

    from ..detect.layout import check_face_layout
    from ..errors import WoodcamWarning

    report = check_face_layout(block)
    for w in report.warnings:
        warnings.warn(w, WoodcamWarning, stacklevel=2)
    # a face detection found no rings on is not judged (its edges hold no rings to meet): said, so
    # 'none looks turned' is not read as covering it
    why: dict[str, list[str]] = {}  # faces grouped by reason, in the report's order
    for n, reason in report.unchecked.items():
        why.setdefault(reason, []).append(n)
    groups = "; ".join(f"{', '.join(names)} ({reason})" for reason, names in why.items())
    skipped = f"; not checked: {groups}" if why else ""
    if not report.warnings:
        print(f"layout: {len(report.faces)} faces checked, none looks turned or mirrored{skipped}"
              if report.faces else f"layout: not checked (no two neighbouring faces with a photo or ring map){skipped}")


def folder_size(spec, size_mm: tuple[float, float, float] | None):
    """``size_mm`` (``--size-mm``) for the block ``spec``, the one home of its rule: it sizes a
    Mokume sample folder only; given with a spec that is no folder (``builtin:flat-sawn``,
    ``log:...``) it was dropped without a word and the block kept its own size: a warning says
    so, and None is returned (a block folder's own size is warned of by its reader)."""
    if size_mm is None:
        return None
    from .._specs import spec_path, split_spec

    path = spec_path(str(spec))
    if path is None or not path.exists() or split_spec(str(spec))[0].startswith(("woodify:", "log:")):
        import warnings

        from ..errors import WoodcamWarning

        warnings.warn(f"--size-mm {say_size_mm(size_mm)} sizes Mokume sample folders only; {str(spec)!r} is no folder "
                      "and keeps its own size: ignored (a built-in or log block takes its size in the spec, "
                      "e.g. builtin:flat-sawn:40x40x40)", WoodcamWarning, stacklevel=3)
        return None
    return size_mm


def open_block(spec, size_mm: tuple[float, float, float] | None = None, face_px: int = 256):
    """``(block, field or None)`` for a block argument: :func:`woodcam.stock.open_block`, sized
    by ``size_mm`` (``--size-mm``) as :func:`folder_size` says."""
    from ..stock import open_block as _open_block

    return _open_block(str(spec), size_mm=folder_size(spec, size_mm), face_px=face_px)


#: A value that looks like numbers ("-14,5,3", "-1e3") is a value, not an option; so is a
#: negative tool number ("--tool -1=flat:6" was argparse's "expected one argument", not the
#: tool number's range).
_NEGATIVE_VALUES = re.compile(r"^-(?:[\d.][\d.,eE+-]*|\d+=\S*)$")


def allow_negative_values(p: argparse.ArgumentParser) -> None:
    """Let options of ``p`` take values such as ``-14,5,3`` (argparse takes them for options)."""
    p._negative_number_matcher = _NEGATIVE_VALUES


def parse_sizes(text: str, option: str, n: int = 3, *, cube: bool = False,
                units: Units = "mm") -> tuple[float, ...]:
    """``"WxDxH"`` (``x``, ``×`` or ``,`` between them), typed in ``units`` -> ``n`` sizes in
    mm, each finite and in (0, :data:`~woodcam.limits.MAX_BLOCK_SIZE_MM`]; with ``cube`` one
    number is a cube's side. Otherwise a UsageError (exit 2: the command line is wrong, as
    argparse says of a malformed number; ``--size-mm 2in`` exited 1) naming ``option``
    (``--sheet-size 1e300x10`` reached an allocation and ``--size-mm 1e300`` a block of 0
    px/mm) with the text as typed and its rule in ``units`` (``--sheet-size 0x1 --units inch``
    said "takes WxH in mm ...; got '0x25.4'")."""
    from ..units import parse_lengths

    k = MM_PER_UNIT[units]
    cap = limit("MAX_BLOCK_SIZE_MM")
    vals = parse_lengths(text, n, max_mm=cap / k, cube=cube)
    dims = "x".join("WDH"[:n]) if n == 3 else "x".join("WH"[:n])
    if vals is None:
        unit = "mm" if units == "mm" else f"inches (--units {units})"
        raise UsageError(f"{option} takes {dims} in {unit}, {n} numbers in (0, {cap / k:.6g}] "
                           f"(raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N)"
                           + (" (or one, a cube's side)" if cube else "") + ", e.g. "
                           + "x".join([f"{50 / k:.2g}"] * n) + f"; got {text!r}")
    return tuple(v * k for v in vals)


class _TypedSizes(tuple):
    """A size option's value from argparse (:func:`sizes_type`): the numbers read in mm, or NaN
    where the text broke the rule in mm, and the ``text`` as typed, which :func:`lengths_to_mm`
    reads again in ``--units``."""

    text: str


def sizes_type(option: str, n: int = 3):
    """argparse ``type`` of a size ``WxDxH`` (``n`` numbers) of ``option``: read by
    :func:`parse_sizes` in mm, its text kept (:class:`_TypedSizes`) and read again, in ``--units``
    with its rule and example in them, at the door (:func:`lengths_to_mm`, a kind "sizes" of
    :data:`LENGTH_OPTIONS`); argparse reads before --units is known, so a size refused here
    ('--block-size 0x1x1 --units inch' said 'takes WxDxH in mm') is refused there."""
    def parse(text: str) -> tuple[float, ...]:
        try:
            vals = parse_sizes(text, option, n)
        except WoodcamError:
            vals = (math.nan,) * n  # refused at the door, in the units typed
        sizes = _TypedSizes(vals)
        sizes.text = text
        return sizes
    return parse


def vector_type(option: str, form: str = "X,Y,Z", example: str = "0,0,50", *, nonzero: bool = False):
    """argparse ``type`` for ``option``: a text like ``form`` (``"X,Y,Z"``, ``"X,Y,Z,R"``) -> as
    many finite floats, not all zero with ``nonzero`` (a direction), or a one-line usage error
    naming the option. The one parser of every comma-separated vector a user types; limits on
    the values are :data:`RANGES`' (checked in mm after ``--units``). Negative values parse as
    values with :func:`allow_negative_values`."""
    n = form.count(",") + 1

    def parse(text: str) -> tuple[float, ...]:
        try:
            vals = tuple(float(v) for v in text.split(","))
        except ValueError:
            vals = ()
        if len(vals) != n or not all(math.isfinite(v) for v in vals):
            raise argparse.ArgumentTypeError(f"{option} {text!r}: give {n} finite numbers {form}, "
                                             f"e.g. {example}")
        if nonzero and not any(vals):
            raise argparse.ArgumentTypeError(f"{option} {text!r}: a direction must not be zero; "
                                             f"e.g. {example}")
        return vals
    return parse


def comma_names(text: str, option: str, choices: tuple[str, ...] = (), *,
                all_: bool = False) -> list[str] | None:
    """The names of a comma list option (``--methods``, ``--faces`` ...): each non-empty, each
    once and, with ``choices``, each one of them; with ``all_`` the word ``all`` gives None (every
    name, the command's default). Else a UsageError (exit 2: the command line is wrong) naming
    ``option``: an empty list or a repeated name was taken as the default, or counted twice,
    without a word. The one parser of such lists."""
    if all_ and text == "all":
        return None
    names = [t.strip() for t in str(text).split(",")]
    if not all(names) or len(set(names)) != len(names):
        whole = "'all' or " if all_ else ""
        among = f" from {', '.join(choices)}" if choices else ""
        raise UsageError(f"{option} must be {whole}a comma list{among}, each name once; got {text!r}")
    bad = [n for n in names if choices and n not in choices]
    if bad:  # said as typed, with the names it is not (it was a Python list: "got ['foo']")
        from .._checks import did_you_mean

        fix = did_you_mean(bad[0], choices) or f"e.g. {option} {','.join(choices[:2])}"
        raise UsageError(f"{option} must be from {', '.join(choices)}{', or all' if all_ else ''}; got "
                         f"{text!r}, in which {', '.join(map(repr, bad))} {'is' if len(bad) == 1 else 'are'} "
                         f"none of them; {fix}")
    return names


def face_names(text: str, option: str, *, all_: bool = False) -> list[str] | None:
    """A comma list of faces (``--faces``, ``--partial-faces``, ``--end-grain``): :func:`comma_names`
    whose names are faces (front ... back, or Mokume letters A-F, as
    :func:`woodcam.frames.check_face` reads them), read before any block is opened. A name that is
    no face was the library's "face must be one of ...; got 'bogus'" (exit 1, after the block was
    opened, naming no option); now a usage error naming the option."""
    names = comma_names(text, option, all_=all_)
    if names is None:
        return None
    from ..frames import FACES, check_face

    bad = []
    for name in names:
        try:
            check_face(name)
        except WoodcamError:
            bad.append(name)
    if bad:
        whole = "'all' or " if all_ else ""
        raise UsageError(f"{option} must be {whole}a comma list of faces from "
                         f"{', '.join(FACES)} (or Mokume letters A-F); got {', '.join(map(repr, bad))}; "
                         f"e.g. {option} front,top")
    return names


def add_bake_options(p: argparse.ArgumentParser, *, texels_default: float | None = 10.0,
                     species: bool = True, screenshot: bool = True) -> None:
    """The options of every command that bakes wood onto a mesh (``bake``, ``demo``, ``gcode``).

    texels_default : the ``--texels-per-mm`` default (None: the command picks, e.g. demo's
        ``--quick``). species : add ``--species``. screenshot : add ``--screenshot [PNG]``.
    """
    p.add_argument("--texels-per-mm", type=float, default=texels_default, metavar="T",
                   help="texture resolution on the surface in texels per mm (default "
                   + (f"{texels_default:g} = {1 / texels_default:g} mm texels)" if texels_default
                      else "10, or 4 with --quick)"))
    if species:
        p.add_argument("--species", default=None, type=species_type,
                       help=SPECIES_HELP + " (default: the block's)")
    p.add_argument("--appearance", choices=("colormap", "neural"), default="colormap",
                   help="colormap: fast colour-of-ring model (default); neural: colour volumes "
                   "learnt from the block's photos per axis (seed 000 sec. 3.3, cached on disk)")
    p.add_argument("--quality", choices=("draft", "normal", "high"), default=None,
                   help="training effort of the neural appearance (default normal)")
    p.add_argument("--epochs", type=int, default=None, metavar="N", help="training epochs of the neural appearance "
                   f"(default: --quality's, {QUALITY_EPOCHS_HELP})")
    add_knot_options(p)
    add_max_atlas_option(p)
    p.add_argument("--no-obj", action="store_true", help="write only the GLB, not OBJ+MTL+PNG")
    p.add_argument("--obj-units", choices=("m", "mm"), default="m",
                   help="length unit of the OBJ's coordinates (default m, what Blender and most "
                   "viewers assume; mm for CAM tools and slicers). The GLB is always metres, Y up (glTF)")
    p.add_argument("--obj-up", choices=("y", "z"), default="y",
                   help="up axis of the OBJ (default y, the OBJ habit and what Blender's importer "
                   "expects; z keeps the block frame, as CAM tools and slicers read an OBJ)")
    if screenshot:
        p.add_argument("--screenshot", nargs="?", const=True, default=None, metavar="PNG",
                       type=not_empty(str, "a .png file name, or no value for the default"),
                       help="also render the result off-screen to PNG (default name: OUT with "
                       "_view.png; no display needed)")


def add_max_triangles_option(p: argparse.ArgumentParser, part: str = "the part",
                             mesh: str = "a mesh part (STL, OBJ ...)") -> None:
    """``--max-triangles N`` (None: :func:`woodcam.cad.load_part`'s default budget), of every
    command that loads a part (bake, place, gcode's ``--part``, woodify: ``part`` names it in the
    help, ``mesh`` the mesh inputs it simplifies)."""
    p.add_argument("--max-triangles", type=int, default=None, metavar="N",
                   help=f"triangle budget of {part}: above it a B-rep part (build123d/cadquery, STEP) is "
                   f"re-meshed with looser tolerances, and {mesh} is simplified, its "
                   "surfaces moved by a stated tolerance; a warning says so (default 120000)")


def add_max_atlas_option(p: argparse.ArgumentParser, *, given_only: bool = False) -> None:
    """``--max-atlas PX`` (the library's ``max_atlas_px``): every command that bakes an atlas.
    ``given_only``: its value is None unless typed (a command that bakes an atlas only for some
    inputs warns when it was given for nothing), the library default otherwise."""
    from ..tolerances import DEFAULT_MAX_ATLAS_PX

    p.add_argument("--max-atlas", type=int, default=None if given_only else DEFAULT_MAX_ATLAS_PX, metavar="PX",
                   help=f"largest texture side in texels (default {DEFAULT_MAX_ATLAS_PX}, what every GPU "
                   "takes); a surface needing more gets a lower texel density, and a warning says so")


def add_knot_options(p: argparse.ArgumentParser) -> None:
    """``--knot-darkening`` and ``--knot-outline``: :class:`woodcam.appearance.knots.KnotShading`
    on the command line (``bake``, ``demo``, ``gcode``, ``log render``); defaults are its own."""
    p.add_argument("--knot-darkening", default=None, metavar="ALIVE,DEAD",
                   help="relative darkening of alive knot wood and the extra darkening of dead "
                   "knot wood, each in [0, 1] (default 0.25,0.45; without it, a colour map fitted "
                   "to photos of a knot colours knot wood as the photos do)")
    p.add_argument("--knot-outline", default=None, metavar="R,G,B",
                   help="colour of the bark ring round dead knots, each in [0, 1] "
                   "(default 0.16,0.10,0.06)")
    # "--knot-darkening -0.1,0.3" was argparse's "expected one argument", not the [0, 1] rule
    allow_negative_values(p)


def knot_shading(args):
    """The :class:`~woodcam.appearance.knots.KnotShading` the knot options ask for."""
    from ..appearance.knots import KnotShading

    changes = {}
    if args.knot_darkening is not None:
        changes["alive_darkening"], changes["dead_darkening"] = floats(
            args.knot_darkening, 2, "--knot-darkening", "0.25,0.45")
    if args.knot_outline is not None:
        changes["outline_rgb"] = floats(args.knot_outline, 3, "--knot-outline", "0.16,0.10,0.06")
    return KnotShading(**changes)


def floats(text: str, n: int, option: str, example: str) -> tuple[float, ...]:
    """``"a,b,..."`` -> n floats in [0, 1], or a UsageError (exit 2, a range error like
    :data:`RANGES`') naming the option, with ``example`` as the fix."""
    try:
        vals = tuple(float(v) for v in text.split(","))
    except ValueError:
        vals = ()
    if len(vals) != n or not all(0.0 <= v <= 1.0 for v in vals):
        raise UsageError(f"{option} takes {n} comma-separated numbers in [0, 1]; got {text!r}; "
                         f"e.g. {example}")
    return vals


def appearance_params(args) -> dict:
    """The appearance keywords of :func:`woodcam.stock.open_stock` from the bake options:
    ``knots`` (a KnotShading) for the colour map, ``quality``/``epochs`` for the neural one."""
    knots = args.knot_darkening is not None or args.knot_outline is not None
    if args.appearance != "neural":
        if args.quality or args.epochs:
            given = " ".join(f"--{k} {v}" for k, v in (("quality", args.quality), ("epochs", args.epochs)) if v)
            raise UsageError("--quality and --epochs apply to --appearance neural only; "
                             f"got {given} with --appearance {args.appearance}; add --appearance neural, "
                             "or leave them out")
        if not knots:
            return {}
        # a darkening asked for replaces the knot colour a colour map would fit to the photos
        return {"knots": knot_shading(args), **({"knot_lut": None} if args.knot_darkening is not None else {})}
    if knots:
        given = " and ".join(o for o, v in (("--knot-darkening", args.knot_darkening),
                                            ("--knot-outline", args.knot_outline)) if v is not None)
        raise UsageError("--knot-darkening and --knot-outline apply to --appearance colormap "
                         f"only (the neural appearance learns knot colours from the photos); got {given} "
                         "with --appearance neural; leave them out, or use --appearance colormap")
    return {k: v for k, v in (("quality", args.quality), ("epochs", args.epochs)) if v is not None}


#: ``--camera``'s note where the picture is preview's (bake, preview): which views are cut
#: (woodcam.view.camera.UNCUT_CAMERAS); gcode's stock view says its own
CUT_VIEWS_NOTE = ("; top and bottom show the part's outside uncut, the other views cut away the half "
                  "toward the camera to show the wood inside")


def add_camera_option(p: argparse.ArgumentParser, note: str = "", exclude: tuple[str, ...] = ()) -> None:
    """``--camera`` of the commands that draw a view of one part the user points
    (``bake`` and ``gcode``: their ``--screenshot``; ``preview``); ``demo``'s renders and
    ``place``'s placements picture keep their fixed views and have none. The same named views
    everywhere (:data:`woodcam._types.CAMERAS`) but those in ``exclude``, which ``note`` (how the
    command draws them) must say why it lacks. Read it with :func:`camera_of`."""
    views = {"iso": "iso (from front-right-above, the default)",
             "bottom": "bottom (the part's underside, e.g. a bowl's foot, or where a cut went through)"}

    p.add_argument("--camera", choices=[c for c in CAMERAS if c not in exclude], default=None,
                   help="view direction: " + ", ".join(views.get(c, c) for c in CAMERAS if c not in exclude)
                   + note)


def camera_of(args: argparse.Namespace, shot: bool = True) -> str:
    """``--camera``'s view, ``"iso"`` when not given. ``shot``: whether the command draws a view
    at all (bake/gcode without ``--screenshot`` do not): a ``--camera`` then warns that it is
    ignored."""
    if args.camera is not None and not shot:
        import warnings

        from ..errors import WoodcamWarning

        warnings.warn(f"--camera {args.camera} chooses the view of --screenshot, which was not asked "
                      "for: ignored; add --screenshot", WoodcamWarning, stacklevel=2)
    return args.camera or "iso"


def stock_options(args) -> dict:
    """Every keyword of :func:`woodcam.stock.open_stock` the bake options carry, and
    ``--size-mm`` (:func:`add_size_option`, :func:`folder_size`) where the command has it."""
    size = folder_size(args.block, args.size_mm) if getattr(args, "size_mm", None) is not None else None
    return {"species": getattr(args, "species", None), "appearance": args.appearance,
            **({"size_mm": size} if size is not None else {}), **appearance_params(args)}


def write_screenshot(args, files: dict, stock) -> None:
    """Render ``files["glb"]`` to ``--screenshot``'s PNG (or OUT_view.png) when asked."""
    if not getattr(args, "screenshot", None):
        return
    from ..pipeline import screenshot_path
    from ..view import preview

    png = screenshot_path(args.screenshot, Path(args.out))
    drop_earlier_output(png, Path(args.out))
    preview(files["glb"], wood=stock.wood, size_mm=stock.size_mm, screenshot=png,
            camera=camera_of(args))
    files["png"] = png


def drop_earlier_output(path: Path, out_glb: Path) -> None:
    """Remove the file ``path`` (a NAME_view.png, gcode's NAME_deviation.png) an earlier run
    listed for ``out_glb``, once this run's GLB has landed and before its own is drawn: a
    Ctrl-C while drawing (seconds) left the earlier part's view or cut's map beside the new
    GLB, passing for its own until the next run. A file no run listed (the user's) is left
    alone, as :func:`remove_stale_outputs` leaves it."""
    from .._atomic import listed_outputs

    if path.parent.resolve() == out_glb.parent.resolve() and path.name in listed_outputs(out_glb.parent, out_glb.name):
        path.unlink(missing_ok=True)


def remove_stale_outputs(out_glb, files: dict, inputs=()) -> None:
    """The files an earlier ``bake``, ``gcode`` or ``demo`` run wrote for the GLB ``out_glb``
    that this run, which wrote ``files`` (a PartPreview's: kind -> path), does not write again
    would pass for this run's: a NAME_view.png when ``--screenshot`` is dropped, gcode's
    NAME_deviation.png without ``--part``, bake's NAME_report.* under a gcode GLB, the OBJ set
    under ``--no-obj``. They go with a warning naming each (:func:`woodcam._atomic.remove_stale`),
    and ``files["list"]`` is the list's path.
    Every run writing a GLB lists its files beside it in ``.woodcam-NAME.glb-files.json``, one
    list whatever the command, and only listed files go: never a file woodcam did not write
    there, nor one of ``inputs`` (the part or program of this run; an OBJ with its MTL and
    texture). Where no run kept a list yet, the OBJ set woodcam wrote there goes (its header
    says so, :func:`woodcam.export.written_obj_set`) and nothing else. Call it once this
    run's files are in place."""
    import glob

    from .._atomic import manifest_path, remove_stale
    from ..export import obj_siblings, written_obj_set

    out_glb = Path(out_glb)
    listed = manifest_path(out_glb.parent, out_glb.name)
    spare = [Path(p) for p in inputs if p]
    spare += [s for p in spare if p.suffix.lower() == ".obj" for s in obj_siblings(p)]  # its set
    marked = [] if listed.is_file() else [glob.escape(p.name) for p in written_obj_set(out_glb.with_suffix(".obj"))]
    remove_stale(out_glb.parent, marked, [out_glb, *files.values()], kind=out_glb.name, spare=spare)
    files["list"] = listed  # every file written is named


def _glb_metadata(glb: Path) -> dict:
    """The woodcam metadata of a GLB file; ``{}`` for another file (an OBJ, a missing path)."""
    from ..export import read_glb_metadata

    return read_glb_metadata(glb) if glb.suffix.lower() == ".glb" and glb.is_file() else {}


def recorded_block_size(glb: Path):
    """The block size ``(W, D, H)`` mm a baked GLB's metadata records, or None (another
    program's file, an OBJ). A malformed size is named in a WoodcamError."""
    from ..errors import WoodcamError
    from ..frames import check_size

    meta = _glb_metadata(glb)
    if meta.get("size_mm") is None:
        return None
    try:
        return tuple(float(v) for v in check_size(meta["size_mm"]))
    except WoodcamError as err:
        raise WoodcamError(f"{str(glb)!r}: its metadata's {err}; re-bake it or pass --block SPEC") from err


def _recorded_sample_size(meta: dict, glb: Path) -> tuple[float, float, float] | None:
    """The Mokume sample size ``(W, D, H)`` mm a baked GLB's metadata records
    (``sample_size_mm``, :func:`woodcam.pipeline.bake_part`), or None; a malformed one, or one
    past :data:`~woodcam.limits.MAX_BLOCK_SIZE_MM` (a GLB is untrusted input), is named in a
    WoodcamError."""
    from ..frames import check_size

    size = meta.get("sample_size_mm")
    if size is None:
        return None
    try:
        sides = tuple(float(v) for v in check_size(size))
    except WoodcamError as err:
        raise WoodcamError(f"{str(glb)!r}: its metadata's sample {err}; re-bake it or pass --block SPEC") from err
    cap = limit("MAX_BLOCK_SIZE_MM")
    if max(sides) > cap:
        raise WoodcamError(f"{str(glb)!r}: its metadata's sample_size_mm {list(sides)} is past the largest block "
                           f"side, {cap:g} mm (raise it with WOODCAM_MAX_BLOCK_SIZE_MM=N); re-bake it or pass "
                           "--block SPEC")
    return (sides[0], sides[1], sides[2])


def stock_of_glb(glb: Path, block: str | None = None, species: str | None = None, *,
                 units: Units = "mm", typed: str | None = None,
                 size_mm: tuple[float, float, float] | None = None):
    """The stock a baked GLB was cut from, as its metadata records it (absolute block spec,
    content digest, species, appearance and its parameters, a Mokume sample's size), or
    ``block`` when given, sized by ``size_mm`` (``--size-mm``, :func:`folder_size`) or else, the
    block being the one baked, by the recorded sample size. The messages name ``block`` as the
    user ``typed`` it (before ``--units``) and the recorded size in ``units``.

    Returns None for a file that records no block and no ``block`` given (``preview`` then shows
    the part alone). A recorded block that no longer exists, or whose content changed since the
    bake, is named in an error or a warning."""
    import warnings

    from ..errors import WoodcamError, WoodcamWarning
    from .._specs import spec_path
    from ..stock import open_stock, spec_digest

    meta = _glb_metadata(glb)
    app = meta.get("appearance") if isinstance(meta.get("appearance"), dict) else {}
    kwargs = {"species": species or app.get("species"),
              "appearance": app.get("kind") or "colormap",
              **_trusted_appearance_params(app.get("params"), glb)}
    sample = _recorded_sample_size(meta, glb)
    if block:
        size_mm = folder_size(block, size_mm)
        same = bool(meta.get("block_digest")) and spec_digest(block) == meta["block_digest"]
        if size_mm is None and same:  # the block baked: at the size baked (a Mokume sample's)
            size_mm = sample
        if meta.get("block_digest") and (not same or (size_mm is not None and sample is not None
                                                       and tuple(size_mm) != sample)):
            # --block of another block (another size, an edited folder) was taken without a word:
            # the section cap then shows other wood than the part's surface
            size = meta.get("size_mm")
            size = (", " + fmt_size(size, units)) if isinstance(size, list) and all(
                isinstance(v, (int, float)) for v in size) else ""
            warnings.warn(f"--block {typed or block} is not the block {glb.name} was baked from "
                          f"({meta.get('block')}{size}): the wood shown inside "
                          "differs from the part's surface", WoodcamWarning, stacklevel=2)
        # the recorded species (the bake's, default oak) was not asked for now: no note that
        # it changes nothing
        return _recorded_species_stated(open_stock(block, **{**kwargs, "species": species or kwargs["species"]},
                                                   species_given=species is not None,
                                                   **({"size_mm": size_mm} if size_mm is not None else {})),
                                        app, species)
    spec = meta.get("block")
    if not spec:
        return None
    if not isinstance(spec, str) or len(spec) > 4096:
        raise WoodcamError(f"the block spec in {str(glb)!r}'s metadata must be a string; got a "
                           f"{type(spec).__name__}; pass --block SPEC")
    path = spec_path(spec)
    if path is not None and not path.exists():
        raise WoodcamError(
            f"{str(glb)!r} was baked from the block {str(path)!r}, which is not there any more; "
            "pass --block SPEC (the same block, moved) to rebuild its wood")
    if meta.get("block_digest") and spec_digest(spec) != meta["block_digest"]:
        warnings.warn(f"the block {spec!r} changed since {glb.name} was baked (its files differ); "
                      "the wood shown is today's", WoodcamWarning, stacklevel=2)
    if size_mm is not None:  # the recorded block is its size: --size-mm would show other wood
        warnings.warn(f"--size-mm {say_size_mm(size_mm)} sizes the block given with --block; {glb.name} is shown "
                      "in the block it records, at the size it was baked: ignored (add --block SPEC to choose another)",
                      WoodcamWarning, stacklevel=2)
    # a Mokume sample at the size it was baked: a resized sample opened at 50 mm showed other wood
    return _recorded_species_stated(open_stock(spec, **kwargs, species_given=species is not None,
                                               **({"size_mm": sample} if sample is not None else {})),
                                    app, species)


def _recorded_species_stated(stock, app: dict, species: str | None):
    """``stock`` reopened with the species a GLB recorded: where the bake recorded it as only the
    default preset (``species_stated`` false, a block nobody gave a species) and none is asked
    for now, still not a claim about the wood (:func:`woodcam.stock.species_text`)."""
    if species is None and app.get("species_stated") is False and "species" in stock.meta:
        stock.meta["species_stated"] = False
    return stock


#: Appearance parameters a GLB's metadata may carry, with their rules. A GLB is untrusted input:
#: it may choose the appearance it was baked with, never unbounded work (issue 15). It never
#: chooses where anything is written: block folders are only read, caches live in the user
#: cache folder (woodcam._cache).
_GLB_APPEARANCE_PARAMS = {
    "quality": ("draft", "normal", "high"),
    "epochs": (1, 2000, False),
    "resolution": (8, 256, False),
    "knot_darkening_alive": (0.0, 1.0, False),
    "knot_darkening_dead": (0.0, 1.0, False),
}


def _trusted_appearance_params(params, glb) -> dict:
    """The appearance parameters of a GLB's metadata, checked (WoodcamError naming the GLB)."""
    if params is None:
        return {}
    if not isinstance(params, dict):
        raise WoodcamError(f"{str(glb)!r}: metadata appearance.params must be an object; got "
                           f"{type(params).__name__}; re-bake it, or pass --block SPEC (and the bake "
                           "options) yourself")
    out = {}
    for key, value in params.items():
        rule = _GLB_APPEARANCE_PARAMS.get(key)
        if key == "dead_outline_rgb":
            ok = (isinstance(value, list) and len(value) == 3
                  and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                          and 0.0 <= v <= 1.0 for v in value))
        elif rule is None:
            ok = False
        elif isinstance(rule[0], str):
            ok = value in rule
        else:
            ok = (isinstance(value, (int, float)) and not isinstance(value, bool)
                  and math.isfinite(value) and rule[0] <= value <= rule[1])
        if not ok:
            raise WoodcamError(f"{str(glb)!r}: metadata appearance.params.{key} = {value!r} is not "
                               "an accepted appearance parameter or is out of range; pass "
                               "--block SPEC (and the bake options) yourself")
        out[key] = value
    return out


# -- numeric options: finite and in range, checked once for every command ---------------------
# woodcam.cli.main calls check_numbers() on the parsed arguments: argparse's float accepts nan
# and inf, and a value out of range must fail with one line, not a hang, an out-of-memory kill
# or a silent substitution (``--tolerance 0`` used to become 0.05 without a word).

#: option dest -> (low, high, low_is_open[, high_is_open]). ``(command, dest)`` keys override a
#: plain ``dest`` for commands where the same option name means another quantity.
#: A RANGES bound that is the limit of that name (woodcam.limits), read when the option is
#: checked (:func:`option_bounds`), so ``$WOODCAM_MAX_BLOCK_SIZE_MM`` raises the options that size a block.
BLOCK_SIZE_CAP = "MAX_BLOCK_SIZE_MM"

RANGES: dict = {
    "texels_per_mm": (0.0, 100.0, True),       # 100 texels/mm = 0.01 mm texels, far below a cutter
    "tolerance": (0.0, 10.0, True),            # tessellation chord, mm
    "size_mm": (0.0, BLOCK_SIZE_CAP, True),          # a block side, mm (woodcam.limits.MAX_BLOCK_SIZE_MM)
    "mesh_tol": (0.0, 10.0, True),             # mm
    "resolution": (8, 256, False),             # colour-volume cells along the longest side
    ("woodify", "resolution"): (*WOODIFY_RESOLUTION_RANGE, False),  # grid nodes: the library's range
    ("gcode", "cell_size"): (0.005, 10.0, False),  # stock grid cell, mm (5 um .. 10 mm)
    "epochs": (1, 100_000, False),
    "finetune_epochs": (0, 100_000, False),
    "steps": (1, 100_000_000, False),
    # block synth: blocks in the set, written on this machine or an engine's: 8.5 MB and ~4 CPU-s
    # a block at the default 512 px (measured), so 1e5 are ~850 GB and ~5 CPU-days; the 1e6 it
    # took were 8.5 TB and weeks (a typo's extra zero filled the disk first)
    "count": (1, 100_000, False),
    # eval realistic: blocks per row, each fitted by every method in every scenario and face set
    # on this machine alone (no engine; ~33 CPU-s a block for three fitters): 1000 a row of the
    # default two face sets are ~18 CPU-hours; 'bench run' is the one for thousands of blocks
    ("eval", "count"): (1, 1000, False),
    "face_px": (16, 16_384, False),            # woodcam.limits.MAX_FACE_PX; 8 px made faces of
                                               # non-square pixels that the fit refused
    "seed": (0, 2**32 - 1, False),
    "ring_width": (0.0, 1000.0, True),         # mm per year
    "px_per_mm": (0.0, 1000.0, True),
    "supersample": (1, 16, False),
    "k_stem": (0.0, 1000.0, True),
    "k_knot": (0.0, 1000.0, True),
    "alive_darkening": (0.0, 1.0, False),
    "dead_darkening": (0.0, 1.0, False),
    "outline_mm": (0.0, 1000.0, False),
    "timeout": (0.0, 1e7, True),               # seconds
    "max_triangles": (100, 100_000_000, False),  # a part's budget (B-rep or mesh); 1e8 triangles is ~10 GB
    "max_atlas": (64, 65_536, False),          # texture side, texels
    "candidates": (1, 1_000_000, False),       # placement candidates: woodcam.advise.advise_placement's
    # bound (1e7 passed here, loaded the part, then failed with exit 1 naming 'candidates')
    "margin": (0.0, 1000.0, False),            # mm
    "top": (1, 100_000, False),
    "voxels": (*REVIEW_VOXELS_RANGE, False),  # per review colour volume; the library's own range
    "workers": (1, 1024, False),
    "memory_limit_mb": (*WORKER_MEMORY_MB_RANGE, False),  # per engine worker; the library's own range
    "connect_timeout_s": (0.0, 3600.0, True),
    # gcode: a rapid rate of 1e-320 mm/min made the machining time infinite (a traceback), a
    # start point 1e300 mm away the same; 100 m is beyond any machine's travel
    ("gcode", "rapid_rate"): (0.1, 1e6, False),  # mm/min
    ("gcode", "until_line"): (1, 100_000_000, False),  # a source line number (-3 exited 1, not 2)
    ("gcode", "start"): (-1e5, 1e5, False),      # mm, work coordinates
    ("gcode", "work_offset"): (-1e5, 1e5, False),
    ("gcode", "machine_zero"): (-1e5, 1e5, False),  # mm, G-code frame
    # woodify: --growth 1e20 divided by zero deep in the rasteriser; --crack-years 0 became 1
    ("woodify", "growth"): (0.0, BLOCK_SIZE_CAP, True),       # mm (woodcam.limits.MAX_BLOCK_SIZE_MM)
    ("woodify", "years"): (0.0, 10_000.0, True),        # the oldest trees are ~5000 years old
    ("woodify", "time_scale"): (0.0, 1e6, True),        # years
    ("woodify", "shape"): (0.0, 100.0, True),           # Weibull shape c
    ("woodify", "crack_years"): (1, 1000, False),
    ("woodify", "crack_threshold"): (0.0, 1e12, True),  # separation eigenvalue (> 0)
    "max_px_per_mm": (0.0, 1000.0, True),  # block from-photos: -5 wrote a block at -5 px/mm
    "zoom": (1, 64, False),                # rings show: picture pixels per face pixel
    "sheets": (1, 1000, False),            # parquetry leaves per block (1e6 ran on, memory growing)
    "gallery": (0, 1000, False),           # bench report: -1 went into Python slicing
    # bench run / eval realistic: exit 1 naming the Python parameters (face_px, blocks, retries),
    # after run.json was written; bench's face_px has the library's floor (bench_settings)
    ("bench", "face_px"): (32, 16_384, False),
    ("bench", "blocks"): (1, 10_000_000, False),
    "retries": (0, 100, False),
    "eq79": (0, 1000, False),
    "thumbnails": (0, 1000, False),
    # the options' own names in the errors (they named the Python parameters: trace_dropout,
    # thickness_mm, relief ...)
    **{(cmd, d): r for cmd in ("block", "bench") for d, r in (
        ("dropout", (0.0, 1.0, False)), ("mislabel", (0.0, 1.0, False)), ("knotted_fraction", (0.0, 1.0, False)),
        ("jitter_mm", (0.0, 10.0, False)), ("dropout_chunk_mm", (0.0, 10_000.0, True)))},
    ("parquetry", "px_per_mm"): (0.0, 50.0, True),     # woodcam.parquetry.ParquetryParams.check
    ("parquetry", "leaf_thickness"): (0.0, 100.0, True),
    ("parquetry", "saw_kerf"): (0.0, 100.0, False),
    ("parquetry", "patch_mm"): (0.0, 10_000.0, True),
    ("parquetry", "min_piece_mm"): (0.0, 1000.0, False),
    ("parquetry", "tool_diameter"): (0.0, 100.0, True),  # a bit of no width cuts nothing
    ("parquetry", "kerf_mm"): (0.0, 100.0, False),
    # Table 1's parameters and the search's: ParquetryParams.check's bounds (exit 1 there, naming
    # w_intens, n_rot ...); the bounds it sets relative to other options (image size >= patch,
    # overlap <= (patch - min piece) / 2, 2^n_adaptive patches <= the panel's shorter side) stay
    # its own. The tops ParquetryParams leaves open are far beyond use: a cost ratio or weight of
    # 1e6; n_adaptive's 32 only bounds what argparse takes (the panel's rule says at most 16)
    **{("parquetry", d): (0.0, 1.0, False) for d in ("w_intens", "w_edge", "w_hist")},
    ("parquetry", "image_size_mm"): (0.0, BLOCK_SIZE_CAP, True),  # woodcam.limits.MAX_BLOCK_SIZE_MM
    ("parquetry", "n_adaptive"): (0, 32, False),
    ("parquetry", "w_adaptive"): (0.0, 1e6, True),
    ("parquetry", "n_rot"): (1, 360, False),
    ("parquetry", "coarse_factor"): (1, 1024, False),
    ("parquetry", "w_struct"): (0.0, 1e6, False),
    ("parquetry", "flat_detail"): (1.0, 1e6, False),
    ("parquetry", "flat_rerank"): (1, 1_000_000, False),  # its floor, rerank: ParquetryParams.check
    ("parquetry", "overlap_mm"): (0.0, 10_000.0, False),
    ("woodify", "relief"): (0.0, 1.0, False),
    ("woodify", "eccentricity"): (-1.0, 1.0, True, True),  # speed (1 + delta n.up) stays > 0
    # sizes and places typed as vectors (vector_type, sizes_type): limits in mm, after --units
    ("woodify", "block_size"): (0.0, BLOCK_SIZE_CAP, True),     # woodcam.limits.MAX_BLOCK_SIZE_MM
    ("gcode", "stock"): (0.0, BLOCK_SIZE_CAP, True),   # a block's size
    ("woodify", "block_centre"): (-1e5, 1e5, False),      # 100 m: 1e300 is a typo, not a place
    ("woodify", "crack_region"): (-1e5, 1e5, False),
}


def _option(dest: str) -> str:
    return "--" + dest.replace("_", "-")


def _bound(v) -> str:
    """A range's end as short as :g writes it where that is the number (1e+06), else whole: --seed's
    2**32 - 1 was '4.29497e+09', a number one cannot type as the largest seed."""
    return f"{v:g}" if float(f"{v:g}") == v else (f"{v:d}" if isinstance(v, int) else repr(v))


def _span(rng, mm: bool = False, per: str = "") -> str:
    """A RANGES entry as the errors and the help say it: ``[1, 1e+06]``, ``(0, 100]``; with ``mm``
    in mm, ``per`` after it (``"/min"``: a rate, ``[0.1, 1e+06] mm/min``)."""
    lo, hi, lo_open, hi_open = (*rng, False)[:4]
    return (f"{'(' if lo_open else '['}{_bound(lo)}, {_bound(hi)}{')' if hi_open else ']'}"
            f"{' mm' + per if mm else ''}")


#: Options read in --units per minute (a rate, not a length): their range and the value typed
#: say "mm/min" and "inch/min" (--rapid-rate 0.001 under --units inch was refused as
#: "must be in [0.1, 1e+06] mm; got 0.001 inch = 0.0254 mm").
PER_MINUTE_OPTIONS = {("gcode", "rapid_rate")}


def option_range(dest: str, command: str | None = None) -> str:
    """The range of option ``dest`` (of ``command``, where it has its own) for its help, from
    :data:`RANGES`, the one table the values are checked against: ``"in [1, 1e+06]"``."""
    return "in " + _span(option_bounds(dest, command))


def option_bounds(dest: str, command: str | None = None) -> tuple | None:
    """The RANGES entry of option ``dest`` (``command``'s own first), a bound that names a limit
    (:data:`BLOCK_SIZE_CAP`) read now through :func:`woodcam.limits.limit`; None without one."""
    rng = RANGES.get((command, dest), RANGES.get(dest))
    return None if rng is None else tuple(limit(b) if isinstance(b, str) else b for b in rng)


def _check_value(value, option: str, rng, typed=None, command: str = "COMMAND", cap: str = "",
                 per: str = "", length: bool = False) -> None:
    """Refuse ``value`` of ``option`` outside ``rng`` (a :data:`RANGES` entry). ``typed``:
    ``(value as typed, its unit)`` of a length read in --units (then ``value`` is mm); ``per``:
    ``"/min"`` for a rate; ``length``: a length option (:data:`LENGTH_OPTIONS`), whose range and
    value say mm under --units mm too (they said '[0.005, 10]; got 20.0' of --cell-size)."""
    # a UsageError (exit 2): a number out of range is a wrong command line, as the exit statuses
    # in 'woodcam --help' say (it exited 1, as a failed work)
    from ..errors import UsageError

    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return
    help_ = f"see 'woodcam {command} --help' for its meaning and default"
    lo, hi, lo_open, hi_open = (*rng, False)[:4] if rng is not None else (None, None, False, False)
    span = "" if rng is None else _span(rng, typed is not None or length, per)
    if isinstance(value, float) and not math.isfinite(value):  # the range and the help too (it said neither)
        got = (f"{value!r}{' mm' + per if length else ''}" if typed is None
               else f"{typed[0]!r} {typed[1]}{per}")
        raise UsageError(f"{option} must be a finite number{' in ' + span if span else ''}; got {got}; {help_}")
    if rng is None:
        return
    if value < lo or value > hi or (lo_open and value <= lo) or (hi_open and value >= hi):
        got = (f"{value!r}{' mm' + per if length else ''}" if typed is None
               else f"{typed[0]!r} {typed[1]}{per} = {value:g} mm{per}")
        raise UsageError(f"{option} must be in {span}; got {got}; {help_}"
                         + (f"; raise it with WOODCAM_{cap}=N" if cap and value > hi else ""))


def check_numbers(args: argparse.Namespace) -> None:
    """Raise a WoodcamError for the first numeric option that is non-finite or out of range."""
    command = getattr(args, "command", None)
    # the whole command for the pointer to its help ("block synth", not "COMMAND")
    name = " ".join(str(c) for c in (command, getattr(args, f"{command}_command", None)) if c)
    for dest, value in vars(args).items():
        if dest.startswith("_") or value is None:
            continue
        rng = option_bounds(dest, command)
        raw = RANGES.get((command, dest), RANGES.get(dest))
        cap = raw[1] if raw is not None and isinstance(raw[1], str) else ""  # a limit's name
        values = value if isinstance(value, (list, tuple)) else [value]
        typed = vars(args).get("_typed", {}).get(dest)
        for i, v in enumerate(values):
            if typed is not None and isinstance(typed[0], (list, tuple)):  # a vector: its typed element
                item = (typed[0][i], typed[1]) if isinstance(typed[0][i], (int, float)) else None
            else:
                item = typed
            _check_value(v, _option(dest), rng, item, name or "COMMAND", cap,
                         "/min" if (command, dest) in PER_MINUTE_OPTIONS else "",
                         LENGTH_OPTIONS.get((command, dest)) in ("number", "vector", "sizes"))


def add_workers_option(p: argparse.ArgumentParser, note: str = "") -> None:
    """``--workers N`` of the commands that run a fit (``fit``, ``bake``): the processes it may
    use (:mod:`woodcam._parallel`); applied by :func:`apply_workers`; ``note`` says which fits."""
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help=f"workers (processes) one fit may use{note} (default: $WOODCAM_WORKERS, else "
                   "min(2, CPU cores)); the fitted field is the same for any N, 1 is slowest")


def apply_workers(args: argparse.Namespace) -> None:
    """Make ``--workers`` (range-checked with every option, :data:`RANGES`) this process' fit
    setting, ``$WOODCAM_WORKERS``."""
    if getattr(args, "workers", None) is not None:
        import os

        from .._parallel import WORKERS_ENV

        os.environ[WORKERS_ENV] = str(args.workers)


def add_confidence_option(p: argparse.ArgumentParser, note: str = "", where: str = "the cut-plane PNGs",
                          tables: str = "table.md summarises") -> None:
    """``--confidence`` of ``eval rings`` / ``eval realistic``: the evidence fit's per-point
    confidence drawn on the cut planes (``where``, ``tables``: and on real blocks' held-out
    faces); ``note`` adds what else it implies."""
    p.add_argument("--confidence", action="store_true",
                   help=f"draw the evidence fit's per-point confidence under its ring lines in {where} "
                   f"(red unsure, green sure{note}); {tables} it either way (default off)")


def add_engine_options(p: argparse.ArgumentParser) -> None:
    """``--engine``, ``--address``, ``--workers``: where many independent tasks run
    (:func:`woodcam.scale.run_many`)."""
    p.add_argument("--engine", choices=("local", "dask"), default=None,
                   help="run one task per item: local = worker processes on this machine, no "
                   "services; dask = a Dask cluster (--address) or, without one, a 2-worker "
                   "cluster on 127.0.0.1. Records are kept per item, so a killed run resumes "
                   "(default: local)")
    p.add_argument("--address", default=None, metavar="tcp://HOST:PORT",
                   help="a running Dask scheduler (with --engine dask; default: none, start a "
                   "local cluster)")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="worker processes, each with one thread (default 2; 1 = serial in this "
                   "process; not with --address)")
    p.add_argument("--memory-limit-mb", type=int, default=None, metavar="MB",
                   help="memory per worker in MiB (default 3072)")
    p.add_argument("--connect-timeout-s", type=float, default=None, metavar="S",
                   help="seconds to wait for the scheduler at --address (default 10)")


_ENGINE_DESTS = ("engine", "address", "workers", "memory_limit_mb", "connect_timeout_s")


def engine_requested(args) -> bool:
    """Whether any of :func:`add_engine_options`' options was given: then the work runs on an
    engine (``--workers 4`` alone ran serially in this process, as if it had not been given)."""
    return bool(engine_given(args))


def engine_given(args) -> list[str]:
    """The engine options given (``['--engine', '--workers']``), as typed on the command line."""
    return [f"--{d.replace('_', '-')}" for d in _ENGINE_DESTS if getattr(args, d, None) is not None]


def engine_options(args) -> dict:
    """The keyword arguments of :func:`woodcam.scale.run_many` from :func:`add_engine_options`."""
    if args.address is not None and args.engine not in (None, "dask"):
        raise UsageError(f"--address needs --engine dask; got --engine {args.engine}; use --engine dask, or "
                         "leave --address out")
    # both were run_many's errors (exit 1, naming the Python parameters) after bench run had
    # written its run.json
    if args.address is not None:
        from ..scale import check_address

        try:
            check_address(args.address, "--address")
        except WoodcamError as err:
            raise UsageError(str(err)) from err
        if args.workers is not None:
            raise UsageError(f"--workers cannot be given with --address: the cluster at {args.address} has its "
                             f"own workers; got --workers {args.workers}; leave --workers out")
    out = {"engine": "dask" if args.address is not None else (args.engine or "local"),
           "address": args.address, "workers": args.workers}
    if args.memory_limit_mb is not None:
        out["memory_limit_mb"] = args.memory_limit_mb
    if args.connect_timeout_s is not None:
        out["connect_timeout_s"] = args.connect_timeout_s
    return out
