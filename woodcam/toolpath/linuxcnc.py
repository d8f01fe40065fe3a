"""LinuxCNC's own interpreter as an oracle and as ``--interpreter linuxcnc``.

Debian's ``linuxcnc-uspace`` package ships LinuxCNC's RS274/NGC interpreter as the Python module
``gcode`` built for Debian's ``/usr/bin/python3`` (not woodcam's virtualenv), so it runs in a
subprocess (:mod:`._linuxcnc_driver`) and its canonical moves come back as JSON. Canonical moves
are compared with woodcam's by :func:`compare_canonical` (end points and arc centres within
``tol_mm``, same kinds, rotations, planes and source lines).
"""

from __future__ import annotations

import functools
import json
import os
import re
import subprocess
import tempfile
from pathlib import Path

from ..errors import WoodcamError
from .interpreter import (
    NO_END,
    NO_PERCENT,
    GcodeError,
    Interpreter,
    add_line_warning,
    blank_program,
    line_list,
    nul_byte_error,
    nul_cut,
    source_lines,
    split_comments,
    tool_entry_in_message,
)

#: Debian's interpreter, for which the ``gcode`` module is built.
LINUXCNC_PYTHON = "/usr/bin/python3"
_DRIVER = Path(__file__).with_name("_linuxcnc_driver.py")
#: What a refusal of LinuxCNC's asks: the line it names is not always the one refused
#: (``parse`` adds 1 where reading a line failed; its AXIS preview says 'near line N')
REFUSED_FIX = ("LinuxCNC's own interpreter refused it near this line: the line itself, or the "
               "one before it where LinuxCNC could not read that one (a bad word or character, "
               "an expression), or for a line of a subroutine its call or the line after the "
               "call; fix that line (--interpreter woodcam names the line itself)")


@functools.lru_cache(maxsize=1)
def linuxcnc_missing() -> str | None:
    """``None`` when LinuxCNC's interpreter can run here, else the reason it cannot."""
    if not os.path.exists(LINUXCNC_PYTHON):
        return f"{LINUXCNC_PYTHON} not found (install Debian's linuxcnc-uspace)"
    r = subprocess.run([LINUXCNC_PYTHON, "-I", "-c", "import gcode"], capture_output=True,
                       text=True, timeout=60)
    if r.returncode:
        return ("LinuxCNC's python module 'gcode' is not importable by /usr/bin/python3 "
                "(apt-get install linuxcnc-uspace): " + r.stderr.strip().splitlines()[-1:][0]
                if r.stderr.strip() else "import gcode failed")
    return None


def run_batch(paths, *, start_mm=(0.0, 0.0, 10.0), timeout_s: float = 10.0,
              machine_zero_mm=(0.0, 0.0, 0.0), tool_diameters_mm=None) -> list[dict]:
    """Run LinuxCNC's interpreter on each file of ``paths`` in one subprocess.

    Returns one dict per file: ``moves`` (canonical ``[kind, line, end, centre, rotation,
    plane]``, mm, in the frame of ``start_mm``: the G54 frame, whose offset is
    ``-machine_zero_mm``; the default zero, or ``None``, is the machine frame), ``messages``
    (the operator messages, ``[line, text]``), ``printed`` (the ``(PRINT,...)`` texts,
    ``[line, text]``), ``said_order`` (the two as the program said them: 0 the next message,
    1 the next PRINT text), ``printed_unplaced`` (``[[index, lines], ...]``: the PRINT texts
    whose line is not known, with the lines that could have printed them), ``error`` (``None``
    or ``[line, message]``), ``seconds``.
    ``tool_diameters_mm``: the tool table's diameters by tool number (mm), what a DEBUG/PRINT
    shows for ``#5410`` (LinuxCNC's table otherwise holds 0).
    """
    why = linuxcnc_missing()
    if why:
        raise WoodcamError(f"--interpreter linuxcnc: {why}; or use --interpreter woodcam")
    job = {"files": [str(Path(p).resolve()) for p in paths], "start_mm": list(start_mm),
           "timeout_s": float(timeout_s),
           "machine_zero_mm": [0.0, 0.0, 0.0] if machine_zero_mm is None else list(machine_zero_mm),
           "tool_diameters_mm": {str(int(n)): float(d) for n, d in
                                 (tool_diameters_mm or {}).items()}}
    r = subprocess.run([LINUXCNC_PYTHON, "-I", str(_DRIVER)], input=json.dumps(job),
                       capture_output=True, text=True,
                       timeout=timeout_s * max(1, len(job["files"])) + 60)
    if r.returncode:
        if len(job["files"]) > 1:  # one program crashed the interpreter: run them one by one
            return [run_batch([p], start_mm=start_mm, timeout_s=timeout_s,
                              machine_zero_mm=machine_zero_mm,
                              tool_diameters_mm=tool_diameters_mm)[0] for p in paths]
        return [{"moves": [], "messages": [], "printed": [], "said_order": [],
                 "printed_unplaced": [], "error": [
                     0, f"LinuxCNC's interpreter crashed (exit {r.returncode})"], "seconds": 0.0}]
    return json.loads(r.stdout)


def run_linuxcnc(text: str, *, start_mm=(0.0, 0.0, 10.0), timeout_s: float = 30.0,
                 machine_zero_mm=(0.0, 0.0, 0.0), said: list | None = None,
                 printed: list | None = None, tool_diameters_mm=None):
    """LinuxCNC's canonical moves of program ``text`` in woodcam's canonical form
    (:mod:`.interpreter`): ``(moves, warnings)``; a refusal raises :class:`GcodeError` with
    LinuxCNC's message and line. ``machine_zero_mm``: the machine origin in the G54 frame
    (mm); ``None`` (not known) refuses a program with G53 lines: LinuxCNC has no "not known"
    and would take machine zero at G-code zero (a ``G53 G0 Z-5`` retract 5 mm into the stock),
    where woodcam's interpreter takes a G53 Z move as a retract to the start height. ``said``,
    when given, receives LinuxCNC's operator messages (``(MSG,...)``, ``(DEBUG,...)``) as
    ``(line, text)``, those before a refusal too; ``printed`` its ``(PRINT,...)`` texts, which
    it writes to its standard output, the same way. ``tool_diameters_mm``: the diameters of
    its tool table by tool number (mm), what a DEBUG/PRINT shows for ``#5410`` of the loaded
    tool (none loaded before an M6: 0); a tool-table entry LinuxCNC's table here does not
    hold (a tool not given, an offset) is shown and warned of as woodcam's interpreter does
    (:func:`_mark_tool_entries`), where LinuxCNC shows 0."""
    nul = nul_byte_error(source_lines(text))  # LinuxCNC drops the rest of its line unsaid
    if nul is not None:
        raise nul
    g53 = _g53_lines(text) if machine_zero_mm is None else []
    if g53:
        raise GcodeError(g53[0], "G53", f"machine coordinates (G53, on line(s) {line_list(g53)}) "
                         "without the machine zero: LinuxCNC's interpreter would take it at "
                         "G-code zero (a G53 Z-5 retract goes 5 mm below the work zero)",
                         "give where the machine zero lies in the G-code frame (--machine-zero "
                         "X,Y,Z; read_gcode's machine_zero_mm), or use --interpreter woodcam, "
                         "which takes a G53 Z move as a retract to the --start height")
    with tempfile.TemporaryDirectory(prefix="woodcam-lcnc-") as d:
        p = Path(d) / "program.ngc"
        marked, unmarked = _mark_tool_entries(text)
        p.write_text(marked)
        res = run_batch([p], start_mm=start_mm, timeout_s=timeout_s,
                        machine_zero_mm=machine_zero_mm, tool_diameters_mm=tool_diameters_mm)[0]
    # the tool-table entries in the texts, shown and warned as woodcam's interpreter does, in
    # the order the program said them (a subroutine's text after the line that called it);
    # each text is one pass of its line (a line in a loop is warned once)
    warnings: list[tuple[int, str]] = []
    warned: dict = {}
    texts: list[list[tuple[int, str]]] = [[], []]
    unplaced = {int(k): [int(ln) for ln in lines] for k, lines in res["printed_unplaced"]}
    kinds = (("messages", "DEBUG"), ("printed", "PRINT"))
    for which in res["said_order"]:
        key, kind = kinds[which]
        k = len(texts[which])
        ln, m = res[key][k]
        texts[which].append((int(ln), _tool_entries_shown(
            m, kind, int(ln), tool_diameters_mm or {}, warnings, warned, (key, k))))
        if int(ln) in unmarked:
            add_line_warning(warnings, warned, int(ln), (
                f"({kind},...) shows {unmarked[int(ln)][0]} as LinuxCNC's tool table here "
                "holds it, unchecked: the line is too long for woodcam to mark which tool is "
                f"loaded ({unmarked[int(ln)][1]} characters; LinuxCNC reads {MAX_LINE}, the "
                "marks need more), so it shows the diameter given for the loaded tool, 0 for a "
                "tool not given (--tools, --tool N=SPEC) and for every other entry, where "
                "woodcam's interpreter says what the entry is; shorten the line (the comment "
                "on a line of its own)"), (key, k))
        if which == 1 and k in unplaced:
            add_line_warning(warnings, warned, int(ln), (
                f"a (PRINT,...) text that any of lines {line_list(unplaced[k])} could have "
                "printed: they are too long for woodcam to mark which line prints "
                f"(LinuxCNC reads {MAX_LINE} characters, the mark needs 3 or more) and the "
                f"texts are alike; it is given line {ln}; shorten the lines or make their "
                "texts differ"), (key, k))
    if said is not None:
        said += [(ln, m.strip()) for ln, m in texts[0]]
    if printed is not None:
        printed += [(ln, m.strip()) for ln, m in texts[1]]
    if res["error"]:
        line, msg = res["error"]
        if msg not in (NO_END, NO_PERCENT):  # (the end of a file: a warning, as woodcam's)
            # (its messages name the file it read: a scratch copy, not the user's)
            raise GcodeError(int(line), "LinuxCNC", _SCRATCH.sub("the program", msg),
                             REFUSED_FIX if int(line) else "LinuxCNC's interpreter failed, "
                             "naming no line of the program; read it with --interpreter woodcam")
        # its parse names the line after the last (line 3 of a 2-line file): the file's last,
        # the line rs274 quotes, as woodcam's interpreter
        lines = source_lines(text)
        if blank_program(nul_cut(lines)):
            # a file of blank lines: rs274 (and the machine) opening it meets the end looking
            # for an opening '%' ('File ended with no percent sign'); the gcode module's parse
            # has no such look and said '... or program end', at line 1 of any blank file, where
            # woodcam's interpreter said rs274's message at the file's last line
            line, msg = max(len(lines), 1), NO_PERCENT
        warnings.append((min(int(line), max(len(lines), 1)), msg))
    moves = [(k, ln, tuple(e), tuple(c) if c else None, rot, plane, feed, rpm, tool, bool(inch))
             for k, ln, e, c, rot, plane, feed, rpm, tool, inch in res["moves"]]
    ran = _ran_lines(text, moves, start_mm, machine_zero_mm, tool_diameters_mm, warnings)
    return [m + (r,) for m, r in zip(moves, ran)], warnings


def _ran_lines(text: str, moves: list, start_mm, machine_zero_mm, tool_diameters_mm,
               warnings: list) -> list[int]:
    """The main-program line each of LinuxCNC's ``moves`` ran under (the canonical tuple's
    ``ran_line``): LinuxCNC reports a subroutine's move at its line in the body and nothing of
    the call (its canon and the state it passes have no call stack, and an o-word line takes
    no comment or marker), so a program with calls is run by woodcam's interpreter too and,
    where its moves come from the same lines in the same order, its ``ran_line`` is taken;
    where they do not, each move keeps its own line, with a warning (``--until-line`` then
    counts a subroutine's moves at the lines of its body)."""
    own = [int(m[1]) for m in moves]
    flat = re.sub(r"\s", "", text).lower()
    if "call" not in flat and "m98" not in flat:
        return own
    why = ""
    try:
        mine, _ = Interpreter(text, start_mm=start_mm, machine_zero_mm=machine_zero_mm,
                              tool_diameters_mm=tool_diameters_mm).run()
    except GcodeError as e:
        mine, why = [], f"it refuses line {e.line}"
    if [int(m[1]) for m in mine] == own:
        return [int(m[10]) for m in mine]
    at = next((i for i, (a, b) in enumerate(zip(mine, moves)) if int(a[1]) != int(b[1])),
              min(len(mine), len(moves)))
    line = int(moves[min(at, len(moves) - 1)][1]) if moves else 1
    warnings.append((line, "woodcam cannot tell which subroutine call ran LinuxCNC's moves "
                     "(LinuxCNC reports a subroutine's move at its line in the body; woodcam's "
                     "interpreter, which tells, makes other moves here"
                     + (f": {why}" if why else "") + "), so --until-line and the --view slider "
                     "place each move at its own line, a subroutine's at the lines of its body; "
                     "read the program with --interpreter woodcam to scrub it by its calls"))
    return own


def may_read_tool_diameters(text: str) -> bool:
    """Whether LinuxCNC's reading of ``text`` can depend on the diameters in its tool table
    (``run_linuxcnc``'s ``tool_diameters_mm``): only a parameter (``#5410``, ``#5401``-``#5413``,
    shown or computed with, also indirectly: ``##1``) and cutter compensation (G41/G42, its
    offset, also ``G[41]``) read them, so a program without a ``#``, a ``[`` and a G41/G42
    word (blanks taken out and any case, as LinuxCNC reads words; in a comment too) reads the
    same moves, messages and warnings whatever the table holds (the driver runs the one file:
    no subroutine files). ``True`` where it may."""
    if "#" in text or "[" in text:
        return True
    return _G41_G42.search(_BLANKS.sub("", text).lower()) is not None


_G41_G42 = re.compile(r"g\+?0*4[12]")
_BLANKS = re.compile(r"[ \t\r]+")
_G53 = re.compile(r"g0*53(?![\d.])")
#: the scratch copy of a program LinuxCNC ran (run_linuxcnc's, the driver's marked one)
_SCRATCH = re.compile(r"\S*woodcam-lcnc-[^/\s]*/program\.ngc")
#: LinuxCNC's longest line (its LINELEN less the end; the driver's MAX_LINE)
MAX_LINE = 252
#: a (DEBUG,...) or (PRINT,...) comment, as LinuxCNC knows them (blanks first, any case)
_SHOWN = re.compile(r"\([ \t]*(?:debug|print),[^)]*\)", re.IGNORECASE)
#: a (PRINT, comment's start, which the driver marks with the line's number (_mark_prints)
_PRINT = re.compile(r"\([ \t]*print,", re.IGNORECASE)
#: a reference to the loaded tool's tool-table entry, #5401-#5413, in such a comment
_ENTRY_REF = re.compile(r"#(0*54(?:0[1-9]|1[0-3]))(?![0-9])")
#: the same put in by LinuxCNC, as marked by _mark_tool_entries: ref, loaded tool, value
_ENTRY_SHOWN = re.compile(r"\x03([0-9]+)\x05(-?[0-9.]+)\x04(-?[0-9.]+|#+)")


def _mark_tool_entries(text: str) -> tuple[str, dict[int, tuple[str, int]]]:
    """``text`` with each ``#5401``-``#5413`` of a DEBUG/PRINT comment led by a mark that has
    LinuxCNC put in the loaded tool (``#5400``): ``\\x03REF\\x05#5400\\x04#REF``. LinuxCNC shows
    the entry of its tool table (the user's diameters, zero offsets), 0 for a tool the user did
    not give; with the mark :func:`_tool_entries_shown` knows the tool and shows and warns as
    woodcam's interpreter does. A line the marks would make too long for LinuxCNC (with the
    driver's mark of a PRINT, its line number) keeps none: returned with its first such
    reference and its length, ``{line: (ref, characters)}``, for a warning."""
    lines = text.split("\n")
    unmarked = {}
    for i, line in enumerate(lines):
        if "54" in line and _SHOWN.search(line):
            marked = _SHOWN.sub(lambda c: _ENTRY_REF.sub(
                lambda m: f"\x03{m.group(1)}\x05#5400\x04#{m.group(1)}", c.group(0)), line)
            if marked == line:
                continue
            room = MAX_LINE - len(_PRINT.findall(line)) * (2 + len(str(i + 1)))
            if len(marked.encode()) <= room:
                lines[i] = marked
            else:
                ref = next(m.group(0) for c in _SHOWN.finditer(line)
                           for m in _ENTRY_REF.finditer(c.group(0)))
                unmarked[i + 1] = (ref, len(line.encode()))
    return "\n".join(lines), unmarked


def _tool_entries_shown(text: str, kind: str, line: int, diameters, warnings: list,
                        warned: dict, pass_id) -> str:
    """``text`` (a DEBUG/PRINT text of ``line`` LinuxCNC put together from a program marked by
    :func:`_mark_tool_entries`) with each marked tool-table entry shown as woodcam's
    interpreter shows it (:func:`.interpreter.tool_entry_in_message`: LinuxCNC's value where
    the user gave the loaded tool's diameter or no tool is loaded, else what it is), its
    warnings added to ``warnings`` once per line (``warned``, ``pass_id``: the text's pass,
    :func:`add_line_warning`)."""
    if "\x03" not in text:
        return text

    def shown(m: re.Match) -> str:
        ref = "#" + m.group(1)
        value, warning = tool_entry_in_message(int(m.group(1)), ref, kind,
                                               int(round(float(m.group(2)))), diameters)
        if warning:
            add_line_warning(warnings, warned, line, warning, pass_id)
        return m.group(3) if isinstance(value, float) else value

    return _ENTRY_SHOWN.sub(shown, text)


def _g53_lines(text: str) -> list[int]:
    """1-based lines of ``text`` with a G53 word (comments taken out, as LinuxCNC reads them)."""
    out = []
    for no, raw in enumerate(source_lines(text), 1):
        if "53" in raw:
            try:
                line = split_comments(raw, no)[0]
            except GcodeError:  # LinuxCNC read the program: cannot happen; no warning then
                continue
            if _G53.search(line):
                out.append(no)
    return out


def canonical(moves, start_mm) -> list[tuple]:
    """Comparable canonical moves: ``(kind, line, end (3,), centre | None, rotation, plane)``
    with zero-length straight moves dropped (LinuxCNC emits some, woodcam none)."""
    out = []
    pos = tuple(float(v) for v in start_mm)
    for m in moves:
        kind, line, end, centre, rot, plane = m[:6]
        end = tuple(float(v) for v in end)
        if kind != 2 and max(abs(a - b) for a, b in zip(end, pos)) < 1e-9:
            continue
        out.append((int(kind), int(line), end, tuple(centre) if centre else None,
                    int(rot) if kind == 2 else 0, int(plane) if kind == 2 else 17))
        pos = end
    return out


def compare_canonical(a, b, tol_mm: float = 1e-6) -> str | None:
    """``None`` when the canonical move lists agree within ``tol_mm``, else the first
    difference in words."""
    if len(a) != len(b):
        for i, (x, y) in enumerate(zip(a, b)):
            d = compare_canonical([x], [y], tol_mm)
            if d:
                return f"move {i}: {d}"
        return f"{len(a)} moves against {len(b)}; first extra: {(a if len(a) > len(b) else b)[min(len(a), len(b))]}"
    for i, (x, y) in enumerate(zip(a, b)):
        if x[0] != y[0] or x[1] != y[1] or x[4] != y[4] or x[5] != y[5]:
            return f"move {i}: {x} against {y}"
        if max(abs(p - q) for p, q in zip(x[2], y[2])) > tol_mm:
            return f"move {i} (line {x[1]}): end {x[2]} against {y[2]}"
        if (x[3] is None) != (y[3] is None) or (x[3] is not None and max(
                abs(p - q) for p, q in zip(x[3], y[3])) > tol_mm):
            return f"move {i} (line {x[1]}): centre {x[3]} against {y[3]}"
    return None
