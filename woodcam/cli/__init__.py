"""The ``woodcam`` command: parses, calls the API, prints. Errors become one line and exit 1
(usage errors 2, failed checks 3; see :data:`EXIT_ERROR` and the others).

A package with one module per command group. Each module in :data:`COMMANDS` defines
``register(subparsers)``, which adds its sub-parser(s) and sets ``func`` on each to the function
that runs the parsed arguments and returns the exit status. To add a command: write one module
here and add one line to :data:`COMMANDS`. Command modules import nothing heavy at module level
(numpy, scipy, numba, torch load inside the ``run`` functions), so ``woodcam --help`` stays fast;
``tests/test_cli_package.py`` checks both rules.

Shared pieces live in :mod:`woodcam.cli.options`: the bake options (``bake``, ``demo``,
``gcode``), the block argument and its resolver, and :func:`~woodcam.cli.options.command_group`
for commands with sub-commands that several modules extend (``eval rings``, ``eval appearance``).
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
import textwrap
import warnings

from .. import _interrupt
from ..errors import UsageError, WoodcamError, caused_by
from .options import OUT_RULE

#: The command modules, in the order their commands appear in ``woodcam --help``.
COMMANDS: tuple[str, ...] = (
    "woodcam.cli.bake",          # demo, bake, preview, blocks
    "woodcam.cli.gcode",         # gcode
    "woodcam.cli.review",        # review
    "woodcam.cli.place",         # place
    "woodcam.cli.cache",         # cache info | clear
    "woodcam.cli.block",         # block synth | show | from-photos
    "woodcam.cli.rings",         # rings detect | show
    "woodcam.cli.log",           # log render | maps | export
    "woodcam.cli.fit",           # fit, eval rings
    "woodcam.cli.eval_bench",    # eval realistic
    "woodcam.cli.appearance",    # eval appearance
    "woodcam.cli.train",         # train gtf | rings
    "woodcam.cli.bench",         # bench run | report
    "woodcam.cli.woodify",       # woodify
    "woodcam.cli.parquetry",     # parquetry
)

#: Old spellings kept working: argv prefix -> its current form.
ALIASES: dict[tuple[str, ...], tuple[str, ...]] = {
    ("eval-appearance",): ("eval", "appearance"),
}
#: Command groups whose old form took no sub-command: ``eval DIRS`` means ``eval rings DIRS``.
DEFAULT_SUBCOMMAND: dict[str, str] = {"eval": "rings"}

_EPILOG = """\
Block specs: 'builtin:NAME' (see 'woodcam blocks'), 'log:gran1@K[:WxDxH]', 'woodify:DIR/field.npz'
(a block cut from a grown object, see 'woodcam woodify'), a block folder with a block.json, or a
Mokume sample folder (six photos and ring maps of a 50 mm cube).
Units are millimetres; the block frame has its origin at the bottom-front-left corner,
X to the right (width), Y away from the viewer (depth), Z up (height).

examples:
  woodcam demo --out out/
  woodcam bake cad_examples/bowl.py --block builtin:flat-sawn --out out/bowl.glb
  woodcam preview out/bowl.glb --screenshot out/bowl.png
  woodcam gcode toolpaths/vcarve_text.nc --tool vbit:60:12 --block builtin:flat-sawn \\
      --out out/vcarve_text.glb --screenshot
  woodcam eval rings out/blocks/block_0000 --out out/eval
  woodcam eval appearance builtin:knotty --out out/eval_appearance
  woodcam woodify trunk.stl --years 40 --eccentricity 0.3 --obstacle post.stl --out out/tree
  woodcam parquetry eye.png --veneer-from ../shared/data/mokume/CN03 --veneer-from builtin:flat-sawn \\
      --out out/eye/

exit status: 0 done; 1 the work failed (a one-line 'woodcam: error: ...' says why); 2 the
command line is wrong (usage; an input path that is not there, a file where a folder is read
or the other way round, or a file of a suffix the command cannot read, too); 3 the work was done \
but a check failed (e.g. gcode --strict);
130 interrupted; 141 the pipe it printed to was closed (woodcam blocks | head), quietly, as git
and ls.
"""

#: Exit statuses (documented in ``woodcam --help`` and the README).
EXIT_OK, EXIT_ERROR, EXIT_USAGE, EXIT_CHECKS = 0, 1, 2, 3
EXIT_INTERRUPTED = _interrupt.EXIT_INTERRUPTED  # 130, also where the process ends after the command
#: Standard output was a pipe whose reader went away (``woodcam blocks | head``): 128 + SIGPIPE,
#: what git, ls and seq end with there (killed by the signal), and like them without a word.
EXIT_BROKEN_PIPE = 141


class _Parser(argparse.ArgumentParser):
    """argparse's parser, whose usage errors are one line: argparse prints the whole usage block
    (up to 15 lines for ``bake``) before its error, which buries the one line that says what is
    wrong; the pointer to ``--help`` replaces the block. Sub-parsers inherit the class
    (``add_subparsers`` makes them with ``type(self)``)."""

    def error(self, message: str):
        # a mistyped command or choice gets the nearest name, as a mistyped option does
        # ('woodcam logs render' listed the eighteen commands and left 'log' to be found)
        bad = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)$", message)
        if bad:
            from .._checks import did_you_mean

            near = did_you_mean(bad.group(1), re.findall(r"'([^']*)'", bad.group(2)))
            message += f"; {near}" if near else ""
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def build_parser() -> argparse.ArgumentParser:
    """The whole ``woodcam`` parser: every module of :data:`COMMANDS` registers its commands."""
    parser = _Parser(
        prog="woodcam", description="CNC cut preview for solid wood: carve a part out of a "
        "block whose growth rings are known and see the wood on every surface.",
        epilog=_EPILOG + "\n" + textwrap.fill("output: " + OUT_RULE, 95) + "\n",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    from .. import __version__

    parser.add_argument("--version", action="version", version=f"woodcam {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in COMMANDS:
        module = importlib.import_module(name)
        register = getattr(module, "register", None)
        if register is None:  # a contributor's mistake, not a user's: say the convention
            raise TypeError(f"command module {name} must define register(subparsers); see "
                            "woodcam/cli/__init__.py")
        register(sub)
    parser.set_defaults(_commands=sub)
    _add_quiet(parser)
    _state_ranges(parser)
    _state_defaults(parser)
    _describe_commands(parser)
    return parser


def _commands(parser: argparse.ArgumentParser, path: tuple[str, ...] = ()):
    """Every (command path, help, parser) of ``parser``'s sub-commands, at any depth."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {a.dest: a.help for a in action._choices_actions}
            for name, sp in action.choices.items():
                yield (*path, name), helps.get(name), sp
                yield from _commands(sp, (*path, name))


def _describe_commands(parser: argparse.ArgumentParser) -> None:
    """A command without a description of its own opens its ``--help`` with its one-line help
    from the command list (``woodcam block show --help`` went straight from usage to arguments,
    saying nowhere what the command does)."""
    for _path, text, sp in _commands(parser):
        if not sp.description and text:
            sp.description = text[0].upper() + text[1:] + ("" if text.endswith(".") else ".")


def _walk_options(parser: argparse.ArgumentParser):
    """Every (command path, optional action) of ``parser`` and its sub-commands."""
    for path, _help, p in [((), None, parser), *_commands(parser)]:
        for action in p._actions:
            if action.option_strings and not isinstance(
                    action, (argparse._HelpAction, argparse._VersionAction)):
                yield list(path), action


def _add_quiet(parser: argparse.ArgumentParser) -> None:
    """Every command takes ``--quiet``: no progress bars, whichever step draws them (``_run``
    runs the command inside :func:`woodcam._progress.silenced`). Six commands had it and
    'bake', 'gcode', 'woodify', 'fit', 'review', 'place', ... none, though their bars are drawn
    the same way."""
    for _path, _help, sp in _commands(parser):
        leaf = not any(isinstance(a, argparse._SubParsersAction) for a in sp._actions)
        if leaf and "--quiet" not in sp._option_string_actions:
            sp.add_argument("--quiet", action="store_true", help="no progress bars")


def _state_ranges(parser: argparse.ArgumentParser) -> None:
    """Every numeric option's help states the range it is checked against (:data:`~woodcam.cli.
    options.RANGES`), before its default: 'block synth --count' said 'in [1, 100000]' and
    'bench run --blocks', 'review --voxels', 'place --candidates' nothing, so a user learnt the
    range from the refusal. A help that states one itself ('in [0, 1]') is left as it is; a
    length read in --units says mm, the unit the range is checked in."""
    from .options import LENGTH_OPTIONS, option_range

    for path, action in _walk_options(parser):
        text = action.help or ""
        if action.type not in (int, float) or text == argparse.SUPPRESS or re.search(r"\bin [\[(]", text):
            continue
        command = path[0] if path else None
        try:
            span = option_range(action.dest, command)
        except TypeError:  # no RANGES entry
            continue
        if LENGTH_OPTIONS.get((command, action.dest)) == "number":
            span += " mm/min" if action.dest == "rapid_rate" else " mm"
        # before the default, said as '(default 3)', '(...; default 3)' or '; default 3'
        said = re.search(r" \([^()]*\bdefault|; default", text)
        action.help = f"{text}, {span}" if said is None else f"{text[:said.start()]}, {span}{text[said.start():]}"


def _state_defaults(parser: argparse.ArgumentParser) -> None:
    """Every option's help ends with its default, so no command leaves a user guessing: the
    help text's own wording when it names one, else the value argparse would use."""
    for _path, action in _walk_options(parser):
        text = action.help or ""
        if action.required or "default" in text.lower() or text == argparse.SUPPRESS:
            continue
        if isinstance(action, (argparse._StoreTrueAction, argparse._StoreFalseAction,
                               argparse._StoreConstAction, argparse._CountAction)):
            continue  # a switch: off unless given
        default = action.default
        shown = ("not set" if default is None or default == [] else
                 ",".join(map(str, default)) if isinstance(default, (list, tuple)) else str(default))
        action.help = f"{text} (default: {shown})".strip()


def _apply_aliases(argv: list[str], parser: argparse.ArgumentParser) -> list[str]:
    for old, new in ALIASES.items():
        if tuple(argv[:len(old)]) == old:
            argv = [*new, *argv[len(old):]]
    if len(argv) >= 2 and argv[0] in DEFAULT_SUBCOMMAND and not argv[1].startswith("-"):
        group = parser.get_default("_commands").choices[argv[0]]
        subs = next(a for a in group._actions if isinstance(a, argparse._SubParsersAction))
        if argv[1] not in subs.choices:
            argv = [argv[0], DEFAULT_SUBCOMMAND[argv[0]], *argv[1:]]
    return _input_after_screenshot(argv)


def _input_after_screenshot(argv: list[str]) -> list[str]:
    """``woodcam preview --screenshot bowl.glb``: --screenshot's optional PNG took the mesh, and
    the command said 'the following arguments are required: mesh' of a mesh typed (bake's part,
    gcode's program alike). A value of --screenshot that is an existing file not named .png is
    the command's input (the PNG must end in .png, and the file is no output to write over):
    --screenshot moves after it and takes its default name. Any other value is left to
    --screenshot's own check ('out' is refused, naming 'out.png')."""
    from pathlib import Path

    argv = list(argv)
    i = 0
    while i < len(argv) - 1:
        value = argv[i + 1]
        if (argv[i] == "--screenshot" and not value.startswith("-") and not value.lower().endswith(".png")
                and Path(value).is_file()):
            argv[i], argv[i + 1] = value, "--screenshot"
            i += 1
        i += 1
    return argv


_printed: set[str] = set()


def print_warnings(items) -> None:
    """Print each warning once, even when it arrives both as a Python warning and in a report."""
    for w in items:
        if w not in _printed:
            _printed.add(w)
            print(f"woodcam: warning: {w}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``woodcam`` console script; returns the exit status.

    Without ``argv`` it runs the process's command line as the process's own command: a Ctrl-C
    after the command returned, while the interpreter exits, still ends the process with exit
    130 and one line (:func:`woodcam._interrupt.handling` with ``process=True``), and the
    handler stays in place to the process's end. Called with ``argv`` (tests, notebooks) it
    puts the previous handler back as it returns."""
    # from the first moment: a Ctrl-C while the command modules import is an interrupt too
    with _interrupt.handling(process=argv is None):
        try:
            rc = _main(argv)
            _interrupt.ended()  # from here a Ctrl-C ends the process itself: no raise to catch
        except KeyboardInterrupt:  # one that landed as the command returned, past its own catch
            _interrupt.ended()
            _interrupt.say()
            rc = EXIT_INTERRUPTED
        except BaseException:  # argparse's SystemExit (--help, a usage error)
            _interrupt.ended()
            raise
    return rc


def _main(argv: list[str] | None) -> int:
    try:
        parser = build_parser()
        args, extra = parser.parse_known_args(_apply_aliases(list(sys.argv[1:] if argv is None else argv), parser))
        if extra:  # said by the command's own parser: its --help lists its options
            _unrecognized(parser, args, extra)
    except KeyboardInterrupt:
        _interrupt.say()
        return EXIT_INTERRUPTED
    return _run(args, parser)


def _unrecognized(parser: argparse.ArgumentParser, args: argparse.Namespace, extra: list[str]) -> None:
    """Exit 2 for the arguments ``extra`` no parser took, said by the parser of the command run
    and with the option nearest a mistyped one: argparse says it of the top parser, so
    'woodcam block show B --out x.png --bogus' pointed at 'woodcam --help', which lists no option
    of ``block show``."""
    path = tuple(str(getattr(args, k)) for k in vars(args)
                 if (k == "command" or k.endswith("_command")) and getattr(args, k) is not None)
    own = next((sp for p, _help, sp in _commands(parser) if p == path), parser)
    message = f"unrecognized arguments: {' '.join(extra)}"
    # compared without the dashes: every option shares them ('--bogus' was near '--out')
    options = [o[2:] for a in own._actions for o in a.option_strings if o.startswith("--")]
    typed = [e.split("=")[0][2:] for e in extra if e.startswith("--")]
    if typed:
        from .._checks import did_you_mean

        near = did_you_mean(typed, options, show=lambda o: f"--{o}")
        message += f"; {near}" if near else ""
    own.error(message)


def _run(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    """Run the parsed command; every way it ends becomes an exit status and at most one line."""
    from ..units import message_units

    _printed.clear()  # once per run: a second main() in one process printed none of the first's
    interrupted = False
    made: list = []  # output folders the run is to make: removed again, where empty, if it fails
    done = False
    # the library's warnings, errors and G-code issues say their lengths in --units (mm without)
    from .._progress import silenced

    with (warnings.catch_warnings(record=True) as caught, message_units(getattr(args, "units", None)),
          silenced(bool(getattr(args, "quiet", False)))):
        warnings.simplefilter("always")
        try:
            from .options import (
                absent_output_folders,
                check_environment,
                check_inputs,
                check_numbers,
                check_out,
                check_screenshot,
                check_values,
                lengths_to_mm,
            )

            check_out(args)  # the --out rule, before any work
            check_screenshot(args)  # and a named --screenshot PNG's
            lengths_to_mm(args, parser)  # --units inch: every length in mm from here on
            check_numbers(args)  # every numeric option finite and in range, before any work
            # the values a library parser reads (--place, --tool): a malformed one is a usage
            # error, before the block is opened (a fit of minutes) and the part loaded
            check_values(args)
            # every input path there and of its kind, last: the value checks above say what is
            # wrong with the options first (a missing part is no reason to hide a bad --tool)
            check_inputs(args)
            check_environment(args)  # the WOODCAM_* settings, read before the work, not after it
            made = absent_output_folders(args)
            rc = args.func(args)
            done = rc == 0
            _interrupt.check()  # a Ctrl-C a library swallowed: the run did not end as asked
            if sys.stdout is not None:  # None where the command was started with it closed (>&-)
                sys.stdout.flush()  # here, not at exit: a closed pipe is then caught below
        except BaseException as err:
            # Ctrl-C, or an error after one: a library swallowed it (trimesh's imports catch
            # BaseException) or left itself half-imported (scipy: NameError), or wrapped it
            # (numba's compiler; a pybind11 module such as OCP, imported by a part script,
            # raises ImportError: woodcam's WoodcamError about it then blamed the script)
            if _interrupt.requested() or caused_by(err, KeyboardInterrupt):
                interrupted = True
                _interrupt.say()
                return EXIT_INTERRUPTED
            # the warnings of the run first, in the order they came, and the line that says why
            # it failed last: printed after it (in the finally below), a warning was the last
            # line a user (or a script reading the last line of stderr) saw
            _print_caught(caught)
            if not isinstance(err, Exception):  # SystemExit and the like: not ours to report
                raise
            if _stdout_closed(err):  # the reader of a pipe went away: it wants no more lines
                return EXIT_BROKEN_PIPE
            if isinstance(err, UsageError):
                print(f"woodcam: error: {err}", file=sys.stderr)
                return EXIT_USAGE
            typed = _typed_spec(args, err)
            if typed:  # a spec typed here broke a rule only its block knows: the command line is wrong
                print(f"woodcam: error: {typed}: {err.rule}", file=sys.stderr)
                return EXIT_USAGE
            if isinstance(err, WoodcamError):
                given = _given_by(args, err)
                print(f"woodcam: error: {given + ': ' if given else ''}{err}", file=sys.stderr)
                return EXIT_ERROR
            if isinstance(err, OSError):  # the system refused a read or write (disk full, no permission)
                where = f" ({err.filename})" if err.filename else ""
                print(f"woodcam: error: {err.strerror or err}{where}; check the path, its permissions and "
                      "the free space", file=sys.stderr)
                return EXIT_ERROR
            if os.environ.get("WOODCAM_DEBUG"):
                raise
            print(f"woodcam: error: internal error ({type(err).__name__}: {str(err)[:300]}); this is a "
                  "woodcam bug: please report the command (WOODCAM_DEBUG=1 shows the traceback)",
                  file=sys.stderr)
            return EXIT_ERROR
        finally:
            if made and not done:  # 'eval appearance --out new' made new/ before reading its block
                from .options import remove_empty_folders

                remove_empty_folders(made)
            if not interrupted:  # an interrupted run is one line: its work is dropped anyway
                _print_caught(caught)  # a run that ended: after its output (once: said above on a failure)
    return rc


def _typed_spec(args: argparse.Namespace, err: BaseException) -> str:
    """``"--block SPEC"`` (as typed) where ``err`` is a :class:`~woodcam.errors.BlockSpecError`
    of a spec given on this command line (``--block``, ``--veneer-from``): a resize past its
    block, found when the block is opened (:func:`woodcam.stock.check_resize_in_block`), after
    the door. "" otherwise: a spec a GLB or a job file recorded is a file's, not the command's."""
    from ..errors import BlockSpecError
    from .options import _command_name, as_typed

    if not isinstance(err, BlockSpecError) or not err.spec:
        return ""
    block = getattr(args, "block", None)
    if block == err.spec or (isinstance(block, list) and err.spec in block):  # in mm once read at the door
        typed = as_typed(args, "block")
        # the name the door gives it: fit's, eval's and block show's positional BLOCK is no --block
        name = next((a.name for a in getattr(args, "_inputs", ()) if a.dest == "block"), "--block")
        if isinstance(block, list):
            typed = typed[block.index(err.spec)] if isinstance(typed, list) else err.spec
        return (f"--block {typed}" if name == "--block"
                else f"{name} of 'woodcam {_command_name(args)}' (block spec {typed!r})")
    specs = getattr(args, "veneer_from", None) or []
    if err.spec in specs:  # as typed: in mm once read at the door, as --block
        return f"--veneer-from {as_typed(args, 'veneer_from')[specs.index(err.spec)]}"
    return ""


def _given_by(args: argparse.Namespace, err: BaseException) -> str:
    """``"--veneer-from of 'woodcam parquetry'"``: the input argument that gave the folder a
    :class:`~woodcam.errors.BlockFolderError` is about (an empty folder as a block), "" if none
    did (the error said the folder alone, which a command of several block inputs left the user
    to match)."""
    from pathlib import Path

    from .._specs import spec_path
    from ..errors import BlockFolderError
    from .options import _command_name

    if not isinstance(err, BlockFolderError) or err.folder is None:
        return ""
    folder = Path(err.folder).resolve()
    for arg in getattr(args, "_inputs", ()):
        value = getattr(args, arg.dest, None)
        for item in value if isinstance(value, list) else [] if value is None else [value]:
            for text in arg.paths(str(item)) if arg.paths else [str(item)]:
                path = spec_path(str(text)) if arg.kind == "block" else Path(str(text))
                if path is not None and path.resolve() == folder:
                    return f"{arg.name} of 'woodcam {_command_name(args)}'"
    return ""


def _stdout_closed(err: BaseException) -> bool:
    """Whether ``err`` is standard output's pipe closed by its reader (``| head``); then stdout
    is pointed at /dev/null so the interpreter's last flush raises nothing. EPIPE is only
    ever a pipe's, never an output file's (written to a temporary and renamed), and the pipe
    is asked itself: one to a worker process that died is not the user's pipe."""
    if not isinstance(err, BrokenPipeError):
        return False
    try:
        fd = sys.stdout.fileno()
        import select

        poller = select.poll()
        poller.register(fd, select.POLLOUT)
        gone = any(events & select.POLLERR for _, events in poller.poll(0))
    except (AttributeError, OSError, ValueError):  # no real stdout, or no poll (Windows)
        return False
    if gone:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, fd)
        os.close(devnull)
    return gone


def _print_caught(caught) -> None:
    """Print the woodcam warnings of ``caught`` not printed yet (:func:`print_warnings`), in the
    order they were raised."""
    print_warnings(str(w.message) for w in caught if _is_ours(w))


def _is_ours(w) -> bool:
    """Warnings woodcam raised itself (its warning classes live in woodcam modules)."""
    return getattr(w.category, "__module__", "").startswith("woodcam")
